//! Calibration from recorded logs: an accelerometer log and a GPS log in, the bias with its σ,
//! filtered and smoothed estimates at every sample, and the NIS test out.
//!
//! The accelerometer log is streamed once, never held: memory grows with the number of GPS
//! fixes, not samples.
//!
//! 1. `pass` reads the GPS log and streams the accelerometer log once (blocks parsed on all
//!    threads, stitched in order): format, increasing time stamps, the steps' histogram, whether
//!    every step equals the configured Δt (the nominal mode), each fix in the step that holds
//!    it, and between fixes what the filter needs: the integrated (p_c, v_c) at each fix's own
//!    time (`integration`: from the prior, or from the first fix) and, per step or piece of a
//!    step a fix cuts, the interval's process noise as unit contributions.
//! 2. `intervals` checks what needed the median step (gaps, two fixes at one end sample) and
//!    runs the filter fix to fix: in nominal mode the in-memory filter's recursion, operation
//!    for operation; then `smoother::backward` runs the Rauch–Tung–Striebel pass over the fixes.
//! 3. [`Prepared::write_fix_estimates`] writes one row per fix; with `--every-sample`,
//!    [`Prepared::write_estimates`] streams the log again (`replay`), repeating the filter
//!    sample by sample (`forward`), and writes each sample's filtered and smoothed estimates.
//!
//! Nothing is written before the logs have passed every check.

mod bartlett;
mod chunked;
pub mod diagnose;
mod forward;
pub mod imu;
mod integration;
mod intervals;
mod nis;
pub mod noise;
pub mod pass;
mod record;
mod replay;
pub mod robust;
mod scan;
mod smoother;
pub mod summary;
pub mod symmetric;
mod units;
pub mod warnings;

use std::io::Write;

use serde::Serialize;
use thiserror::Error;

use crate::config::Config;
use crate::error::{ConfigError, FilterError};
use crate::filter::ErrorStateModel;
use crate::input::LogError;
use crate::input::csv::GpsFix;
use crate::input::csv::read::{LogSource, read_gps};
use crate::model::{Model, NoiseStats, filter_stats, validate_calibration};
use crate::state::{StateMatrix, StateVector};
use forward::FilteredFix;
pub use nis::{NisTest, nis_test, nis_test_rows};
pub use pass::NOMINAL_TOLERANCE;
use scan::Scan;
use smoother::SmoothedFix;

/// How each step's Δt is taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepMode {
    /// Every step equals the configured Δt to a relative 10⁻⁹: the constant Δt and the
    /// in-memory filter's recursion, operation for operation (a simulated log calibrates to the
    /// simulation's bits).
    Nominal,
    /// Φ(Δt_j) and Q(Δt_j) from each pair of consecutive time stamps.
    PerStep,
}

impl StepMode {
    /// The name in `summary.json`.
    pub fn name(self) -> &'static str {
        match self {
            StepMode::Nominal => "nominal",
            StepMode::PerStep => "per_step",
        }
    }
}

/// What a calibration takes from the configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// p_c(0): the mean of p(0), m (unused when `prior_from_first_fix`).
    pub position_mean_m: f64,
    /// v_c(0): the mean of v(0), m/s (unused when `prior_from_first_fix`).
    pub velocity_mean_m_s: f64,
    /// The statistics the filter assumes (`[filter]`, defaulting to the truth sections). With
    /// `prior_from_first_fix`, P(0)'s σ's are the GPS σ's: `initial_position_sigma_m` =
    /// `gps_position_sigma_m`, `initial_velocity_sigma_m_s` = `gps_velocity_sigma_m_s`.
    pub filter_stats: NoiseStats,
    /// The configured step Δt = 1 / accelerometer.sample_rate_hz, s; `None` when the
    /// configuration sets no rate: the log's median step is taken, and the Δt mode is per-step.
    pub nominal_dt_s: Option<f64>,
    /// The NIS test's false-alarm rate α (`checks.false_alarm_rate`).
    pub false_alarm_rate: f64,
    /// Whether the prior comes from the first GPS fix (no `[initial]` section): its position and
    /// velocity carried back to the first sample ([`pass::Start::FirstFix`]), with the GPS σ's
    /// as P(0)'s σ's. Code that changes the GPS σ's of `filter_stats` re-derives P(0) with
    /// [`Settings::with_gps_sigmas`].
    pub prior_from_first_fix: bool,
}

impl Settings {
    /// The settings of a validated model: the configured prior and rate.
    pub fn from_model(model: &Model) -> Self {
        let c = &model.config;
        Self {
            position_mean_m: c.initial.position_mean_m,
            velocity_mean_m_s: c.initial.velocity_mean_m_s,
            filter_stats: model.filter_stats,
            nominal_dt_s: Some(model.timeline.dt_s),
            false_alarm_rate: c.checks.false_alarm_rate,
            prior_from_first_fix: false,
        }
    }

