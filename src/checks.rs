//! Statistical verdicts on an ensemble: does the filter's covariance describe its actual errors?
//!
//! Each check is a family of hypothesis tests, one per member (a fix, a stage, a component, a
//! pair of fixes). Its bounds hold the family-wise false-alarm rate α of a consistent filter:
//! each member is tested two-sided at α/M (Bonferroni over the M members).
//!
//! | id | member statistic | distribution under a consistent filter |
//! |----|------------------|----------------------------------------|
//! | `mean_error` | z = e_ave / √(P/N) | N(0, 1) |
//! | `covariance_match` | P_ave / P (diagonal) | χ²(N−1)/(N−1) |
//! | `orthogonality` | z = √N · corr(e − e_ave, δx̂) | ≈ N(0, 1) |
//! | `residual_whiteness` | z = √N · Σr_i r_m / √(Σr_i² Σr_m²), t_m < t_i | ≈ N(0, 1) |
//! | `nees` | (1/N) Σ eᵀP⁻¹e | χ²(3N)/N |
//! | `nis` | (1/N) Σ rᵀS⁻¹r | χ²(2N)/N |

use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use crate::ensemble::{EnsembleStats, StageStats};
use crate::model::Timeline;

/// Names of the error-state components, in state order.
pub const STATE_NAMES: [&str; 3] = ["position", "velocity", "bias"];
/// Names of the residual components.
pub const RESIDUAL_NAMES: [&str; 2] = ["position", "velocity"];

/// How a check's members are distributed under a consistent filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Standard normal scores; worst is the largest |z|, bound the two-sided quantile.
    Normal,
    /// Scaled χ² statistics; worst is the member farthest outside relative to its band.
    ChiSquared,
}

/// The verdict of one check.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// Stable identifier, e.g. `covariance_match`.
    pub id: &'static str,
    /// What each member computes.
    pub statistic: &'static str,
    pub kind: Kind,
    /// Members tested (M).
    pub members: usize,
    /// Family-wise false-alarm rate α.
    pub false_alarm_rate: f64,
    /// The worst member's statistic: max |z| for normal checks, the ratio for χ² checks.
    pub worst: f64,
    /// The bound on the worst member's side.
    pub bound: f64,
    /// Acceptance band of every member, [lower, upper].
    pub lower: f64,
    pub upper: f64,
    /// Whether every member lies in its band.
    pub passed: bool,
    /// Members outside the band.
    pub failures: usize,
    /// Where the worst member is: time of its fix, s.
    pub worst_time_s: f64,
    /// Which member is worst, in words.
    pub worst_member: String,
}

/// The statement's single residual pair (t_m, t_i).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualPair {
    pub t_m_s: f64,
    pub t_i_s: f64,
    /// (1/N) Σ r(t_i)·r(t_m)ᵀ, row-major: rows are components of r(t_i), columns of r(t_m).
    pub correlation: [[f64; 2]; 2],
    /// The same as normalized scores z = √N·corr.
    pub z: [[f64; 2]; 2],
    /// Two-sided bound on |z| for these four members at the family-wise rate.
    pub bound: f64,
    pub passed: bool,
}

/// All verdicts on one ensemble.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdicts {
    pub checks: Vec<Check>,
    pub residual_pair: ResidualPair,
}

impl Verdicts {
    /// True when every check passed.
    pub fn all_passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// The check named `id`.
    pub fn get(&self, id: &str) -> Option<&Check> {
        self.checks.iter().find(|c| c.id == id)
    }
}

/// Two-sided standard normal bound at per-member rate `alpha_member`.
pub fn normal_bound(alpha_member: f64) -> f64 {
    Normal::standard().inverse_cdf(1.0 - alpha_member / 2.0)
}

/// Two-sided band of χ²(dof)/scale at per-member rate `alpha_member`.
pub fn chi_squared_band(dof: f64, scale: f64, alpha_member: f64) -> (f64, f64) {
    let chi = ChiSquared::new(dof).expect("positive degrees of freedom");
    (
        chi.inverse_cdf(alpha_member / 2.0) / scale,
        chi.inverse_cdf(1.0 - alpha_member / 2.0) / scale,
    )
}

/// One member's value and where it sits.
struct Member {
    value: f64,
    time_s: f64,
    label: String,
}

