//! Calibration from recorded logs: an accelerometer log and a GPS log in, the bias with its σ,
//! filtered and smoothed estimates at every sample, and the NIS test out.
//!
//! The accelerometer log is streamed once, never held: memory grows with the number of GPS
//! fixes, not samples.
//!
//! 1. `pass` reads the GPS log and streams the accelerometer log once (blocks parsed on all
//!    threads, stitched in order): format, increasing time stamps, the steps' histogram, whether
//!    every step equals the configured Δt (the nominal mode), each fix at its nearest sample,
//!    and between fixes what the filter needs: the integrated (p_c, v_c) at each fix and, per
//!    step, the interval's process noise as unit contributions.
//! 2. `intervals` checks what needed the median step (gaps, fixes between samples) and runs the
//!    filter fix to fix: in nominal mode the in-memory filter's recursion, operation for
//!    operation; then `smoother::backward` runs the Rauch–Tung–Striebel pass over the fixes.
//! 3. [`Prepared::write_fix_estimates`] writes one row per fix; with `--every-sample`,
//!    [`Prepared::write_estimates`] streams the log again, repeating the filter sample by
//!    sample (`forward`), and writes each sample's filtered and smoothed estimates.
//!
//! Nothing is written before the logs have passed every check.

pub mod diagnose;
mod forward;
mod intervals;
mod nis;
pub mod noise;
pub mod pass;
mod record;
mod scan;
mod smoother;
pub mod summary;
mod units;
pub mod warnings;

use std::io::Write;

use serde::Serialize;
use thiserror::Error;

use crate::error::FilterError;
use crate::filter::ErrorStateModel;
use crate::logs::read::{AccelReader, LogSource, read_gps};
use crate::logs::{LogError, LogProblem};
use crate::model::{Model, NoiseStats};
use crate::state::{ErrorState, StateMatrix, StateVector};
use forward::FilteredFix;
pub use nis::{NisTest, nis_test};
pub use pass::NOMINAL_TOLERANCE;
use scan::{FixMatcher, Scan};
use smoother::SmoothedFix;
use summary::EstimateRow;

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
    /// p_c(0): the mean of p(0), m.
    pub position_mean_m: f64,
    /// v_c(0): the mean of v(0), m/s.
    pub velocity_mean_m_s: f64,
    /// The statistics the filter assumes (`[filter]`, defaulting to the truth sections).
    pub filter_stats: NoiseStats,
    /// The configured step Δt = 1 / accelerometer.sample_rate_hz, s.
    pub nominal_dt_s: f64,
    /// The NIS test's false-alarm rate α (`checks.false_alarm_rate`).
    pub false_alarm_rate: f64,
    /// Whether the prior comes from the first fix, its σ's the GPS σ's (so P(0) follows them
    /// when they are estimated).
    pub prior_from_first_fix: bool,
}