    /// The settings of `config` as `calibrate --config` takes them: [`Self::from_config`] with
    /// the rate and the prior as the file `text` sets them (none without a file), an error
    /// pointed at its line there.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first key outside its accepted range.
    pub fn from_config_text(
        config: &Config,
        text: Option<&crate::config::ConfigText>,
    ) -> Result<Self, ConfigError> {
        let sets = |key: &str| text.is_some_and(|t| t.sets(key));
        Self::from_config(
            config,
            sets("accelerometer.sample_rate_hz"),
            sets("initial"),
        )
        .map_err(|e| match text {
            Some(t) => t.locate(e),
            None => e,
        })
    }

    /// The settings of a recording's configuration `config`, checking only the keys a
    /// calibration uses ([`validate_calibration`]): `rate_set` when it sets
    /// `accelerometer.sample_rate_hz`, `initial_set` when it has an `[initial]` section.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first key outside its accepted range.
    pub fn from_config(
        config: &Config,
        rate_set: bool,
        initial_set: bool,
    ) -> Result<Self, ConfigError> {
        validate_calibration(config, rate_set, initial_set)?;
        let settings = Self {
            position_mean_m: config.initial.position_mean_m,
            velocity_mean_m_s: config.initial.velocity_mean_m_s,
            filter_stats: filter_stats(config),
            nominal_dt_s: rate_set.then(|| 1.0 / config.accelerometer.sample_rate_hz),
            false_alarm_rate: config.checks.false_alarm_rate,
            prior_from_first_fix: !initial_set,
        };
        let (p, v) = (
            settings.filter_stats.gps_position_sigma_m,
            settings.filter_stats.gps_velocity_sigma_m_s,
        );
        Ok(settings.with_gps_sigmas(p, v))
    }

    /// The same settings with the GPS σ's `position_sigma_m` and `velocity_sigma_m_s`, and
    /// with them P(0)'s σ's when the prior comes from the first fix.
    pub fn with_gps_sigmas(mut self, position_sigma_m: f64, velocity_sigma_m_s: f64) -> Self {
        let f = &mut self.filter_stats;
        f.gps_position_sigma_m = position_sigma_m;
        f.gps_velocity_sigma_m_s = velocity_sigma_m_s;
        if self.prior_from_first_fix {
            f.initial_position_sigma_m = position_sigma_m;
            f.initial_velocity_sigma_m_s = velocity_sigma_m_s;
        }
        self
    }

    /// Where the integration starts, given the GPS log's `fixes`.
    fn start(&self, fixes: &[GpsFix]) -> pass::Start {
        match fixes.first() {
            Some(f) if self.prior_from_first_fix => pass::Start::FirstFix {
                t_s: f.t_s,
                position_m: f.position_m,
                velocity_m_s: f.velocity_m_s,
            },
            _ => pass::Start::Prior(pass::Integrated {
                pc_m: self.position_mean_m,
                vc_m_s: self.velocity_mean_m_s,
            }),
        }
    }
}

/// A calibration that could not be completed.
#[derive(Debug, Error)]
pub enum CalibrateError {
    /// A log is bad input.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The filter's covariance stopped being positive definite.
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The estimates could not be written.
    #[error("cannot write the estimates: {0}")]
    Write(#[from] std::io::Error),
}

impl CalibrateError {
    /// Whether the input is to blame (a bad log or filter statistics), not the machine.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, CalibrateError::Write(_))
    }
}

/// The logs checked and filtered, and the smoother's backward pass done: ready to write.
pub struct Prepared<'a> {
    settings: Settings,
    model: ErrorStateModel,
    /// (p_c, v_c) at the first sample, where the integration starts.
    start: pass::Integrated,
    accel: &'a dyn LogSource,
    scan: Scan,
    fixes: Vec<FilteredFix>,
    smoothed: Vec<SmoothedFix>,
    /// Filtered estimate and covariance at the last sample.
    end: (StateVector, StateMatrix),
    /// The noise statistics estimated from the drive (`--estimate-noise`), which the filter
    /// then ran with.
    noise: Option<crate::likelihood::NoiseEstimate>,
}

/// Checks the logs and reduces the accelerometer log in one streamed pass, then runs the
/// filter fix to fix and the smoother's backward pass: O(fixes) after the pass.
///
/// # Errors
/// [`CalibrateError::Log`] naming the file and line of the first problem of either log;
/// [`CalibrateError::Filter`] when a covariance is not positive definite.
pub fn prepare<'a>(
    accel: &'a dyn LogSource,
    gps: &dyn LogSource,
    settings: &Settings,
) -> Result<Prepared<'a>, CalibrateError> {
    prepare_with(accel, gps, settings, None)
}

