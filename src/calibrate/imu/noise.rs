//! `calibrate --imu --estimate-noise`: the noise statistics and the receiver's time offset by
//! maximum likelihood of the GNSS innovations, with profile-likelihood intervals.
//!
//! A filter whose statistics are right has white innovations with covariance S, so the
//! statistics that maximise ℓ(θ) = −½ Σ_k (m_k ln 2π + ln det S_k + ν_kᵀS_k⁻¹ν_k) are those the
//! drive supports (Mehra, IEEE Trans. Automatic Control 15(2), 1970; the same likelihood as the
//! one-axis `--estimate-noise`, `crate::likelihood`). ℓ is evaluated on the filter linearized
//! about one run over the IMU steps held in memory ([`super::linearized`]: the recursion over the
//! fixes alone, equal to the run's ℓ at its own statistics); the search is repeated about a run
//! at its maximum until the maximum stops moving (at most [`MAX_RUNS`] runs), and the intervals
//! come from the model about the last. The σ's and random walks are searched in their
//! logarithms within ×10^±2 of their starting values; the time offset linearly within
//! ±[`MAX_TIME_OFFSET_S`]. An interval end that reaches the box is open, and the key is then
//! reported as not identifiable.

use serde::Serialize;

use super::Settings;
use super::config::MAX_TIME_OFFSET_S;
use super::linearized::Linearized;
use super::run::{filter, shifted};
use crate::error::ConfigError;
use crate::input::imu_csv::{HeldSteps, ImuSpan};
use crate::input::records::{GnssRow, ImuStep};
use crate::likelihood::{Fit, climb, maximize};
use crate::progress::{Cancel, Cancelled};

/// Runs of the filter the search linearizes about, at most.
pub const MAX_RUNS: usize = 12;

/// The maximum has stopped moving when no key's search variable moves more than this between
/// two runs (a logarithm: 0.1 %; the offset: 0.1 ms).
const SETTLED: f64 = 1e-3;

/// A quantity `--estimate-noise` can estimate on the three-axis path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ImuKey {
    /// The fixes' horizontal position σ (north and east), m.
    GnssHorizontalSigma,
    /// Their vertical position σ, m.
    GnssVerticalSigma,
    /// Their velocity σ per component, m/s.
    GnssVelocitySigma,
    /// The accelerometers' velocity random walk, m/s/√s.
    AccelVrw,
    /// The gyros' angle random walk, rad/√s.
    GyroArw,
    /// The accelerometer biases' random walk, m/s²/√s.
    AccelBiasRandomWalk,
    /// The gyro biases' random walk, rad/s/√s.
    GyroBiasRandomWalk,
    /// The receiver's time offset, s.
    GnssTimeOffset,
}

impl ImuKey {
    /// Every key, in `summary.json`'s order.
    pub const ALL: [ImuKey; 8] = [
        ImuKey::GnssHorizontalSigma,
        ImuKey::GnssVerticalSigma,
        ImuKey::GnssVelocitySigma,
        ImuKey::AccelVrw,
        ImuKey::GyroArw,
        ImuKey::AccelBiasRandomWalk,
        ImuKey::GyroBiasRandomWalk,
        ImuKey::GnssTimeOffset,
    ];

    /// The keys searched when none is named: the receiver's three σ's, the velocity random walk
    /// and the time offset.
    pub const DEFAULT: [ImuKey; 5] = [
        ImuKey::GnssHorizontalSigma,
        ImuKey::GnssVerticalSigma,
        ImuKey::GnssVelocitySigma,
        ImuKey::AccelVrw,
        ImuKey::GnssTimeOffset,
    ];

