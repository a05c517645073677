//! Simulated drives whose GPS errors are correlated, calibrated as recorded ones: the bias's
//! intervals against its known truth, and how often the summary says its interval is
//! conditional on a rejected model.
//!
//! A drive is simulated into logs in memory with the `euler` truth and a constant bias (the
//! filter's error model is then exact but for the GPS). With [`GpsMarkov`] every fix also
//! carries a first-order Gauss–Markov error in position and in velocity (independent, of
//! stationary σ and correlation time τ), and the filter assumes white GPS errors of the total
//! σ, √(σ_white² + σ_gm²): the right spread, the wrong correlation. Without it the drive is
//! consistent: the filter's model is the truth's.

use rayon::prelude::*;

use crate::calibrate::{self, CalibrateError, Settings};
use crate::config::{BiasModelKind, Config, TruthModel};
use crate::error::FilterError;
use crate::filter::FilterSchedule;
use crate::input::csv::GPS_COLUMNS;
use crate::input::csv::read::LogText;
use crate::input::csv::text::{header, push_row};
use crate::logs::write::LogWriter;
use crate::model::Model;
use crate::random::Stream;
use crate::simulation;

/// Length of each drive, s.
pub const DRIVE_DURATION_S: f64 = 120.0;
/// The stream key of the Gauss–Markov draws (the simulation's own streams are keyed by seed).
const MARKOV_KEY: u64 = 0x6770_735f_6d61_726b;

/// A first-order Gauss–Markov GPS error (Maybeck 1979, Stochastic Models, Estimation and
/// Control vol. 1, §4.11): g(t + Δ) = e^{−Δ/τ}·g(t) + σ·√(1 − e^{−2Δ/τ})·n, g(0) ~ N(0, σ²),
/// in position and in velocity, each its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsMarkov {
    /// Stationary σ of the position error, m.
    pub position_sigma_m: f64,
    /// Stationary σ of the velocity error, m/s.
    pub velocity_sigma_m_s: f64,
    /// Correlation time τ, s.
    pub correlation_time_s: f64,
}

/// One drive's bias against its truth.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveBias {
    /// The true (constant) bias, m/s².
    pub truth_m_s2: f64,
    /// The summary's bias, σ and flags.
    pub summary: calibrate::summary::Summary,
}

impl DriveBias {
    /// Whether the filter's 95 % interval b̂ ± z·σ covers the truth.
    pub fn white_covers(&self) -> bool {
        let z = crate::stats::normal_bound(1.0 - calibrate::robust::CONFIDENCE);
        let s = &self.summary;
        (self.truth_m_s2 - s.bias_m_s2).abs() <= z * s.bias_sigma_m_s2
    }

    /// Whether the robust interval covers the truth.
    pub fn robust_covers(&self) -> bool {
        let r = &self.summary.bias_robust;
        (r.lower..=r.upper).contains(&self.truth_m_s2)
    }
}

/// The drives' configuration from `config`: its rates and statistics, the euler truth over
/// [`DRIVE_DURATION_S`], a constant bias, a filter that assumes the truth's statistics.
pub fn drive_config(config: &Config) -> Config {
    let mut c = config.clone();
    c.profile.duration_s = DRIVE_DURATION_S;
    c.ensemble.truth = TruthModel::Euler;
    c.checks.residual_pair_s = None;
    let a = &mut c.accelerometer;
    a.bias_model = BiasModelKind::Constant;
    a.bias_random_walk_m_s2_per_sqrt_s = None;
    a.bias_correlation_time_s = None;
    c.filter = Default::default();
    c
}

/// Simulates drive `index` of `model`, adds `markov`'s error to its fixes if given, and
/// calibrates it.
///
/// # Errors
/// [`CalibrateError`] as [`calibrate::prepare_with`] (not for a simulated drive).
pub fn run_drive(
    model: &Model,
    schedule: &FilterSchedule,
    index: u64,
    markov: Option<GpsMarkov>,
) -> Result<DriveBias, CalibrateError> {
    let (mut accel, mut gps, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    let mut writer = LogWriter::new(&model.timeline, &mut accel, &mut gps, &mut truth)?;
    let seed = model.config.ensemble.seed;
    simulation::run_realization(model, schedule, seed, index, &mut writer);
    writer.finish()?;
    let mut settings = Settings::from_model(model);
    if let Some(g) = markov {
        gps = add_markov(&gps, g, &mut Stream::new(seed ^ MARKOV_KEY, index));
        let f = &mut settings.filter_stats;
        f.gps_position_sigma_m = f.gps_position_sigma_m.hypot(g.position_sigma_m);
        f.gps_velocity_sigma_m_s = f.gps_velocity_sigma_m_s.hypot(g.velocity_sigma_m_s);
    }
    let truth_m_s2 = last_bias(&truth);
    let (accel, gps) = (
        LogText::new("accelerometer.csv", accel),
        LogText::new("gps.csv", gps),
    );
    let prepared = calibrate::prepare_with(&accel, &gps, &settings, None)?;
    Ok(DriveBias {
        truth_m_s2,
        summary: prepared.calibration().summary,
    })
}

/// Drives `0..drives` of [`drive_config`]`(config)` with `markov`, on all threads; a drive that
/// cannot be calibrated is left out.
///
/// # Errors
/// [`FilterError`] when the configuration's filter is not positive definite; `None` when the
/// configuration cannot run a drive of [`DRIVE_DURATION_S`].
pub fn run(
    config: &Config,
    drives: u64,
    markov: Option<GpsMarkov>,
) -> Result<Option<Vec<DriveBias>>, FilterError> {
    let config = drive_config(config);
    let Ok(model) = Model::new(&config) else {
        return Ok(None);
    };
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    Ok(Some(
        (0..drives)
            .into_par_iter()
            .filter_map(|i| run_drive(&model, &schedule, i, markov).ok())
            .collect(),
    ))
}

/// The GPS log `gps` (the writer's rows: t, position, velocity) with a Gauss–Markov error
/// added to every fix.
fn add_markov(gps: &[u8], g: GpsMarkov, stream: &mut Stream) -> Vec<u8> {
    let text = String::from_utf8_lossy(gps);
    let mut out = header(&GPS_COLUMNS);
    let (mut e, mut last_t) = ([0.0; 2], f64::NAN);
    let sigma = [g.position_sigma_m, g.velocity_sigma_m_s];
    for line in text.lines().skip(1) {
        let row: Vec<f64> = line.split(',').filter_map(|x| x.parse().ok()).collect();
        let [t, p, v] = row[..] else { continue };
        let a = (-(t - last_t) / g.correlation_time_s).exp();
        for k in 0..2 {
            // The first fix draws from the stationary law (a = NaN there).
            e[k] = if a.is_finite() {
                a * e[k] + sigma[k] * (1.0 - a * a).sqrt() * stream.normal()
            } else {
                sigma[k] * stream.normal()
            };
        }
        last_t = t;
        push_row(&mut out, &[t, p + e[0], v + e[1]]);
    }
    out.into_bytes()
}

/// The bias of the truth log's last row.
fn last_bias(truth: &[u8]) -> f64 {
    let text = String::from_utf8_lossy(truth);
    text.lines()
        .last()
        .and_then(|l| l.rsplit(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or(f64::NAN)
}
