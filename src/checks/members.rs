//! The members of each check: one statistic per fix, stage and component, computed from the
//! ensemble statistics through [`Statistics`], whatever the state's size. Each distinct random
//! quantity is a member once: a constant state (for the error state, the bias: the last row of Φ
//! is (0, 0, 1) and Q has no bias term) does not move between fixes, so its a priori error and
//! estimate at fix i > 0 are the a posteriori ones of fix i − 1 and are not counted again.

use super::catalogue::{CheckId, MemberId};
use crate::ensemble::{StageView, Statistics};
use crate::filter::Stage;

/// Normalized residual correlation z = √N · Σ r_a r_b / √(Σ r_a² Σ r_b²) of stacked residual
/// components a and b (component M·i + j is component j of the residual at fix i).
///
/// # Formula
/// z = √N · m_ab / √(m_aa · m_bb), m the residual second moments (1/N) Σ r_a r_b.
///
/// NaN when the ensemble did not keep that pair (see [`crate::ensemble::ResidualLayout`]).
pub fn residual_z(stats: &dyn Statistics, a: usize, b: usize) -> f64 {
    let m = |a, b| stats.residual_moment(a, b).unwrap_or(f64::NAN);
    z_score(stats.realizations(), m(a, b), m(a, a), m(b, b))
}

/// √N · m_ab / √(m_aa · m_bb).
pub fn z_score(n: u64, m_ab: f64, m_aa: f64, m_bb: f64) -> f64 {
    (n as f64).sqrt() * m_ab / (m_aa * m_bb).sqrt()
}

/// Calls `f(value, member)` for every member of the built-in check `id`, in fix order.
pub fn for_each(id: CheckId, stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    let n = stats.realizations() as f64;
    let dims = stats.dims();
    // For every fix and stage: `g(fix, stage, stats of the stage)`.
    let per_stage = |g: &mut dyn FnMut(usize, Stage, &StageView)| {
        for i in 0..stats.fix_count() {
            for stage in Stage::ALL {
                g(i, stage, &stats.stage(i, stage));
            }
        }
    };
    match id {
        CheckId::MEAN_ERROR | CheckId::COVARIANCE_MATCH => per_stage(&mut |i, stage, s| {
            for state in 0..dims.states {
                if stats.is_copy(i, stage, state) {
                    continue;
                }
                let k = state;
                let value = if id == CheckId::MEAN_ERROR {
                    s.mean_error[k] / (s.filter_cov(k, k) / n).sqrt()
                } else {
                    s.ensemble_cov(k, k) / s.filter_cov(k, k)
                };
                let fix = i as u32;
                f(value, MemberId::State { fix, stage, state });
            }
        }),
        CheckId::COVARIANCE_CORRELATION => {
            // Fisher's transformation: for bivariate normal errors atanh(r) is close to normal
            // with mean atanh(ρ) and variance 1/(N − 3).
            let scale = (n - 3.0).max(1.0).sqrt();
            per_stage(&mut |i, stage, s| {
                let pairs =
                    (0..dims.states).flat_map(|a| (a + 1..dims.states).map(move |b| (a, b)));
                for (a, b) in pairs {
                    let c = |a, b| s.ensemble_cov(a, b);
                    let p = |a, b| s.filter_cov(a, b);
                    let r = c(a, b) / (c(a, a) * c(b, b)).sqrt();
                    let rho = p(a, b) / (p(a, a) * p(b, b)).sqrt();
                    let member = MemberId::Correlation {
                        fix: i as u32,
                        stage,
                        a,
                        b,
                    };
                    f(scale * (r.atanh() - rho.atanh()), member);
                }
            })
        }
        CheckId::ORTHOGONALITY => per_stage(&mut |i, stage, s| {
            for error in 0..dims.states {
                for estimate in 0..dims.states {
                    let c = s.orthogonality_corr(error, estimate);
                    // NaN marks an estimate component that does not vary: nothing to test.
                    let copy = stats.is_copy(i, stage, error) && stats.is_constant(estimate);
                    if c.is_finite() && !copy {
                        let member = MemberId::ErrorEstimate {
                            fix: i as u32,
                            stage,
                            error,
                            estimate,
                        };
                        f(n.sqrt() * c, member);
                    }
                }
            }
        }),
        CheckId::RESIDUAL_WHITENESS => {
            let layout = stats.residual_layout();
            let width = dims.measurements;
            for later in 1..stats.fix_count() {
                for earlier in (0..later).filter(|&m| layout.keeps(later, m)) {
                    for at_later in 0..width {
                        for at_earlier in 0..width {
                            let z = residual_z(
                                stats,
                                width * later + at_later,
                                width * earlier + at_earlier,
                            );
                            let member = MemberId::ResidualPair {
                                later: later as u32,
                                earlier: earlier as u32,
                                at_later,
                                at_earlier,
                            };
                            f(z, member);
                        }
                    }
                }
            }
        }
        CheckId::NEES => per_stage(&mut |i, stage, s| {
            f(
                s.nees_avg,
                MemberId::Nees {
                    fix: i as u32,
                    stage,
                },
            )
        }),
        CheckId::NIS => {
            for i in 0..stats.fix_count() {
                f(stats.nis_avg(i), MemberId::Nis { fix: i as u32 });
            }
        }
        // A check defined outside this file computes its own members.
        _ => {}
    }
}
