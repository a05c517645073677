//! The orthogonality check: the error is orthogonal to the estimate.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::fixed;

/// The error is uncorrelated with the estimate.
///
/// # Formula
/// z = √N·corr(e_j − e_ave,j, δx̂_k) ≈ N(0, 1), for each j, k, fix and stage; |z| ≤ √N.
pub const CHECK: Definition = Definition {
    id: CheckId::ORTHOGONALITY,
    title: "orthogonality",
    hypothesis: "the error is orthogonal to the estimate",
    statistic: "z = √N · corr(e, δx̂)",
    members: "each error and estimate component at each fix, a priori and a posteriori; the a \
                 priori bias pair, a copy of the previous fix's, is counted once",
    rationale: "Each entry of the orthogonality matrix is normalized by the ensemble standard \
                 deviations to a correlation, which for uncorrelated variables has standard \
                 deviation 1/√N; the score cannot exceed √N, so small ensembles cannot fail it.",
    formula: r"C(t_i) = \frac{1}{N} \sum_{l=1}^{N} \left(e^l(t_i) - e^{\mathrm{ave}}(t_i)\right) \dxhat^l(t_i)\T, \qquad z_{jk} = \sqrt{N}\, \frac{C_{jk}}{\sigma(e_j)\, \sigma(\widehat{\delta x}_k)} \approx \mathcal{N}(0, 1)",
    null: |_, _| Null::CorrelationScore,
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, at, .. } = w;
        format!(
            "Errors are correlated with estimates: {outside} exceed |z| = {}, up to {} ({at}). The gain is not the minimum-variance gain for the simulated system.",
            fixed(c.upper, 2),
            fixed(c.worst_value(), 1)
        )
    },
};

/// √N·corr(e_j, δx̂_k) for every error and estimate state of every stage at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    let n = stats.realizations() as f64;
    let states = stats.dims().states;
    members::per_stage(stats, &mut |i, stage, s| {
        for error in 0..states {
            for estimate in 0..states {
                let c = s.orthogonality_corr(error, estimate);
                // NaN marks an estimate component that does not vary: nothing to test. Two
                // constant states' a priori pair is the previous fix's a posteriori one.
                let copy = stats.is_copy(i, stage, error) && stats.is_constant(estimate);
                if c.is_finite() && !copy {
                    let fix = i as u32;
                    let member = MemberId::ErrorEstimate {
                        fix,
                        stage,
                        error,
                        estimate,
                    };
                    f(n.sqrt() * c, member);
                }
            }
        }
    });
}
