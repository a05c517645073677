//! The residual-whiteness check: residuals at different fixes are uncorrelated.

use super::catalogue::{CheckId, Definition, FailureWords, Null};
use super::members;
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
    for_each_member: |stats, f| members::for_each(CheckId::RESIDUAL_WHITENESS, stats, f),
    failure: |c, w| {
        let FailureWords { outside, at, .. } = w;
        format!(
            "The residuals are not white: {outside} exceed |z| = {}, up to {} ({at}). Information is left in the residual sequence.",
            fixed(c.upper, 2),
            fixed(c.worst_value(), 1)
        )
    },
};
