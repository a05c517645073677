//! Diagnosis of a calibration: what the innovations, the NIS of every fix and the bias's path
//! say beyond the NIS verdict, as numbers (`summary.json`'s `diagnostics`) and as sentences the
//! numbers choose (`sentences`).
//!
//! For a consistent filter the innovations r_i = δz_i − H·δx̂⁻_i are independent N(0, S_i)
//! (the innovation property of the Kalman filter), so each measured component normalized by its
//! predicted σ, u_i,k = r_i,k / √S_i,kk, is a sequence of independent N(0, 1) values. Each test
//! below asks one thing of that sequence, or of the bias's estimates, at a stated false-alarm
//! rate: whether the sequence is white (its autocorrelation), whether its mean square is 1, how
//! many fixes fall outside the per-fix NIS band, and whether the filtered bias strays from the
//! smoothed one by more than their covariances allow.

mod bias;
mod sentences;
pub mod whiteness;

use serde::Serialize;
use statrs::distribution::{Binomial, DiscreteCDF};

use crate::state::{BiasModel, ErrorState, NoiseStats};
use crate::stats::chi_squared_band;

use super::forward::FilteredFix;
use super::nis::NisTest;
use super::smoother::SmoothedFix;

pub use bias::bias_departure;
pub use sentences::{findings, lag_runs};
pub use whiteness::{
    FIXES_PER_LAG, MAX_LAGS, Whiteness, autocorrelation, lag_band, max_lag, whiteness,
};

/// Measured components M.
const M: usize = ErrorState::MEAS;
/// At most this many fixes outside the per-fix NIS band are listed by time.
pub const MAX_LISTED: usize = 100;

/// What the innovations of one measured component say.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasurementDiagnostics {
    /// The component: "position" or "velocity".
    pub measurement: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// The configuration key of its GPS σ (`filter.gps_position_sigma_m`, …).
    pub gps_sigma_key: &'static str,
    /// The GPS σ the filter assumes, in `unit`.
    pub gps_sigma: f64,
    /// The whiteness of u_i = r_i / √S_ii, at α / M.
    pub whiteness: Whiteness,
    /// (1/n) Σ u_i²: 1 expected; n times it is χ²(n) for a consistent filter.
    pub mean_square: f64,
    /// Its two-sided band at α / M: the α/(2M) and 1 − α/(2M) quantiles of χ²(n) / n.
    pub mean_square_band: [f64; 2],
    /// "in", "below" or "above" its band.
    pub mean_square_place: &'static str,
    /// The GPS's share of the predicted variance, (1/n) Σ R_kk / S_i,kk: near 1 the residuals'
    /// spread is set by the GPS σ, near 0 by the integration's (W, the bias, the prior).
    pub gps_share: f64,
    /// The GPS σ the residuals suggest, √(mean of r_i² − (S_i,kk − R_kk)), in `unit`: the
    /// residuals' mean square less what the filter predicts of them besides R, over the fixes
    /// where R_kk ≥ S_i,kk / 2 (past the prior); absent when that is not positive or no fix
    /// qualifies.
    pub gps_sigma_from_residuals: Option<f64>,
}

/// The per-fix NIS against its χ²(M) band, and the fixes outside it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NisPerFix {
    /// The per-fix rate α: each consistent fix falls outside with this probability.
    pub false_alarm_rate: f64,
    /// The band's lower end: the α/2 quantile of χ²(M).
    pub lower: f64,
    /// Its upper end: the 1 − α/2 quantile.
    pub upper: f64,
    /// Fixes outside the band.
    pub outside: usize,
    /// Fixes below it (residuals smaller than predicted).
    pub below: usize,
    /// Fixes above it.
    pub above: usize,
    /// α·n: the expected count outside.
    pub expected_outside: f64,
    /// The most fixes outside that chance explains: the count is Binomial(n, α) for a
    /// consistent filter (its innovations are independent) and exceeds this with probability
    /// at most α.
    pub outside_bound: u64,
    /// "pass" when `outside` ≤ `outside_bound`, else "fail".
    pub verdict: &'static str,
    /// Time of each fix outside, s (the first [`MAX_LISTED`]).
    pub outside_t_s: Vec<f64>,
    /// Its NIS (the same fixes).
    pub outside_nis: Vec<f64>,
}