    /// Its name on the command line and in `summary.json`.
    pub fn name(self) -> &'static str {
        match self {
            ImuKey::GnssHorizontalSigma => "gnss_horizontal_sigma_m",
            ImuKey::GnssVerticalSigma => "gnss_vertical_sigma_m",
            ImuKey::GnssVelocitySigma => "gnss_velocity_sigma_m_s",
            ImuKey::AccelVrw => "accel_vrw_m_s_per_sqrt_s",
            ImuKey::GyroArw => "gyro_arw_rad_per_sqrt_s",
            ImuKey::AccelBiasRandomWalk => "accel_bias_random_walk_m_s2_per_sqrt_s",
            ImuKey::GyroBiasRandomWalk => "gyro_bias_random_walk_rad_s_per_sqrt_s",
            ImuKey::GnssTimeOffset => "gnss_time_offset_s",
        }
    }

    /// What it is, in words with its unit.
    pub fn words(self) -> &'static str {
        match self {
            ImuKey::GnssHorizontalSigma => "the fixes' horizontal position σ, m",
            ImuKey::GnssVerticalSigma => "the fixes' vertical position σ, m",
            ImuKey::GnssVelocitySigma => "the fixes' velocity σ per component, m/s",
            ImuKey::AccelVrw => "the accelerometers' velocity random walk, m/s/√s",
            ImuKey::GyroArw => "the gyros' angle random walk, rad/√s",
            ImuKey::AccelBiasRandomWalk => "the accelerometer biases' random walk, m/s²/√s",
            ImuKey::GyroBiasRandomWalk => "the gyro biases' random walk, rad/s/√s",
            ImuKey::GnssTimeOffset => {
                "the receiver's time offset (a fix stamped t is at t + offset), s"
            }
        }
    }

    /// The field of the assumptions ([`Settings`]) it sets.
    pub fn field(self) -> &'static str {
        match self {
            ImuKey::GnssHorizontalSigma | ImuKey::GnssVerticalSigma => "gnss_position_sigma_m",
            ImuKey::GnssVelocitySigma => "gnss_velocity_sigma_m_s",
            ImuKey::AccelVrw => "accel_vrw_m_s_per_sqrt_s",
            ImuKey::GyroArw => "gyro_arw_rad_per_sqrt_s",
            ImuKey::AccelBiasRandomWalk => "accel_bias_random_walk_m_s2_per_sqrt_s",
            ImuKey::GyroBiasRandomWalk => "gyro_bias_random_walk_rad_s_per_sqrt_s",
            ImuKey::GnssTimeOffset => "gnss_time_offset_s",
        }
    }

    /// The key named `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether it is searched linearly (it can be negative), not in its logarithm.
    fn linear(self) -> bool {
        self == ImuKey::GnssTimeOffset
    }

    /// Its value in `s`.
    pub fn get(self, s: &Settings) -> f64 {
        match self {
            ImuKey::GnssHorizontalSigma => s.gnss_position_sigma_m[0],
            ImuKey::GnssVerticalSigma => s.gnss_position_sigma_m[2],
            ImuKey::GnssVelocitySigma => s.gnss_velocity_sigma_m_s,
            ImuKey::AccelVrw => s.accel_vrw_m_s_per_sqrt_s,
            ImuKey::GyroArw => s.gyro_arw_rad_per_sqrt_s,
            ImuKey::AccelBiasRandomWalk => s.accel_bias_random_walk_m_s2_per_sqrt_s,
            ImuKey::GyroBiasRandomWalk => s.gyro_bias_random_walk_rad_s_per_sqrt_s,
            ImuKey::GnssTimeOffset => s.gnss_time_offset_s,
        }
    }

    /// `s` with this key set to `v`.
    pub fn set(self, s: &mut Settings, v: f64) {
        match self {
            ImuKey::GnssHorizontalSigma => {
                s.gnss_position_sigma_m[0] = v;
                s.gnss_position_sigma_m[1] = v;
            }
            ImuKey::GnssVerticalSigma => s.gnss_position_sigma_m[2] = v,
            ImuKey::GnssVelocitySigma => s.gnss_velocity_sigma_m_s = v,
            ImuKey::AccelVrw => s.accel_vrw_m_s_per_sqrt_s = v,
            ImuKey::GyroArw => s.gyro_arw_rad_per_sqrt_s = v,
            ImuKey::AccelBiasRandomWalk => s.accel_bias_random_walk_m_s2_per_sqrt_s = v,
            ImuKey::GyroBiasRandomWalk => s.gyro_bias_random_walk_rad_s_per_sqrt_s = v,
            ImuKey::GnssTimeOffset => s.gnss_time_offset_s = v,
        }
    }

    /// The search's box around the value `v`, in the search's variable.
    fn bounds(self, v: f64) -> (f64, f64) {
        if self.linear() {
            (-MAX_TIME_OFFSET_S, MAX_TIME_OFFSET_S)
        } else {
            let c = v.max(1e-12).ln();
            (
                c - BOX_DECADES * std::f64::consts::LN_10,
                c + BOX_DECADES * std::f64::consts::LN_10,
            )
        }
    }

    /// The key's value of the search's variable `u`.
    fn value(self, u: f64) -> f64 {
        if self.linear() { u } else { u.exp() }
    }
}

/// The search's box for a σ or random walk: its starting value ×10^±2.
const BOX_DECADES: f64 = 2.0;

