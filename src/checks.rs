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
//! | `covariance_correlation` | z = √(N−3)·(atanh r − atanh ρ), r and ρ the off-diagonal correlations of P_ave and P | ≈ N(0, 1) |
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
    (
        chi_squared_quantile(dof, alpha_member / 2.0, false) / scale,
        chi_squared_quantile(dof, alpha_member / 2.0, true) / scale,
    )
}

/// The χ²(dof) quantile with lower-tail probability `p` (or upper-tail `p` when `upper`).
///
/// statrs' inverse CDF is the starting point; it is then refined by bisection in log space on the
/// tail probability itself, which stays accurate far into either tail and for one or two degrees
/// of freedom, where the inverse alone can be off by a large factor.
pub fn chi_squared_quantile(dof: f64, p: f64, upper: bool) -> f64 {
    let chi = ChiSquared::new(dof).expect("positive degrees of freedom");
    let start = chi.inverse_cdf(if upper { 1.0 - p } else { p });
    // tail(x) − p changes sign once: increasing for the lower tail, decreasing for the upper.
    let miss = |x: f64| if upper { p - chi.sf(x) } else { chi.cdf(x) - p };
    let (mut lo, mut hi) = (start.max(f64::MIN_POSITIVE), start.max(f64::MIN_POSITIVE));
    while miss(lo) > 0.0 && lo > 1e-300 {
        lo /= 4.0;
    }
    while miss(hi) < 0.0 && hi < 1e300 {
        hi *= 4.0;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if miss(mid) < 0.0 {
            lo = mid
        } else {
            hi = mid
        }
        if hi / lo - 1.0 < 1e-14 {
            break;
        }
    }
    (lo * hi).sqrt()
}

/// Which member of a family a value belongs to; turned into words only for the worst member,
/// so that families with millions of members stay cheap.
#[derive(Clone, Copy, Debug)]
enum Tag {
    /// A state component of one stage: the mean error or the variance.
    Component {
        prior: bool,
        j: u8,
        what: &'static str,
    },
    /// Error component j against estimate component k.
    Pair {
        prior: bool,
        j: u8,
        k: u8,
    },
    /// The correlation of error components j and k.
    Correlation {
        prior: bool,
        j: u8,
        k: u8,
    },
    /// The NEES of one stage.
    Nees {
        prior: bool,
    },
    Nis,
    /// Residual component j at fix i against residual component k at fix m.
    Residual {
        i: u32,
        m: u32,
        j: u8,
        k: u8,
    },
}

impl Tag {
    fn label(self, stats: &EnsembleStats) -> String {
        match self {
            Tag::Component { prior, j, what } => {
                format!("{} {} {what}", stage_name(prior), STATE_NAMES[j as usize])
            }
            Tag::Pair { prior, j, k } => format!(
                "{} {} error × {} estimate",
                stage_name(prior),
                STATE_NAMES[j as usize],
                STATE_NAMES[k as usize]
            ),
            Tag::Correlation { prior, j, k } => format!(
                "{} {}–{} error correlation",
                stage_name(prior),
                STATE_NAMES[j as usize],
                STATE_NAMES[k as usize]
            ),
            Tag::Nees { prior } => format!("{} NEES", stage_name(prior)),
            Tag::Nis => "NIS".to_string(),
            Tag::Residual { i, m, j, k } => format!(
                "{} residual at {:.1} s × {} residual at {:.1} s",
                RESIDUAL_NAMES[j as usize],
                stats.fixes[i as usize].time_s,
                RESIDUAL_NAMES[k as usize],
                stats.fixes[m as usize].time_s
            ),
        }
    }
}

/// One member's value and where it sits.
struct Member {
    value: f64,
    time_s: f64,
    tag: Tag,
}

fn stage_name(prior: bool) -> &'static str {
    if prior { "a priori" } else { "a posteriori" }
}

/// A family's verdict once its band is known: counts the members outside [lower, upper] (a
/// non-finite member is outside every band) and finds the worst by `excursion`.
#[allow(clippy::too_many_arguments)]
fn verdict(
    id: &'static str,
    statistic: &'static str,
    kind: Kind,
    alpha: f64,
    (lower, upper): (f64, f64),
    members: &[Member],
    excursion: impl Fn(f64) -> f64,
    stats: &EnsembleStats,
) -> Check {
    let failures = members
        .iter()
        .filter(|x| !(lower..=upper).contains(&x.value))
        .count();
    let worst = members.iter().max_by(|a, b| {
        let (ea, eb) = (excursion(a.value), excursion(b.value));
        // NaN sorts above every number, so a non-finite member is the worst.
        ea.is_nan().cmp(&eb.is_nan()).then(ea.total_cmp(&eb))
    });
    let (worst_value, worst_time_s, worst_member) = match worst {
        Some(w) => (w.value, w.time_s, w.tag.label(stats)),
        // A family can be empty (no estimate varies over the ensemble): nothing to reject.
        None => (0.0, 0.0, "no member could be tested".to_string()),
    };
    Check {
        id,
        statistic,
        kind,
        members: members.len(),
        false_alarm_rate: alpha,
        worst: worst_value,
        bound: upper,
        lower,
        upper,
        passed: failures == 0,
        failures,
        worst_time_s,
        worst_member,
    }
}