/// The bias's path: how far the smoothed bias moves and whether the filtered bias strays from
/// it more than the filter's model allows.
///
/// # Formula
/// The smoothed estimation error e^s_i is uncorrelated with every fix, so the filtered error
/// e_i = e^s_i + (x̂^s_i − x̂_i) splits into uncorrelated parts and
/// d_i = (b̂_i − b̂^s_i) / √(P_i,bb − P^s_i,bb) is N(0, 1) at each fix for a consistent filter,
/// whatever its bias model. The test takes max |d_i| over the n_d fixes where the smoother
/// removed at least 10⁻⁶ of the filtered variance, against the two-sided normal bound at α / n_d
/// (Bonferroni; the d_i are correlated, so the rate is at most α). A bias that drifts while the
/// filter holds it constant pulls the early filtered estimates away from the smoothed one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiasDiagnostics {
    /// The bias model the filter assumes.
    pub bias_model: &'static str,
    /// Smallest smoothed bias at a fix, m/s².
    pub smoothed_min_m_s2: f64,
    /// Largest, m/s².
    pub smoothed_max_m_s2: f64,
    /// (max − min) of the smoothed bias in units of its median σ at the fixes: 0 for a constant
    /// bias, whose smoothed estimate is one number (the last fix's is taken for min and max).
    pub smoothed_range_sigmas: f64,
    /// max |d_i|.
    pub departure_max_sigmas: f64,
    /// Time of that fix, s.
    pub departure_t_s: f64,
    /// The fixes n_d the test takes.
    pub departure_fixes: usize,
    /// The bound on max |d_i| at α: the normal bound at α / n_d.
    pub departure_bound_sigmas: f64,
    /// "pass", "fail", or "untestable" when no fix qualifies.
    pub verdict: &'static str,
}

/// `summary.json`'s `diagnostics`: what the numbers point to, beside the NIS verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostics {
    /// α, `checks.false_alarm_rate`: each measurement's whiteness and mean-square tests take
    /// α / M (so the M of them reject together at most α), the per-fix count and the bias test α.
    pub false_alarm_rate: f64,
    /// The fix rate: 1 / the mean interval between fixes without the gaps (intervals within 0.5
    /// to 1.5 times the median), Hz; 0 below two fixes.
    pub fix_rate_hz: f64,
    /// Per measured component: position, then velocity.
    pub measurements: Vec<MeasurementDiagnostics>,
    /// The per-fix NIS.
    pub nis_per_fix: NisPerFix,
    /// The bias's path.
    pub bias: BiasDiagnostics,
    /// What the tests above point to, in sentences ([`findings`]).
    pub findings: Vec<String>,
}

impl Diagnostics {
    /// The tests that reject, in one line for the command's output ("position innovations not
    /// white at lags 1–20, smaller than predicted; …"), or that none does.
    pub fn headline(&self) -> String {
        let mut parts: Vec<String> = Vec::new();
        for m in &self.measurements {
            let mut what = Vec::new();
            if m.whiteness.verdict == "fail" {
                what.push(format!(
                    "not white at lags {}",
                    lag_runs(&m.whiteness.lags_outside)
                ));
            }
            if m.mean_square_place != "in" {
                let side = if m.mean_square_place == "above" {
                    "larger"
                } else {
                    "smaller"
                };
                what.push(format!("{side} than predicted"));
            }
            if !what.is_empty() {
                parts.push(format!("{} innovations {}", m.measurement, what.join(", ")));
            }
        }
        if self.bias.verdict == "fail" {
            parts.push(format!(
                "the bias strays {}σ from its smoothed path (bound {}σ)",
                crate::format::short(self.bias.departure_max_sigmas),
                crate::format::short(self.bias.departure_bound_sigmas)
            ));
        }
        let p = &self.nis_per_fix;
        if p.verdict == "fail" {
            parts.push(format!(
                "{} fixes outside the per-fix NIS band (chance explains {})",
                p.outside, p.outside_bound
            ));
        }
        if parts.is_empty() {
            "no diagnostic rejects".to_string()
        } else {
            parts.join("; ")
        }
    }
}