/// One key's estimate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyEstimate {
    /// The key.
    pub key: &'static str,
    /// The maximum-likelihood value, which the calibration uses.
    pub value: f64,
    /// The interval's lower end; `null` when it reached the search's bound.
    pub lower: Option<f64>,
    /// The upper end; `null` when it reached the search's bound.
    pub upper: Option<f64>,
    /// Whether both ends lie inside the search's bounds: only then does the drive determine it.
    pub identifiable: bool,
    /// The search's bounds.
    pub search_bounds: [f64; 2],
}

/// The estimate of the requested keys.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoiseEstimate {
    /// ℓ at the maximum.
    pub log_likelihood: f64,
    /// Evaluations of ℓ (each a recursion over the fixes of the linearized filter).
    pub evaluations: u64,
    /// Runs of the filter over the IMU log the search linearized about.
    pub filter_runs: usize,
    /// Whether the maximum stopped moving within [`MAX_RUNS`] runs.
    pub settled: bool,
    /// The intervals' confidence.
    pub confidence: f64,
    /// The fixes ℓ sums over.
    pub fixes: usize,
    /// Each key, in the request's order.
    pub keys: Vec<KeyEstimate>,
    /// The assumptions with the estimates in place.
    #[serde(skip)]
    pub settings: Settings,
}

/// The log-likelihood of the GNSS innovations of the filter with assumptions `s` over the
/// first `fixes` fixes after the alignment's; −∞ when the filter cannot run or updates fewer.
pub fn log_likelihood(rows: &[GnssRow], steps: &[ImuStep], s: &Settings, fixes: usize) -> f64 {
    crate::with_layout!(s.layout(), N => log_likelihood_of::<N>(rows, steps, s, fixes))
}

/// [`log_likelihood`] of a filter of `N` error states.
fn log_likelihood_of<const N: usize>(
    rows: &[GnssRow],
    steps: &[ImuStep],
    s: &Settings,
    fixes: usize,
) -> f64 {
    let rows = shifted(rows, s.gnss_time_offset_s);
    let Ok(run) = filter::<N>(&rows, &mut HeldSteps::new(steps), s, "") else {
        return f64::NEG_INFINITY;
    };
    if run.records.len() < fixes {
        return f64::NEG_INFINITY;
    }
    let ln_2pi = (2.0 * std::f64::consts::PI).ln();
    -0.5 * run.records[..fixes]
        .iter()
        .map(|r| r.rows as f64 * ln_2pi + r.log_det_s + r.nis)
        .sum::<f64>()
}

/// The fixes every offset in the box leaves inside the IMU log: those after the alignment's
/// fix stamped at least [`MAX_TIME_OFFSET_S`] before its end.
fn fixes_in_reach(rows: &[GnssRow], span: &ImuSpan, start: usize) -> usize {
    rows[start + 1..]
        .iter()
        .filter(|r| r.t_s + MAX_TIME_OFFSET_S <= span.last_s)
        .count()
}

/// Whether the noise statistics can be estimated under `s`: not with the χ² gate, whose
/// rejected fixes the likelihood does not yet leave out.
///
/// # Errors
/// [`ConfigError::Invalid`] naming `filter.innovation_gate`.
pub fn check_estimable(s: &Settings) -> Result<(), ConfigError> {
    if s.innovation_gate {
        return Err(ConfigError::invalid(
            "filter.innovation_gate",
            true,
            "false with --estimate-noise: the likelihood of the noise statistics does not yet \
             leave the gate's rejected fixes out",
        ));
    }
    Ok(())
}

/// Maximises ℓ over `keys` from `s` (the others held), with each key's profile-likelihood
/// interval at `confidence`. `None` when ℓ is not finite at `s`.
pub fn estimate(
    rows: &[GnssRow],
    steps: &[ImuStep],
    span: &ImuSpan,
    s: &Settings,
    keys: &[ImuKey],
    confidence: f64,
) -> Option<NoiseEstimate> {
    estimate_cancellable(rows, steps, span, (s, keys, confidence), &Cancel::new())
        .unwrap_or_default()
}

/// [`estimate`] that stops when `cancel` is raised: every evaluation of ℓ then returns −∞ at
/// once, so the search and the intervals end within one evaluation, and the result is
/// [`Cancelled`].
///
/// # Errors
/// [`Cancelled`] when the flag was raised before the estimate was complete.
pub fn estimate_cancellable(
    rows: &[GnssRow],
    steps: &[ImuStep],
    span: &ImuSpan,
    (s, keys, confidence): (&Settings, &[ImuKey], f64),
    cancel: &Cancel,
) -> Result<Option<NoiseEstimate>, Cancelled> {
    let found = search(rows, steps, span, (s, keys, confidence), cancel);
    cancel.check()?;
    Ok(found)
}

