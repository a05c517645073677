//! The members of each check: one statistic per fix, stage and component, computed from the
//! ensemble statistics. Each distinct random quantity is a member once: the bias does not move
//! between fixes (the last row of Φ is (0, 0, 1) and Q has no bias term), so the a priori bias
//! error and estimate at fix i > 0 are the a posteriori ones of fix i − 1 and are not counted
//! again.

use super::catalogue::{CheckId, MemberId};
use crate::ensemble::{EnsembleStats, StageStats};
use crate::filter::{Component, Stage};

/// Whether (fix, stage, component) is the a priori bias, a copy of the previous fix's a
/// posteriori bias, and so not a member of its own.
pub fn is_bias_copy(fix: usize, stage: Stage, c: Component) -> bool {
    fix > 0 && stage == Stage::Prior && c == Component::Bias
}

/// Normalized residual correlation z = √N · Σ r_a r_b / √(Σ r_a² Σ r_b²) of stacked residual
/// components a and b (2i is the position residual at fix i, 2i + 1 the velocity residual).
///
/// # Formula
/// z = √N · m_ab / √(m_aa · m_bb), m the residual second moments (1/N) Σ r_a r_b.
///
/// NaN when the ensemble did not keep that pair (see [`crate::ensemble::ResidualLayout`]).
pub fn residual_z(stats: &EnsembleStats, a: usize, b: usize) -> f64 {
    let m = |a, b| stats.residual_moment(a, b).unwrap_or(f64::NAN);
    z_score(stats.realizations, m(a, b), m(a, a), m(b, b))
}

/// √N · m_ab / √(m_aa · m_bb).
pub fn z_score(n: u64, m_ab: f64, m_aa: f64, m_bb: f64) -> f64 {
    (n as f64).sqrt() * m_ab / (m_aa * m_bb).sqrt()
}

/// Calls `f(value, member)` for every member of the built-in check `id`, in fix order.
pub fn for_each(id: CheckId, stats: &EnsembleStats, f: &mut dyn FnMut(f64, MemberId)) {
    let n = stats.realizations as f64;
    // For every fix and stage: `g(fix, stage, stats of the stage)`.
    let per_stage = |g: &mut dyn FnMut(usize, Stage, &StageStats)| {
        for (i, fix) in stats.fixes.iter().enumerate() {
            for stage in Stage::ALL {
                g(i, stage, fix.stage(stage));
            }
        }
    };
    match id {
        CheckId::MEAN_ERROR | CheckId::COVARIANCE_MATCH => per_stage(&mut |i, stage, s| {
            for state in Component::STATE {
                if is_bias_copy(i, stage, state) {
                    continue;
                }
                let k = state.index();
                let value = if id == CheckId::MEAN_ERROR {
                    s.mean_error[k] / (s.filter_cov[k][k] / n).sqrt()
                } else {
                    s.ensemble_cov[k][k] / s.filter_cov[k][k]
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
                let (c, p) = (&s.ensemble_cov, &s.filter_cov);
                for (a, b) in [(0, 1), (0, 2), (1, 2)] {
                    let r = c[a][b] / (c[a][a] * c[b][b]).sqrt();
                    let rho = p[a][b] / (p[a][a] * p[b][b]).sqrt();
                    let member = MemberId::Correlation {
                        fix: i as u32,
                        stage,
                        a: Component::STATE[a],
                        b: Component::STATE[b],
                    };
                    f(scale * (r.atanh() - rho.atanh()), member);
                }
            })
        }
        CheckId::ORTHOGONALITY => per_stage(&mut |i, stage, s| {
            for error in Component::STATE {
                for estimate in Component::STATE {
                    let c = s.orthogonality_corr[error.index()][estimate.index()];
                    // NaN marks an estimate component that does not vary: nothing to test.
                    let copy = is_bias_copy(i, stage, error) && estimate == Component::Bias;
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
            let layout = &stats.residual_layout;
            for later in 1..stats.fixes.len() {
                for earlier in (0..later).filter(|&m| layout.keeps(later, m)) {
                    for at_later in Component::MEASURED {
                        for at_earlier in Component::MEASURED {
                            let z = residual_z(
                                stats,
                                2 * later + at_later.index(),
                                2 * earlier + at_earlier.index(),
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
            for (i, fix) in stats.fixes.iter().enumerate() {
                f(fix.nis_avg, MemberId::Nis { fix: i as u32 });
            }
        }
        // A check defined outside this file computes its own members.
        _ => {}
    }
}
