//! The variance check: the ensemble variance equals the filter's P.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::sig;

/// The ensemble variance equals the filter's.
///
/// # Formula
/// (N − 1)·P_ave,kk / P_kk ~ χ²(N − 1), for each state k, fix i and stage.
pub const CHECK: Definition = Definition {
    id: CheckId::COVARIANCE_MATCH,
    title: "variance",
    hypothesis: "the ensemble variance equals the filter's P",
    statistic: "Pᵃᵛᵉ / P (diagonal)",
    members: "each state at each fix, a priori and a posteriori; the a priori bias, a copy of \
                 the previous fix's a posteriori bias, is counted once",
    rationale: "For Gaussian errors each diagonal ratio of the unbiased ensemble covariance to \
                 P is a scaled χ²(N−1) variable.",
    formula: r"P^{\mathrm{ave}}(t_i) = \frac{1}{N-1} \sum_{l=1}^{N} \left(e^l - e^{\mathrm{ave}}\right)\left(e^l - e^{\mathrm{ave}}\right)\T, \qquad (N-1)\,\frac{P^{\mathrm{ave}}_{kk}}{P_{kk}} \sim \chi^2(N-1)",
    null: |n, _| Null::ChiSquared {
        dof: n - 1.0,
        scale: n - 1.0,
    },
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, band, at } = w;
        format!(
            "The ensemble variance does not match the filter's P: {outside} leave the χ² band {band}, the worst ratio being {} ({at}). The filter's covariance misstates its actual errors.",
            sig(c.worst_value(), 3)
        )
    },
};

/// P_ave,kk / P_kk for every state of every stage at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    members::per_state(stats, &mut |i, stage, k, s| {
        let value = s.ensemble_cov(k, k) / s.filter_cov(k, k);
        let (fix, state) = (i as u32, k);
        f(value, MemberId::State { fix, stage, state });
    });
}