fn normal_check(
    id: &'static str,
    statistic: &'static str,
    alpha: f64,
    members: &[Member],
    stats: &EnsembleStats,
) -> Check {
    let bound = normal_bound(alpha / members.len().max(1) as f64);
    let mut c = verdict(
        id,
        statistic,
        Kind::Normal,
        alpha,
        (-bound, bound),
        members,
        f64::abs,
        stats,
    );
    c.worst = c.worst.abs();
    c
}

fn chi_squared_check(
    id: &'static str,
    statistic: &'static str,
    alpha: f64,
    (dof, scale): (f64, f64),
    members: &[Member],
    stats: &EnsembleStats,
) -> Check {
    let (lower, upper) = chi_squared_band(dof, scale, alpha / members.len().max(1) as f64);
    let median = ChiSquared::new(dof).expect("positive dof").inverse_cdf(0.5) / scale;
    let excursion = |x: f64| {
        if x >= median {
            (x - median) / (upper - median)
        } else {
            (median - x) / (median - lower)
        }
    };
    let mut c = verdict(
        id,
        statistic,
        Kind::ChiSquared,
        alpha,
        (lower, upper),
        members,
        excursion,
        stats,
    );
    // The bound on the worst member's side.
    c.bound = if c.worst >= median { upper } else { lower };
    c
}

