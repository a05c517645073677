//! Noise statistics from simulated drives: `calibrate --estimate-noise` on drives whose truth is
//! known. Each drive is simulated into logs in memory and calibrated through the same path as a
//! recorded one (the logs' text, the one pass, the search, the intervals); the study keeps the
//! estimates against the truth and counts how often each interval covers it.
//!
//! The drives use the `euler` truth, for which the filter's error model is exact: with the
//! analytic truth and point samples the filter's own model error (the Euler lag) would be
//! measured along with the estimator's.

use rayon::prelude::*;

use crate::calibrate::{self, CalibrateError, Settings};
use crate::config::{BiasModelKind, Config, TruthModel};
use crate::error::FilterError;
use crate::filter::FilterSchedule;
use crate::input::csv::read::LogText;
use crate::likelihood::{Key, NoiseEstimate, Request};
use crate::logs::write::LogWriter;
use crate::model::Model;
use crate::progress::Progress;
use crate::simulation;
use crate::stats::binomial_band;

/// Simulated drives of the report's study.
pub const NOISE_DRIVES: u64 = 200;
/// Length of each drive, s.
pub const NOISE_DURATION_S: f64 = 120.0;
/// K of the truth's random-walk bias, m/s² per √s: over a drive the bias moves by about
/// K·√120 ≈ 0.022 m/s², many times the σ a GPS-aided filter reaches on a constant bias.
pub const NOISE_K_M_S2_PER_SQRT_S: f64 = 2e-3;
/// How far from the truth the search starts: every statistic searched is configured in
/// `[filter]` at this multiple of the truth's.
pub const NOISE_START_FACTOR: f64 = 3.0;
/// The intervals' confidence.
pub const NOISE_CONFIDENCE: f64 = 0.95;
/// The false-alarm rate of the coverage band.
pub const NOISE_FALSE_ALARM_RATE: f64 = 0.01;
/// The statistics the study estimates.
pub const NOISE_KEYS: [Key; 3] = [Key::GpsPosition, Key::GpsVelocity, Key::BiasRandomWalk];

/// How often one statistic's intervals covered the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyCoverage {
    /// The statistic.
    pub key: Key,
    /// Its true value.
    pub truth: f64,
    /// Drives on which it was identifiable (both interval ends inside the search's bounds).
    pub identifiable: u64,
    /// Of those, the intervals that covered the truth.
    pub covered: u64,
    /// The binomial band of covered counts at the confidence, both ends accepted.
    pub band: (u64, u64),
    /// Intervals of half the width (in the statistic's logarithm, about the estimate) that
    /// covered: the negative control, which must fall outside the band.
    pub half_width_covered: u64,
    /// The median of estimate / truth over the identifiable drives.
    pub median_ratio: f64,
}

impl KeyCoverage {
    /// Whether the covered count lies in its band.
    pub fn holds(&self) -> bool {
        (self.band.0..=self.band.1).contains(&self.covered)
    }

    /// Whether the negative control's count lies in the band (it should not).
    pub fn half_width_holds(&self) -> bool {
        (self.band.0..=self.band.1).contains(&self.half_width_covered)
    }
}

/// The study.
#[derive(Clone, Debug)]
pub struct NoiseStudy {
    /// Drives simulated.
    pub drives: u64,
    /// Length of each, s.
    pub duration_s: f64,
    /// The configuration of the drives (the truth, and the filter's starting statistics).
    pub config: Config,
    /// Every drive's estimate, by index.
    pub estimates: Vec<NoiseEstimate>,
    /// The coverage of each statistic, in [`NOISE_KEYS`]' order.
    pub coverage: Vec<KeyCoverage>,
}

/// The configuration of the study's drives from `config`: its rates and statistics, the euler
/// truth over [`NOISE_DURATION_S`] with a random-walk bias of [`NOISE_K_M_S2_PER_SQRT_S`], and a
/// filter that assumes a random walk with every searched statistic at
/// [`NOISE_START_FACTOR`] × the truth's.
pub fn drive_config(config: &Config) -> Config {
    let mut c = config.clone();
    c.profile.duration_s = NOISE_DURATION_S;
    c.ensemble.truth = TruthModel::Euler;
    c.checks.residual_pair_s = None;
    let a = &mut c.accelerometer;
    a.bias_model = BiasModelKind::RandomWalk;
    a.bias_random_walk_m_s2_per_sqrt_s = Some(NOISE_K_M_S2_PER_SQRT_S);
    a.bias_correlation_time_s = None;
    c.filter = Default::default();
    c.filter.bias_model = Some(BiasModelKind::RandomWalk);
    c.filter.bias_random_walk_m_s2_per_sqrt_s = Some(NOISE_K_M_S2_PER_SQRT_S * NOISE_START_FACTOR);
    c.filter.gps_position_sigma_m = Some(c.gps.position_sigma_m * NOISE_START_FACTOR);
    c.filter.gps_velocity_sigma_m_s = Some(c.gps.velocity_sigma_m_s * NOISE_START_FACTOR);
    c
}

