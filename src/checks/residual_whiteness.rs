//! The residual-whiteness check: residuals at different fixes are uncorrelated.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::fixed;

/// Residuals at different fixes are uncorrelated.
///
/// # Formula
/// z = √N·Σ r_j(tᵢ)·r_k(tₘ) / √(Σ r_j(tᵢ)²·Σ r_k(tₘ)²) ≈ N(0, 1), for each pair tₘ < tᵢ
/// and components j, k; |z| ≤ √N.
pub const CHECK: Definition = Definition {
    id: CheckId::RESIDUAL_WHITENESS,
    title: "residual whiteness",
    hypothesis: "residuals at different fixes are uncorrelated",
    statistic: "z = √N · corr(r(tᵢ), r(tₘ))",
    members: "each pair of fixes tₘ < tᵢ (in runs of more than 1000 fixes, or with \
                 checks.residual_max_lag, those at most that lag apart) and pair of components",
    rationale: "The residual correlation is computed for every tested pair of fixes and components and \
                 normalized the same way; its score cannot exceed √N either.",
    formula: r"z_{jk} = \sqrt{N}\, \frac{\sum_l r^l_j(t_i)\, r^l_k(t_m)}{\sqrt{\sum_l r^l_j(t_i)^2 \sum_l r^l_k(t_m)^2}} \approx \mathcal{N}(0, 1), \quad t_m < t_i",
    null: |_, _| Null::CorrelationScore,
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, at, .. } = w;
        format!(
            "The residuals are not white: {outside} exceed |z| = {}, up to {} ({at}). Information is left in the residual sequence.",
            fixed(c.upper, 2),
            fixed(c.worst_value(), 1)
        )
    },
};

/// z of every kept pair of residual components at two different fixes.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    let layout = stats.residual_layout();
    let width = stats.dims().measurements;
    for later in 1..stats.fix_count() {
        for earlier in (0..later).filter(|&m| layout.keeps(later, m)) {
            for at_later in 0..width {
                for at_earlier in 0..width {
                    let a = width * later + at_later;
                    let b = width * earlier + at_earlier;
                    let member = MemberId::ResidualPair {
                        later: later as u32,
                        earlier: earlier as u32,
                        at_later,
                        at_earlier,
                    };
                    f(members::residual_z(stats, a, b), member);
                }
            }
        }
    }
}
