//! The NIS check: the average NIS is 2, the measurement dimension.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use crate::ensemble::Statistics;
use crate::format::sig;

/// The average normalized innovation squared is the measurement dimension.
///
/// # Formula
/// N·ν̄ = Σ rᵀS⁻¹r ~ χ²(2N), for each fix.
pub const CHECK: Definition = Definition {
    id: CheckId::NIS,
    title: "NIS",
    hypothesis: "the average NIS is 2, the measurement dimension",
    statistic: "(1/N) Σ rᵀS⁻¹r",
    members: "each fix",
    rationale: "Each realization's rᵀS⁻¹r is χ²(2), so N times the average is χ²(2N).",
    formula: r"\bar{\nu}(t_i) = \frac{1}{N} \sum_{l=1}^{N} r^l(t_i)\T S(t_i)^{-1} r^l(t_i), \qquad N \bar{\nu} \sim \chi^2(2N)",
    null: |n, dims| Null::ChiSquared {
        dof: dims.measurements as f64 * n,
        scale: n,
    },
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, band, at } = w;
        format!(
            "The average NIS leaves its χ² band {band} at {outside}; the worst value is {} ({at}).",
            sig(c.worst_value(), 3)
        )
    },
};

/// The average NIS at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    for i in 0..stats.fix_count() {
        f(stats.nis_avg(i), MemberId::Nis { fix: i as u32 });
    }
}
