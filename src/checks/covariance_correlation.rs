//! The correlation check: the ensemble correlations equal those of P.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::fixed;

/// The correlations between error components equal those of the filter's P.
///
/// # Formula
/// z = √(N − 3)·(atanh r_jk − atanh ρ_jk) ≈ N(0, 1), r from P_ave and ρ from P, for each
/// pair j < k, fix and stage (Fisher's transformation).
pub const CHECK: Definition = Definition {
    id: CheckId::COVARIANCE_CORRELATION,
    title: "correlation",
    hypothesis: "the ensemble correlations equal those of P",
    statistic: "z = √(N−3)·(atanh r − atanh ρ)",
    members: "each pair of states at each fix, a priori and a posteriori",
    rationale: "The correlation r of each pair of error components in the ensemble is compared \
                 with the correlation ρ that the filter's P implies, through Fisher's \
                 transformation, whose normal approximation needs N\u{a0}>\u{a0}3.",
    formula: r"r_{jk} = \frac{P^{\mathrm{ave}}_{jk}}{\sqrt{P^{\mathrm{ave}}_{jj} P^{\mathrm{ave}}_{kk}}}, \quad \rho_{jk} = \frac{P_{jk}}{\sqrt{P_{jj} P_{kk}}}, \qquad z = \sqrt{N-3}\,\left(\operatorname{atanh} r_{jk} - \operatorname{atanh} \rho_{jk}\right) \approx \mathcal{N}(0, 1)",
    null: |_, _| Null::Fisher,
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, at, .. } = w;
        format!(
            "The correlations between error components differ from those of the filter's P: {outside} exceed |z| = {}, up to {} ({at}).",
            fixed(c.upper, 2),
            fixed(c.worst_value(), 1)
        )
    },
};

/// Fisher's z of every pair of states of every stage at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    // Fisher's transformation: for bivariate normal errors atanh(r) is close to normal with mean
    // atanh(ρ) and variance 1/(N − 3).
    let scale = (stats.realizations() as f64 - 3.0).max(1.0).sqrt();
    let states = stats.dims().states;
    members::per_stage(stats, &mut |i, stage, s| {
        for a in 0..states {
            for b in a + 1..states {
                let (c, p) = (|a, b| s.ensemble_cov(a, b), |a, b| s.filter_cov(a, b));
                let r = c(a, b) / (c(a, a) * c(b, b)).sqrt();
                let rho = p(a, b) / (p(a, a) * p(b, b)).sqrt();
                let fix = i as u32;
                let member = MemberId::Correlation { fix, stage, a, b };
                f(scale * (r.atanh() - rho.atanh()), member);
            }
        }
    });
}