/// Simulates drive `index` of `model` into logs in memory and calibrates it with `request`.
///
/// # Errors
/// [`CalibrateError`] as [`calibrate::prepare_with`] (not for a simulated drive).
pub fn run_drive(
    model: &Model,
    schedule: &FilterSchedule,
    index: u64,
    request: &Request,
) -> Result<NoiseEstimate, CalibrateError> {
    let (mut accel, mut gps, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    let mut writer = LogWriter::new(&model.timeline, &mut accel, &mut gps, &mut truth)?;
    simulation::run_realization(
        model,
        schedule,
        model.config.ensemble.seed,
        index,
        &mut writer,
    );
    writer.finish()?;
    let (accel, gps) = (
        LogText::new("accelerometer.csv", accel),
        LogText::new("gps.csv", gps),
    );
    let settings = Settings::from_model(model);
    let prepared = calibrate::prepare_with(&accel, &gps, &settings, Some(request))?;
    Ok(prepared
        .noise_estimate()
        .cloned()
        .expect("an estimate was asked for"))
}

/// Runs the study: [`NOISE_DRIVES`] (or `drives`) drives of [`drive_config`]`(config)`, on all
/// threads, the same numbers on any number of them.
///
/// `None` when the configuration cannot run a drive of [`NOISE_DURATION_S`] (its rates do not
/// fit that length), as the drifting-bias study does.
///
/// # Errors
/// [`FilterError`] when the configuration's filter is not positive definite; a drive that
/// cannot be calibrated counts as one whose statistics are not identifiable.
pub fn run(
    config: &Config,
    drives: u64,
    progress: &mut dyn Progress,
) -> Result<Option<NoiseStudy>, FilterError> {
    let config = drive_config(config);
    let Ok(model) = Model::new(&config) else {
        return Ok(None);
    };
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    let request = Request {
        keys: NOISE_KEYS.to_vec(),
        confidence: NOISE_CONFIDENCE,
    };
    progress.start("noise statistics from drives", drives);
    let estimates: Vec<Option<NoiseEstimate>> = (0..drives)
        .into_par_iter()
        .map(|i| run_drive(&model, &schedule, i, &request).ok())
        .collect();
    progress.advance(drives);
    progress.finish();
    let truth = truth_stats(&model);
    let estimates: Vec<NoiseEstimate> = estimates.into_iter().flatten().collect();
    let coverage = NOISE_KEYS
        .iter()
        .enumerate()
        .map(|(j, &key)| key_coverage(key, truth[j], &estimates, j))
        .collect();
    Ok(Some(NoiseStudy {
        drives,
        duration_s: NOISE_DURATION_S,
        config,
        estimates,
        coverage,
    }))
}

/// The true values of [`NOISE_KEYS`] in the drives of `model`.
pub fn truth_stats(model: &Model) -> [f64; 3] {
    NOISE_KEYS.map(|k| k.get(&model.truth_stats))
}

/// The coverage of statistic `j` (`key`, true value `truth`) over `estimates`.
pub fn key_coverage(key: Key, truth: f64, estimates: &[NoiseEstimate], j: usize) -> KeyCoverage {
    let mut ratios = Vec::new();
    let (mut covered, mut half) = (0, 0);
    for e in estimates {
        let k = &e.keys[j];
        if !k.identifiable {
            continue;
        }
        let upper = k.upper.unwrap_or(f64::INFINITY);
        covered += u64::from(k.lower <= truth && truth <= upper);
        // The same interval at half its width about the estimate, in the logarithm.
        let (lo, hi) = (k.value.ln() - k.lower.ln(), upper.ln() - k.value.ln());
        let t = truth.ln() - k.value.ln();
        half += u64::from(-lo / 2.0 <= t && t <= hi / 2.0);
        ratios.push(k.value / truth);
    }
    ratios.sort_by(f64::total_cmp);
    let n = ratios.len() as u64;
    KeyCoverage {
        key,
        truth,
        identifiable: n,
        covered,
        band: binomial_band(n, NOISE_CONFIDENCE, NOISE_FALSE_ALARM_RATE),
        half_width_covered: half,
        median_ratio: ratios.get(ratios.len() / 2).copied().unwrap_or(f64::NAN),
    }
}
