//! The probability that a check fails a mistuned filter, in closed form where the distribution
//! of its members is known from the actual covariance: a scaled normal for the mean error (the
//! error stays centred, with the actual variance), a scaled χ² for the variance ratio, and weighted
//! χ² sums for NEES and NIS, approximated by the scaled χ² with the same mean and variance.
//!
//! A check fails when any of its members does. Whatever the dependence between members, that
//! probability lies between the largest member's and the sum of all (Fréchet bounds), which are
//! what the study reports from here. The point value that treats the members as independent is
//! kept for comparison only: members are strongly correlated across fixes and it overstates the
//! probability (the sampled prediction of [`super::sampler`] replaces it).

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use super::covariance::{ActualFix, weights};
use crate::checks::{Budget, CheckId, band};
use crate::filter::{FilterSchedule, Stage};
use crate::state::ErrorState;

/// A predicted detection probability with its bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// The probability that the check fails, members taken as independent.
    pub probability: f64,
    /// The largest member's failure probability: a lower bound.
    pub lower: f64,
    /// The sum of the members' failure probabilities, capped at 1: an upper bound.
    pub upper: f64,
}

impl Detection {
    fn of(member_probabilities: &[f64]) -> Self {
        let lower = member_probabilities.iter().cloned().fold(0.0, f64::max);
        let upper = member_probabilities.iter().sum::<f64>().min(1.0);
        let log_none: f64 = member_probabilities
            .iter()
            .map(|p| (-p.clamp(0.0, 1.0)).ln_1p())
            .sum();
        let probability = (-log_none.exp_m1()).clamp(lower, upper);
        Self {
            probability,
            lower,
            upper,
        }
    }
}

/// P(X ∉ [lo, hi]) for X = (a/n)·χ²(ν).
fn outside_scaled_chi_squared(nu: f64, a: f64, n: f64, (lo, hi): (f64, f64)) -> f64 {
    let chi = ChiSquared::new(nu).expect("positive degrees of freedom");
    chi.cdf(lo * n / a) + chi.sf(hi * n / a)
}

/// The predicted probability that check `id` fails at `n` realizations within `budget`, when
/// the filter `schedule` has the actual error covariances `actual`; `None` for the checks whose
/// statistic under a mistuned filter has no closed form here (the correlation scores).
pub fn predicted(
    id: CheckId,
    schedule: &FilterSchedule,
    actual: &[ActualFix],
    n: u64,
    budget: &Budget,
) -> Option<Detection> {
    let nf = n as f64;
    let stages = |f: &ActualFix, i: usize, stage: Stage| {
        let c = &schedule.fixes[i];
        match stage {
            Stage::Prior => (f.prior, c.p_prior, c.p_prior_inv),
            Stage::Posterior => (f.post, c.p_post, c.p_post_inv),
        }
    };
    let mut p = Vec::new();
    match id {
        CheckId::MEAN_ERROR | CheckId::COVARIANCE_MATCH => {
            let mut ratios = Vec::new();
            for (i, f) in actual.iter().enumerate() {
                for stage in Stage::ALL {
                    let (pa, pf, _) = stages(f, i, stage);
                    for k in 0..ErrorState::DIM {
                        let copy = i > 0 && stage == Stage::Prior && schedule.constant[k];
                        if !copy {
                            ratios.push(pa[(k, k)] / pf[(k, k)]);
                        }
                    }
                }
            }
            let share = budget.share() / ratios.len() as f64;
            let (lo, hi, _) = band(id.definition(), n, ErrorState::DIMS, share);
            for r in ratios {
                p.push(if id == CheckId::MEAN_ERROR {
                    // e_ave/√(P/N) ~ N(0, r): outside ±b with probability 2·Φ(−b/√r).
                    2.0 * Normal::standard().cdf(-hi / r.sqrt())
                } else {
                    // P_ave/P ~ r·χ²(N − 1)/(N − 1).
                    outside_scaled_chi_squared(nf - 1.0, r, nf - 1.0, (lo, hi))
                });
            }
        }
        CheckId::NEES | CheckId::NIS => {
            let mut forms = Vec::new();
            for (i, f) in actual.iter().enumerate() {
                if id == CheckId::NEES {
                    for stage in Stage::ALL {
                        let (pa, _, pinv) = stages(f, i, stage);
                        forms.push(weights(&pinv, &pa));
                    }
                } else {
                    forms.push(weights(&schedule.fixes[i].s_inv, &f.innovation));
                }
            }
            let share = budget.share() / forms.len() as f64;
            let (lo, hi, _) = band(id.definition(), n, ErrorState::DIMS, share);
            for (sum, sum_sq) in forms {
                // N·average = Σ_k λ_k χ²(N) ≈ a·χ²(ν) with the same mean and variance.
                let a = sum_sq / sum;
                let nu = nf * sum * sum / sum_sq;
                p.push(outside_scaled_chi_squared(nu, a, nf, (lo, hi)));
            }
        }
        // The correlation scores, and any other check.
        _ => return None,
    }
    Some(Detection::of(&p))
}