fn stage_name(prior: bool) -> &'static str {
    if prior { "a priori" } else { "a posteriori" }
}

fn normal_check(
    id: &'static str,
    statistic: &'static str,
    alpha: f64,
    members: Vec<Member>,
) -> Check {
    let m = members.len().max(1);
    let bound = normal_bound(alpha / m as f64);
    // A non-finite member is outside every band.
    let failures = members
        .iter()
        .filter(|x| !(-bound..=bound).contains(&x.value))
        .count();
    let worst = members
        .iter()
        .max_by(|a, b| a.value.abs().total_cmp(&b.value.abs()))
        .expect("a check has members");
    Check {
        id,
        statistic,
        kind: Kind::Normal,
        members: members.len(),
        false_alarm_rate: alpha,
        worst: worst.value.abs(),
        bound,
        lower: -bound,
        upper: bound,
        passed: failures == 0,
        failures,
        worst_time_s: worst.time_s,
        worst_member: worst.label.clone(),
    }
}

fn chi_squared_check(
    id: &'static str,
    statistic: &'static str,
    alpha: f64,
    (dof, scale): (f64, f64),
    members: Vec<Member>,
) -> Check {
    let (lower, upper) = chi_squared_band(dof, scale, alpha / members.len() as f64);
    let median = ChiSquared::new(dof).expect("positive dof").inverse_cdf(0.5) / scale;
    let excursion = |x: f64| {
        if x >= median {
            (x - median) / (upper - median)
        } else {
            (median - x) / (median - lower)
        }
    };
    let failures = members
        .iter()
        .filter(|x| !(lower..=upper).contains(&x.value))
        .count();
    let worst = members
        .iter()
        .max_by(|a, b| excursion(a.value).total_cmp(&excursion(b.value)))
        .expect("a check has members");
    Check {
        id,
        statistic,
        kind: Kind::ChiSquared,
        members: members.len(),
        false_alarm_rate: alpha,
        worst: worst.value,
        bound: if worst.value >= median { upper } else { lower },
        lower,
        upper,
        passed: failures == 0,
        failures,
        worst_time_s: worst.time_s,
        worst_member: worst.label.clone(),
    }
}

/// For every fix and both stages, `f(stage stats, is_prior)` → per-component members.
fn per_stage(
    stats: &EnsembleStats,
    mut f: impl FnMut(&StageStats, f64, bool, &mut Vec<Member>),
) -> Vec<Member> {
    let mut out = Vec::new();
    for fix in &stats.fixes {
        f(&fix.prior, fix.time_s, true, &mut out);
        f(&fix.post, fix.time_s, false, &mut out);
    }
    out
}

/// Normalized residual correlation z = √N · Σ r_a r_b / √(Σ r_a² Σ r_b²) of stacked residual
/// components a and b (2i + 0 is the position residual at fix i, 2i + 1 the velocity residual).
pub fn residual_z(stats: &EnsembleStats, a: usize, b: usize) -> f64 {
    let n = stats.realizations as f64;
    let d = stats.residual_moment(a, a) * stats.residual_moment(b, b);
    n.sqrt() * stats.residual_moment(a, b) / d.sqrt()
}