impl Settings {
    /// The settings of a validated model.
    pub fn from_model(model: &Model) -> Self {
        let c = &model.config;
        Self {
            position_mean_m: c.initial.position_mean_m,
            velocity_mean_m_s: c.initial.velocity_mean_m_s,
            filter_stats: model.filter_stats,
            nominal_dt_s: model.timeline.dt_s,
            false_alarm_rate: c.checks.false_alarm_rate,
            prior_from_first_fix: false,
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

/// One sample of the forward pass as a visitor sees it.
type Visit<'v> =
    dyn FnMut(&forward::Forward<'_>, Option<&FilteredFix>) -> Result<(), CalibrateError> + 'v;

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
    let start = pass::Integrated {
        pc_m: settings.position_mean_m,
        vc_m_s: settings.velocity_mean_m_s,
    };
    let steps = (settings.nominal_dt_s, settings.filter_stats.bias_model);
    let reduced = pass::reduce(accel, &fixes, steps, start)?;
    let scan = Scan::of(&reduced, fixes, gps.name())?;
    let run = |stats: &NoiseStats| {
        let model = ErrorStateModel::new(settings.nominal_dt_s, stats);
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
        noise = Some(found);
    }
    let (model, (fixes, end)) = run(&settings.filter_stats)?;
    Ok(Prepared {
        settings,
        model,
        accel,
        smoothed: smoother::backward(&fixes),
        fixes,
        scan,
        end,
        noise,
    })
}

impl Prepared<'_> {
    /// One pass of the integration and the filter over the accelerometer log, handing every
    /// sample (after its fix, if any) to `visit`. Returns the number of samples.
    fn forward_pass(&self, visit: &mut Visit<'_>) -> Result<u64, CalibrateError> {
        let mut reader = AccelReader::open(self.accel)?;
        let changed = || LogError::of_file(self.accel.name(), LogProblem::Changed);
        let mut matcher = FixMatcher::new(&self.scan);
        let Some(mut current) = reader.next_sample()? else {
            return Err(changed().into());
        };
        let s = &self.settings;
        // The accelerometer line of the previous fix: the rows integrated since are behind the
        // next fix's prediction.
        let mut since_line = current.line;
        let mut fw = forward::Forward::new(
            &self.model,
            ErrorState {
                stats: self.settings.filter_stats,
            },
            self.scan.mode,
            s.position_mean_m,
            s.velocity_mean_m_s,
            current.t_s,
        );
        loop {
            let next = reader.next_sample()?;
            if let Some(n) = &next {
                self.scan.check_step(reader.file(), &current, n)?;
            }
            let fix = match matcher.at_sample(current.t_s, next.map(|n| n.t_s))? {
                Some(i) => Some(self.update_finite(&mut fw, i, (reader.file(), since_line))?),
                None => None,
            };
            if fix.is_some() {
                since_line = current.line;
            }
            visit(&fw, fix.as_ref())?;
            match next {
                Some(n) => {
                    fw.advance(current.accel_m_s2, n.t_s);
                    // Overflow in the step or the integration: the row integrated is to blame.
                    if !fw.is_finite() {
                        let what = "the step to the next row, the integrated velocity and \
                                    position or their covariance is no longer a finite number: \
                                    a time stamp or acceleration here is too large"
                            .to_string();
                        let problem = LogProblem::Overflow { what };
                        return Err(LogError::at(reader.file(), current.line, problem).into());
                    }
                    current = n;
                }
                None => break,
            }
        }
        matcher.finish()?;
        if fw.k + 1 != self.scan.samples {
            return Err(changed().into());
        }
        Ok(fw.k + 1)
    }

    /// The measurement update with fix `i` of the scan; `accel` is the accelerometer log's name
    /// and the line of the previous fix's sample.
    ///
    /// # Errors
    /// [`FilterError`] as [`forward::Forward::update`]; [`LogProblem::Overflow`] when the fix's
    /// residual, NIS or estimate is not finite: naming the fix's line when the fix is the larger
    /// of the fix and the integrated (p_c, v_c) it is compared with, else the accelerometer rows
    /// integrated since the previous fix.
    fn update_finite(
        &self,
        fw: &mut forward::Forward<'_>,
        i: usize,
        (accel, since_line): (&str, u64),
    ) -> Result<FilteredFix, CalibrateError> {
        let gps = &self.scan.gps[i];
        let fix = fw.update(gps)?;
        if fix.is_finite() {
            return Ok(fix);
        }
        let largest = |v: &[f64]| v.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
        let error = if largest(fix.z.as_slice()) >= largest(fix.integrated.as_slice()) {
            let what = "the filter's residual, NIS or estimate at this fix is no longer a \
                        finite number: its position or velocity is too large"
                .to_string();
            LogError::at(&self.scan.gps_name, gps.line, LogProblem::Overflow { what })
        } else {
            let what = format!(
                "the residual of the fix at {} line {} is no longer a finite number: the velocity \
                 and position integrated from this row to that fix's sample are too large (an \
                 acceleration of those rows is)",
                self.scan.gps_name, gps.line
            );
            let line = since_line.max(1);
            LogError::at(accel, line, LogProblem::Overflow { what })
        };
        Err(error.into())
    }

    /// Runs the filter sample by sample over the log once more, as `--every-sample` writes
    /// it, and takes its fixes: in per-step mode their numbers then are those of the
    /// per-sample recursion (the reduced pass agrees to rounding); in nominal mode they are
    /// the same bits already, and nothing is read.
    ///
    /// # Errors
    /// As [`Prepared::write_estimates`].
    pub fn per_sample(&mut self) -> Result<(), CalibrateError> {
        if self.scan.mode == StepMode::Nominal {
            return Ok(());
        }
        let mut fixes = Vec::with_capacity(self.fixes.len());
        let mut end = self.end;
        self.forward_pass(&mut |fw, fix| {
            if let Some(f) = fix {
                fixes.push(f.clone());
            }
            end = (fw.x, fw.p);
            Ok(())
        })?;
        if fixes.len() != self.fixes.len() {
            return Err(LogError::of_file(self.accel.name(), LogProblem::Changed).into());
        }
        self.smoothed = smoother::backward(&fixes);
        self.fixes = fixes;
        self.end = end;
        Ok(())
    }

    /// Writes `estimates.csv` to `out`, one row per GPS fix: the a priori, a posteriori and
    /// smoothed estimates with their σ, the innovation with its σ, and the NIS.
    ///
    /// # Errors
    /// [`CalibrateError::Write`] when `out` fails.
    pub fn write_fix_estimates(&self, out: &mut dyn Write) -> Result<(), CalibrateError> {
        let header = format!("{}\n", summary::FIX_ESTIMATES_COLUMNS.join(","));
        out.write_all(header.as_bytes())?;
        let mut row = String::with_capacity(1024);
        // Every fix of the GPS log was applied, in order.
        for ((f, sm), gps) in self.fixes.iter().zip(&self.smoothed).zip(&self.scan.gps) {
            row.clear();
            summary::push_fix_row(&mut row, f, gps.t_s, sm);
            out.write_all(row.as_bytes())?;
        }
        out.flush()?;
        Ok(())
    }

    /// Writes `estimates.csv` to `out`, one row per sample in time order (`--every-sample`):
    /// the log read again.
    ///
    /// # Errors
    /// [`CalibrateError::Write`] when `out` fails; [`LogProblem::Changed`] when the log no longer
    /// reads as it did.
    pub fn write_estimates(&self, out: &mut dyn Write) -> Result<(), CalibrateError> {
        let header = format!("{}\n", summary::ESTIMATES_COLUMNS.join(","));
        out.write_all(header.as_bytes())?;
        let mut rows = summary::EstimateChunks::new(out);
        let mut next = 0usize;
        let changed = || LogError::of_file(self.accel.name(), LogProblem::Changed);
        self.forward_pass(&mut |fw, fix| {
            if let Some(f) = fix
                && self.fixes.get(next) != Some(f)
            {
                return Err(changed().into());
            }
            // The first fix after this sample: its smoothed estimate carries back to here.
            while self.fixes.get(next).is_some_and(|f| f.sample <= fw.k) {
                next += 1;
            }
            let (xs, ps) = match (self.fixes.get(next), self.smoothed.get(next)) {
                (Some(f), Some(sm)) => sm.smooth(&fw.x, &fw.p, &fw.transition_to(f)),
                _ => (fw.x, fw.p),
            };
            let row = EstimateRow {
                t_s: fw.t_s,
                fix: fix.is_some(),
                integrated: [fw.pc_m, fw.vc_m_s],
                filtered: (&fw.x, &fw.p),
                smoothed: (&xs, &ps),
            };
            rows.push(row.values())?;
            Ok(())
        })?;
        rows.flush()?;
        Ok(())
    }
}
