//! The NEES check: the average NEES is 3, the state dimension.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::sig;

/// The average normalized estimation error squared is the state dimension.
///
/// # Formula
/// N·ε̄ = Σ eᵀP⁻¹e ~ χ²(3N), for each fix and stage.
pub const CHECK: Definition = Definition {
    id: CheckId::NEES,
    title: "NEES",
    hypothesis: "the average NEES is 3, the state dimension",
    statistic: "(1/N) Σ eᵀP⁻¹e",
    members: "each fix, a priori and a posteriori",
    rationale: "Each realization's eᵀP⁻¹e is χ²(3) for Gaussian errors, so N times the average \
                 is χ²(3N).",
    formula: r"\bar{\epsilon}(t_i) = \frac{1}{N} \sum_{l=1}^{N} e^l(t_i)\T P(t_i)^{-1} e^l(t_i), \qquad N \bar{\epsilon} \sim \chi^2(3N)",
    null: |n, dims| Null::ChiSquared {
        dof: dims.states as f64 * n,
        scale: n,
    },
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, band, at } = w;
        format!(
            "The average NEES leaves its χ² band {band} at {outside}; the worst value is {} ({at}).",
            sig(c.worst_value(), 3)
        )
    },
};

/// The average NEES of every stage at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    members::per_stage(stats, &mut |i, stage, s| {
        let fix = i as u32;
        f(s.nees_avg, MemberId::Nees { fix, stage });
    });
}