/// Runs every check on `stats` at family-wise rate `alpha`.
pub fn evaluate(
    stats: &EnsembleStats,
    timeline: &Timeline,
    alpha: f64,
    residual_pair_s: [f64; 2],
) -> Verdicts {
    let n = stats.realizations as f64;
    let mean_error = per_stage(stats, |s, t, prior, out| {
        for (j, name) in STATE_NAMES.iter().enumerate() {
            out.push(Member {
                value: s.mean_error[j] / (s.filter_cov[j][j] / n).sqrt(),
                time_s: t,
                label: format!("{} {name} error", stage_name(prior)),
            });
        }
    });
    let covariance = per_stage(stats, |s, t, prior, out| {
        for (j, name) in STATE_NAMES.iter().enumerate() {
            out.push(Member {
                value: s.ensemble_cov[j][j] / s.filter_cov[j][j],
                time_s: t,
                label: format!("{} {name} variance", stage_name(prior)),
            });
        }
    });
    let orthogonality = per_stage(stats, |s, t, prior, out| {
        for (row, error_name) in s.orthogonality_corr.iter().zip(STATE_NAMES) {
            for (&c, estimate_name) in row.iter().zip(STATE_NAMES) {
                if c.is_finite() {
                    out.push(Member {
                        value: n.sqrt() * c,
                        time_s: t,
                        label: format!(
                            "{} {error_name} error × {estimate_name} estimate",
                            stage_name(prior)
                        ),
                    });
                }
            }
        }
    });
    let nees = per_stage(stats, |s, t, prior, out| {
        out.push(Member {
            value: s.nees_avg,
            time_s: t,
            label: format!("{} NEES", stage_name(prior)),
        })
    });
    let nis: Vec<Member> = stats
        .fixes
        .iter()
        .map(|f| Member {
            value: f.nis_avg,
            time_s: f.time_s,
            label: "NIS".to_string(),
        })
        .collect();
    let fixes = stats.fixes.len();
    let mut whiteness = Vec::with_capacity(2 * fixes * fixes);
    for i in 1..fixes {
        for m in 0..i {
            for (j, name_i) in RESIDUAL_NAMES.iter().enumerate() {
                for (k, name_m) in RESIDUAL_NAMES.iter().enumerate() {
                    whiteness.push(Member {
                        value: residual_z(stats, 2 * i + j, 2 * m + k),
                        time_s: stats.fixes[i].time_s,
                        label: format!(
                            "{name_i} residual at {:.1} s × {name_m} residual at {:.1} s",
                            stats.fixes[i].time_s, stats.fixes[m].time_s
                        ),
                    });
                }
            }
        }
    }

    let checks = vec![
        normal_check(
            "mean_error",
            "e_ave / √(P/N), each component, a priori and a posteriori",
            alpha,
            mean_error,
        ),
        chi_squared_check(
            "covariance_match",
            "P_ave / P, each diagonal element, a priori and a posteriori; (N−1)·ratio ~ χ²(N−1)",
            alpha,
            (n - 1.0, n - 1.0),
            covariance,
        ),
        normal_check(
            "orthogonality",
            "√N · correlation of (e − e_ave) and δx̂, every component pair, a priori and a posteriori",
            alpha,
            orthogonality,
        ),
        normal_check(
            "residual_whiteness",
            "√N · correlation of r(t_i) and r(t_m), every pair t_m < t_i and component pair",
            alpha,
            whiteness,
        ),
        chi_squared_check(
            "nees",
            "average eᵀP⁻¹e, a priori and a posteriori; N·average ~ χ²(3N)",
            alpha,
            (3.0 * n, n),
            nees,
        ),
        chi_squared_check(
            "nis",
            "average rᵀS⁻¹r; N·average ~ χ²(2N)",
            alpha,
            (2.0 * n, n),
            nis,
        ),
    ];

    let [tm, ti] = residual_pair_s;
    let m = timeline.fix_index_at(tm).expect("validated fix time");
    let i = timeline.fix_index_at(ti).expect("validated fix time");
    let pair_bound = normal_bound(alpha / 4.0);
    let correlation = std::array::from_fn(|j| {
        std::array::from_fn(|k| stats.residual_moment(2 * i + j, 2 * m + k))
    });
    let z: [[f64; 2]; 2] =
        std::array::from_fn(|j| std::array::from_fn(|k| residual_z(stats, 2 * i + j, 2 * m + k)));
    let residual_pair = ResidualPair {
        t_m_s: stats.fixes[m].time_s,
        t_i_s: stats.fixes[i].time_s,
        correlation,
        z,
        bound: pair_bound,
        passed: z.iter().flatten().all(|v| v.abs() <= pair_bound),
    };
    Verdicts {
        checks,
        residual_pair,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_bound_is_the_two_sided_quantile() {
        approx::assert_relative_eq!(
            normal_bound(0.05),
            1.959_963_984_540_054,
            max_relative = 1e-9
        );
    }

    #[test]
    fn chi_squared_band_matches_wilson_hilferty_for_large_dof() {
        let k = 30_000.0;
        let (lo, hi) = chi_squared_band(k, k, 1e-6);
        let z = normal_bound(1e-6);
        let wh = |z: f64| (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3);
        approx::assert_relative_eq!(lo, wh(-z), max_relative = 1e-4);
        approx::assert_relative_eq!(hi, wh(z), max_relative = 1e-4);
    }
}