/// [`prepare`], and with `estimate` the noise statistics it names estimated from the drive
/// first (maximum likelihood over the reduced log), the filter and smoother then run with them.
///
/// # Errors
/// As [`prepare`]; [`CalibrateError::Filter`] when the likelihood is not finite at the
/// configured statistics, where the search starts.
pub fn prepare_with<'a>(
    accel: &'a dyn LogSource,
    gps: &dyn LogSource,
    settings: &Settings,
    estimate: Option<&crate::likelihood::Request>,
) -> Result<Prepared<'a>, CalibrateError> {
    let mut settings = settings.clone();
    if let Some(request) = estimate {
        settings.filter_stats = noise::prepare_stats(&settings.filter_stats, request);
    }
    let fixes = read_gps(gps)?;
    let start = settings.start(&fixes);
    // Without a configured rate no step is nominal (NaN equals none).
    let steps = (
        settings.nominal_dt_s.unwrap_or(f64::NAN),
        settings.filter_stats.bias_model,
    );
    let reduced = pass::reduce(accel, &fixes, steps, start)?;
    let scan = Scan::of(&reduced, fixes, gps.name())?;
    let start = start.at(scan.span_s.0, reduced.first_accel_m_s2);
    let dt_s = settings.nominal_dt_s.unwrap_or(scan.median_step_s);
    let run = |stats: &NoiseStats| {
        let model = ErrorStateModel::new(dt_s, stats);
        let filtered = intervals::filter(&scan, &reduced, &model, stats, accel.name())?;
        Ok::<_, CalibrateError>((model, filtered))
    };
    let mut noise = None;
    if let Some(request) = estimate {
        let duration_s = scan.span_s.1 - scan.span_s.0;
        settings.filter_stats = noise::start_stats(&settings.filter_stats, duration_s);
        let (_, (fixes, _)) = run(&settings.filter_stats)?;
        let found = noise::estimate(
            &fixes,
            &reduced.fixes,
            &settings.filter_stats,
            (request, settings.prior_from_first_fix, duration_s),
        )
        // The filter just ran at these statistics, so ℓ is finite there unless a determinant
        // underflows.
        .ok_or(FilterError::InnovationNotPositiveDefinite {
            time_s: scan.span_s.0,
        })?;
        settings.filter_stats = found.stats;
        // A prior from the first fix takes the estimated GPS σ's.
        let (p, v) = (
            found.stats.gps_position_sigma_m,
            found.stats.gps_velocity_sigma_m_s,
        );
        settings = settings.with_gps_sigmas(p, v);
        noise = Some(found);
    }
    let stats = &settings.filter_stats;
    let model = ErrorStateModel::new(dt_s, stats);
    // The reduced log is freed as this last run goes, before the smoother's pass.
    let (fixes, end) = intervals::filter_last(&scan, reduced, &model, stats, accel.name())?;
    Ok(Prepared {
        settings,
        model,
        start,
        accel,
        smoothed: smoother::backward(&fixes),
        fixes,
        scan,
        end,
        noise,
    })
}

impl Prepared<'_> {
    /// Writes `estimates.csv` to `out`, one row per GPS fix: the a priori, a posteriori and
    /// smoothed estimates with their σ, the innovation with its σ, and the NIS. The rows are
    /// formatted a block of fixes at a time on all threads and written in order (the shortest
    /// round-trip form of 33 numbers a row is most of the work).
    ///
    /// # Errors
    /// [`CalibrateError::Write`] when `out` fails.
    pub fn write_fix_estimates(&self, out: &mut dyn Write) -> Result<(), CalibrateError> {
        use rayon::prelude::*;
        /// Fixes formatted at once, and per thread's share.
        const BLOCK: usize = 1 << 14;
        const SHARE: usize = BLOCK / 16;
        let header = format!("{}\n", summary::FIX_ESTIMATES_COLUMNS.join(","));
        out.write_all(header.as_bytes())?;
        // Every fix of the GPS log was applied, in order.
        let (fixes, smoothed, gps) = (&self.fixes, &self.smoothed, &self.scan.gps);
        let n = fixes.len().min(smoothed.len()).min(gps.len());
        for start in (0..n).step_by(BLOCK) {
            let end = (start + BLOCK).min(n);
            let texts: Vec<String> = (start..end)
                .into_par_iter()
                .step_by(SHARE)
                .map(|from| {
                    let to = (from + SHARE).min(end);
                    let mut text = String::with_capacity((to - from) * 640);
                    for i in from..to {
                        let gps_t_s = gps[i].t_s;
                        summary::push_fix_row(&mut text, &fixes[i], gps_t_s, &smoothed[i]);
                    }
                    text
                })
                .collect();
            for text in texts {
                out.write_all(text.as_bytes())?;
            }
        }
        out.flush()?;
        Ok(())
    }
}