/// One fix as the diagnosis reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixSeries {
    /// Time, s.
    pub t_s: f64,
    /// Residual r, (m, m/s).
    pub residual: [f64; M],
    /// diag S, (m², (m/s)²).
    pub s_diag: [f64; M],
    /// rᵀ S⁻¹ r.
    pub nis: f64,
    /// Filtered bias and its variance, (m/s², (m/s²)²).
    pub bias_filtered: [f64; 2],
    /// Smoothed bias and its variance.
    pub bias_smoothed: [f64; 2],
}

/// Diagnoses a calibration: its `fixes` with their `smoothed` estimates, the filter's assumed
/// statistics `stats`, the NIS test `nis` of the whole log and α = `false_alarm_rate`.
pub fn diagnose(
    fixes: &[FilteredFix],
    smoothed: &[SmoothedFix],
    stats: &NoiseStats,
    nis: &NisTest,
    false_alarm_rate: f64,
) -> Diagnostics {
    let gps_sigma = [stats.gps_position_sigma_m, stats.gps_velocity_sigma_m_s];
    let series = Calibrated { fixes, smoothed };
    of(&series, gps_sigma, stats.bias_model, nis, false_alarm_rate)
}

/// Fixes as the diagnosis reads them, one at a time: a calibration's are formed from its
/// filtered and smoothed records as they are read, not copied whole (80 bytes a fix).
pub trait Series {
    /// How many fixes.
    fn len(&self) -> usize;
    /// Fix `i`, `i` < [`Series::len`].
    fn at(&self, i: usize) -> FixSeries;
    /// Whether there is none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Series for [FixSeries] {
    fn len(&self) -> usize {
        <[FixSeries]>::len(self)
    }
    fn at(&self, i: usize) -> FixSeries {
        self[i]
    }
}

/// A calibration's fixes with their smoothed estimates.
struct Calibrated<'a> {
    fixes: &'a [FilteredFix],
    smoothed: &'a [SmoothedFix],
}

impl Series for Calibrated<'_> {
    fn len(&self) -> usize {
        self.fixes.len().min(self.smoothed.len())
    }
    fn at(&self, i: usize) -> FixSeries {
        let (f, sm, b) = (&self.fixes[i], &self.smoothed[i], ErrorState::BIAS);
        FixSeries {
            t_s: f.t_s,
            residual: std::array::from_fn(|k| f.residual[k]),
            s_diag: std::array::from_fn(|k| f.s[(k, k)]),
            nis: f.nis,
            bias_filtered: [f.post[b], f.p_post[(b, b)]],
            bias_smoothed: [sm.x[b], sm.p[(b, b)]],
        }
    }
}

/// The fixes of `series` in order.
fn each<S: Series + ?Sized>(series: &S) -> impl Iterator<Item = FixSeries> + '_ {
    (0..series.len()).map(|i| series.at(i))
}

/// [`diagnose`] of plain series: `gps_sigma` = (σ_p, σ_v) the filter assumes.
pub fn of<S: Series + ?Sized>(
    series: &S,
    gps_sigma: [f64; M],
    bias_model: BiasModel,
    nis: &NisTest,
    false_alarm_rate: f64,
) -> Diagnostics {
    let fix_rate_hz = fix_rate_hz(series);
    let measurements = (0..M)
        .map(|k| measurement(series, k, gps_sigma[k], false_alarm_rate / M as f64))
        .collect();
    let mut d = Diagnostics {
        false_alarm_rate,
        fix_rate_hz,
        measurements,
        nis_per_fix: nis_per_fix(series, false_alarm_rate),
        bias: bias::bias(series, bias_model, false_alarm_rate),
        findings: Vec::new(),
    };
    d.findings = findings(&d, nis);
    d
}

/// 1 / the mean interval between fixes over the intervals within 0.5 to 1.5 times the median
/// (a missing fix is a gap, not a slower rate); 0 below two fixes.
fn fix_rate_hz<S: Series + ?Sized>(series: &S) -> f64 {
    let mut steps: Vec<f64> = each(series)
        .zip(each(series).skip(1))
        .map(|(a, b)| b.t_s - a.t_s)
        .collect();
    steps.sort_by(f64::total_cmp);
    let Some(&median) = steps.get(steps.len() / 2) else {
        return 0.0;
    };
    let usual = steps
        .iter()
        .filter(|&&dt| (0.5 * median..=1.5 * median).contains(&dt));
    let (count, sum) = usual.fold((0usize, 0.0), |(c, s), dt| (c + 1, s + dt));
    if sum > 0.0 { count as f64 / sum } else { 0.0 }
}