/// For every fix and both stages, `f(stage stats, time, is_prior, out)` pushes members.
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
        for j in 0..3u8 {
            let k = j as usize;
            out.push(Member {
                value: s.mean_error[k] / (s.filter_cov[k][k] / n).sqrt(),
                time_s: t,
                tag: Tag::Component {
                    prior,
                    j,
                    what: "error",
                },
            });
        }
    });
    let covariance = per_stage(stats, |s, t, prior, out| {
        for j in 0..3u8 {
            let k = j as usize;
            out.push(Member {
                value: s.ensemble_cov[k][k] / s.filter_cov[k][k],
                time_s: t,
                tag: Tag::Component {
                    prior,
                    j,
                    what: "variance",
                },
            });
        }
    });
    // Fisher's transformation: for bivariate normal errors atanh(r) is close to normal with mean
    // atanh(ρ) and variance 1/(N − 3).
    let fisher_scale = (n - 3.0).max(1.0).sqrt();
    let correlation = per_stage(stats, |s, t, prior, out| {
        for (j, k) in [(0u8, 1u8), (0, 2), (1, 2)] {
            let (a, b) = (j as usize, k as usize);
            let r = s.ensemble_cov[a][b] / (s.ensemble_cov[a][a] * s.ensemble_cov[b][b]).sqrt();
            let rho = s.filter_cov[a][b] / (s.filter_cov[a][a] * s.filter_cov[b][b]).sqrt();
            out.push(Member {
                value: fisher_scale * (r.atanh() - rho.atanh()),
                time_s: t,
                tag: Tag::Correlation { prior, j, k },
            });
        }
    });
    let orthogonality = per_stage(stats, |s, t, prior, out| {
        for (j, row) in (0u8..).zip(&s.orthogonality_corr) {
            for (k, &c) in (0u8..).zip(row) {
                // NaN marks an estimate component that does not vary: nothing to test.
                if c.is_finite() {
                    out.push(Member {
                        value: n.sqrt() * c,
                        time_s: t,
                        tag: Tag::Pair { prior, j, k },
                    });
                }
            }
        }
    });
    let nees = per_stage(stats, |s, t, prior, out| {
        out.push(Member {
            value: s.nees_avg,
            time_s: t,
            tag: Tag::Nees { prior },
        })
    });
    let nis: Vec<Member> = stats
        .fixes
        .iter()
        .map(|f| Member {
            value: f.nis_avg,
            time_s: f.time_s,
            tag: Tag::Nis,
        })
        .collect();
    let fixes = stats.fixes.len();
    let mut whiteness = Vec::with_capacity(2 * fixes * fixes);
    for i in 1..fixes {
        for m in 0..i {
            for j in 0..2u8 {
                for k in 0..2u8 {
                    whiteness.push(Member {
                        value: residual_z(stats, 2 * i + j as usize, 2 * m + k as usize),
                        time_s: stats.fixes[i].time_s,
                        tag: Tag::Residual {
                            i: i as u32,
                            m: m as u32,
                            j,
                            k,
                        },
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
            &mean_error,
            stats,
        ),
        chi_squared_check(
            "covariance_match",
            "P_ave / P, each diagonal element, a priori and a posteriori; (N−1)·ratio ~ χ²(N−1)",
            alpha,
            (n - 1.0, n - 1.0),
            &covariance,
            stats,
        ),
        normal_check(
            "covariance_correlation",
            "√(N−3) · (atanh r − atanh ρ), r and ρ the correlations of P_ave and P, each off-diagonal pair, a priori and a posteriori",
            alpha,
            &correlation,
            stats,
        ),
        normal_check(
            "orthogonality",
            "√N · correlation of (e − e_ave) and δx̂, every component pair, a priori and a posteriori",
            alpha,
            &orthogonality,
            stats,
        ),
        normal_check(
            "residual_whiteness",
            "√N · correlation of r(t_i) and r(t_m), every pair t_m < t_i and component pair",
            alpha,
            &whiteness,
            stats,
        ),
        chi_squared_check(
            "nees",
            "average eᵀP⁻¹e, a priori and a posteriori; N·average ~ χ²(3N)",
            alpha,
            (3.0 * n, n),
            &nees,
            stats,
        ),
        chi_squared_check(
            "nis",
            "average rᵀS⁻¹r; N·average ~ χ²(2N)",
            alpha,
            (2.0 * n, n),
            &nis,
            stats,
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

    fn empty_stats() -> EnsembleStats {
        EnsembleStats {
            realizations: 10,
            fixes: Vec::new(),
            residual_corr: Vec::new(),
        }
    }

    #[test]
    fn an_empty_family_passes_and_a_non_finite_member_fails() {
        let stats = empty_stats();
        let c = normal_check("x", "", 0.01, &[], &stats);
        assert!(c.passed && c.members == 0 && c.worst.is_finite());
        let members = [
            Member {
                value: 0.5,
                time_s: 1.0,
                tag: Tag::Nis,
            },
            Member {
                value: f64::NAN,
                time_s: 2.0,
                tag: Tag::Nis,
            },
        ];
        let c = normal_check("x", "", 0.01, &members, &stats);
        assert!(!c.passed && c.failures == 1 && c.worst_time_s == 2.0);
        let members = [
            Member {
                value: 3.0,
                time_s: 1.0,
                tag: Tag::Nis,
            },
            Member {
                value: f64::NAN,
                time_s: 2.0,
                tag: Tag::Nis,
            },
        ];
        let c = chi_squared_check("x", "", 0.01, (30.0, 10.0), &members, &stats);
        assert!(!c.passed && c.failures == 1 && c.worst_time_s == 2.0);
    }

    #[test]
    fn chi_squared_worst_takes_the_bound_of_its_side() {
        let stats = empty_stats();
        let members = [
            Member {
                value: 2.95,
                time_s: 1.0,
                tag: Tag::Nis,
            },
            Member {
                value: 2.2,
                time_s: 2.0,
                tag: Tag::Nis,
            },
        ];
        let c = chi_squared_check("nees", "", 0.01, (3000.0, 1000.0), &members, &stats);
        assert_eq!(c.worst, 2.2);
        assert_eq!(c.bound, c.lower);
        assert!(!c.passed);
    }

    #[test]
    fn normal_bound_is_the_two_sided_quantile() {
        approx::assert_relative_eq!(
            normal_bound(0.05),
            1.959_963_984_540_054,
            max_relative = 1e-9
        );
    }

    #[test]
    fn chi_squared_quantiles_are_exact_for_one_and_two_degrees_of_freedom() {
        let p = 5.5e-6;
        // χ²(1) is the square of a standard normal: its p-quantile is Φ⁻¹((1 + p)/2)².
        let exact = Normal::standard().inverse_cdf(0.5 + p / 2.0).powi(2);
        approx::assert_relative_eq!(
            chi_squared_quantile(1.0, p, false),
            exact,
            max_relative = 1e-6
        );
        // χ²(2) is exponential with mean 2.
        approx::assert_relative_eq!(
            chi_squared_quantile(2.0, p, false),
            -2.0 * (-p).ln_1p(),
            max_relative = 1e-9
        );
        approx::assert_relative_eq!(
            chi_squared_quantile(2.0, p, true),
            -2.0 * p.ln(),
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