/// The search of [`estimate_cancellable`], on the filter of the error states `s` names.
fn search(
    rows: &[GnssRow],
    steps: &[ImuStep],
    span: &ImuSpan,
    request: (&Settings, &[ImuKey], f64),
    cancel: &Cancel,
) -> Option<NoiseEstimate> {
    crate::with_layout!(request.0.layout(), N => search_of::<N>(rows, steps, span, request, cancel))
}

/// [`search`] on a filter of `N` error states.
fn search_of<const N: usize>(
    rows: &[GnssRow],
    steps: &[ImuStep],
    span: &ImuSpan,
    (s, keys, confidence): (&Settings, &[ImuKey], f64),
    cancel: &Cancel,
) -> Option<NoiseEstimate> {
    let settings_at = |u: &[f64]| {
        let mut t = *s;
        for (k, x) in keys.iter().zip(u) {
            k.set(&mut t, k.value(*x));
        }
        t
    };
    let bounds: Vec<(f64, f64)> = keys.iter().map(|k| k.bounds(k.get(s))).collect();
    let lo: Vec<f64> = bounds.iter().map(|b| b.0).collect();
    let hi: Vec<f64> = bounds.iter().map(|b| b.1).collect();
    let mut u: Vec<f64> = keys
        .iter()
        .map(|k| {
            if k.linear() {
                k.get(s)
            } else {
                k.get(s).max(1e-12).ln()
            }
        })
        .collect();
    let mut model = Linearized::<N>::new(rows, steps, s).ok()?;
    let fixes = fixes_in_reach(rows, span, model.start);
    let mut at_run = model.log_likelihood(s, fixes);
    let (mut evaluations, mut filter_runs, mut settled) = (0, 1, false);
    'search: while filter_runs < MAX_RUNS {
        let f = |x: &[f64]| {
            if cancel.is_cancelled() {
                return f64::NEG_INFINITY;
            }
            model.log_likelihood(&settings_at(x), fixes)
        };
        let (best, _, n) = climb(&f, (&lo, &hi), &u)?;
        evaluations += n;
        if best.iter().zip(&u).all(|(a, b)| (a - b).abs() <= SETTLED) {
            settled = true;
            break;
        }
        // A run at the model's maximum: taken when the likelihood of that run (its model's ℓ
        // at its own statistics, equal to the filter's) beats the last run's; else halfway.
        let mut step: Vec<f64> = best.iter().zip(&u).map(|(a, b)| a - b).collect();
        while filter_runs < MAX_RUNS && !cancel.is_cancelled() {
            let candidate: Vec<f64> = u.iter().zip(&step).map(|(a, d)| a + d).collect();
            let t = settings_at(&candidate);
            filter_runs += 1;
            if let Ok(next) = Linearized::<N>::new(rows, steps, &t) {
                let value = next.log_likelihood(&t, fixes);
                if value > at_run {
                    (model, u, at_run) = (next, candidate, value);
                    continue 'search;
                }
            }
            step.iter_mut().for_each(|d| *d *= 0.5);
            if step.iter().all(|d| d.abs() <= SETTLED) {
                settled = true;
                break 'search;
            }
        }
    }
    let f = |x: &[f64]| {
        if cancel.is_cancelled() {
            return f64::NEG_INFINITY;
        }
        model.log_likelihood(&settings_at(x), fixes)
    };
    let fit: Fit = maximize(&f, (&lo, &hi), &u, confidence)?;
    let estimates = key_estimates(keys, &fit, (&lo, &hi));
    Some(NoiseEstimate {
        log_likelihood: fit.value,
        evaluations: evaluations + fit.evaluations,
        filter_runs,
        settled,
        confidence,
        fixes,
        keys: estimates,
        settings: settings_at(&fit.u),
    })
}

/// Each key's estimate from the fit, its interval ends open where they reached the box
/// [lo, hi].
fn key_estimates(keys: &[ImuKey], fit: &Fit, (lo, hi): (&[f64], &[f64])) -> Vec<KeyEstimate> {
    keys.iter()
        .enumerate()
        .map(|(j, &k)| {
            let (l, h) = (fit.ends[2 * j].at, fit.ends[2 * j + 1].at);
            let inside = |x: Option<f64>| x.is_some_and(|x| x > lo[j] && x < hi[j]);
            KeyEstimate {
                key: k.name(),
                value: k.value(fit.u[j]),
                lower: l.filter(|&x| x > lo[j]).map(|x| k.value(x)),
                upper: h.filter(|&x| x < hi[j]).map(|x| k.value(x)),
                identifiable: inside(l) && inside(h),
                search_bounds: [k.value(lo[j]), k.value(hi[j])],
            }
        })
        .collect()
}
