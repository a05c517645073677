//! The mean-error check: the ensemble mean error is zero.

use super::catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
use super::members;
use crate::ensemble::Statistics;
use crate::format::fixed;

/// The ensemble mean error is zero.
///
/// # Formula
/// z = e_ave,k(tᵢ) / √(P_kk(tᵢ)/N) ~ N(0, 1), for each state k, fix i and stage.
pub const CHECK: Definition = Definition {
    id: CheckId::MEAN_ERROR,
    title: "mean error",
    hypothesis: "the ensemble mean error is zero",
    statistic: "z = eᵃᵛᵉ / √(P/N)",
    members: "each state at each fix, a priori and a posteriori; the a priori bias, a copy of \
                 the previous fix's a posteriori bias, is counted once",
    rationale: "Its standard error is σ/√N with σ from the filter's P, so each component of the \
                 mean error divided by it is a standard normal score.",
    formula: r"e^{\mathrm{ave}}(t_i) = \frac{1}{N} \sum_{l=1}^{N} e^l(t_i), \qquad z = \frac{e^{\mathrm{ave}}_k(t_i)}{\sqrt{P_{kk}(t_i)/N}} \sim \mathcal{N}(0, 1)",
    null: |_, _| Null::Normal,
    for_each_member,
    failure: |c, w| {
        let FailureWords { outside, at, .. } = w;
        format!(
            "The ensemble mean error is not zero: {outside} leave the band, the worst ({at}) by |z| = {} against a bound of {}. The errors carry a systematic part that the filter's model does not contain.",
            fixed(c.worst_value(), 1),
            fixed(c.upper, 2)
        )
    },
};

/// z for every state of every stage at every fix.
fn for_each_member(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    let n = stats.realizations() as f64;
    members::per_state(stats, &mut |i, stage, k, s| {
        let value = s.mean_error[k] / (s.filter_cov(k, k) / n).sqrt();
        let (fix, state) = (i as u32, k);
        f(value, MemberId::State { fix, stage, state });
    });
}