/// The diagnostics of measured component `k` at rate `rate`.
fn measurement<S: Series + ?Sized>(
    series: &S,
    k: usize,
    gps_sigma: f64,
    rate: f64,
) -> MeasurementDiagnostics {
    const _: () = assert!(M == 2, "one GPS σ key per measured component");
    let keys = [
        "filter.gps_position_sigma_m",
        "filter.gps_velocity_sigma_m_s",
    ];
    let variable = ErrorState::MEASURED[k];
    let u: Vec<f64> = each(series)
        .map(|f| f.residual[k] / f.s_diag[k].sqrt())
        .collect();
    let n = u.len().max(1) as f64;
    let mean_square = u.iter().map(|x| x * x).sum::<f64>() / n;
    let (lo, hi) = chi_squared_band(n, n, rate);
    let r = gps_sigma * gps_sigma;
    let gps_share = each(series).map(|f| r / f.s_diag[k]).sum::<f64>() / n;
    // The fixes where the GPS is at least half of S: the first fixes, where the prior's σ
    // dominates S, would swamp the residuals' spread with S − R.
    let settled = || each(series).filter(|f| 2.0 * r >= f.s_diag[k]);
    let settled_count = settled().count();
    let excess = settled()
        .map(|f| f.residual[k].powi(2) - (f.s_diag[k] - r))
        .sum::<f64>()
        / settled_count.max(1) as f64;
    MeasurementDiagnostics {
        measurement: variable.key,
        unit: variable.unit,
        gps_sigma_key: keys[k],
        gps_sigma,
        whiteness: whiteness(&u, rate),
        mean_square,
        mean_square_band: [lo, hi],
        mean_square_place: place(mean_square, lo, hi),
        gps_share,
        gps_sigma_from_residuals: (excess > 0.0 && settled_count > 0).then(|| excess.sqrt()),
    }
}

/// "in", "below" or "above" the band [lo, hi].
fn place(x: f64, lo: f64, hi: f64) -> &'static str {
    if x < lo {
        "below"
    } else if x > hi {
        "above"
    } else {
        "in"
    }
}

/// The per-fix NIS of `series` against its band at rate α.
fn nis_per_fix<S: Series + ?Sized>(series: &S, alpha: f64) -> NisPerFix {
    let (lower, upper) = chi_squared_band(M as f64, 1.0, alpha);
    // (t, NIS) of each fix outside.
    let outside: Vec<(f64, f64)> = each(series)
        .filter(|f| !(lower..=upper).contains(&f.nis))
        .map(|f| (f.t_s, f.nis))
        .collect();
    let below = outside.iter().filter(|&&(_, nis)| nis < lower).count();
    let bound = binomial_bound(series.len() as u64, alpha, alpha);
    let listed = &outside[..outside.len().min(MAX_LISTED)];
    NisPerFix {
        false_alarm_rate: alpha,
        lower,
        upper,
        outside: outside.len(),
        below,
        above: outside.len() - below,
        expected_outside: alpha * series.len() as f64,
        outside_bound: bound,
        verdict: if outside.len() as u64 <= bound {
            "pass"
        } else {
            "fail"
        },
        outside_t_s: listed.iter().map(|&(t, _)| t).collect(),
        outside_nis: listed.iter().map(|&(_, nis)| nis).collect(),
    }
}

/// The smallest count u with P(K > u) ≤ `rate` for K ~ Binomial(`trials`, `p`).
pub fn binomial_bound(trials: u64, p: f64, rate: f64) -> u64 {
    let Ok(b) = Binomial::new(p.clamp(0.0, 1.0), trials) else {
        return trials;
    };
    (0..trials).find(|&u| b.sf(u) <= rate).unwrap_or(trials)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binomial_bound_is_the_upper_quantile() {
        // Binomial(577, 0.01): P(K > 12) = 0.0062 ≤ 0.01 < P(K > 11) = 0.0149 (scipy binom.sf).
        assert_eq!(binomial_bound(577, 0.01, 0.01), 12);
        assert_eq!(binomial_bound(0, 0.01, 0.01), 0);
    }
}
