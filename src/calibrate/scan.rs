//! The first pass over the logs, and the rules it sets for the second: the median step and the
//! steps accepted around it, whether the nominal recursion applies, and which sample each GPS
//! fix belongs to.

use crate::logs::read::{AccelReader, LogSource, read_gps};
use crate::logs::steps::{ACCEPTED_STEP_RATIO, StepMedian};
use crate::logs::{AccelSample, GpsFix, LogError, LogProblem};

use super::StepMode;

/// Relative tolerance within which every step of a log must equal the configured Δt for the
/// nominal recursion to run: time stamps written as j·Δt differ from j·Δt by a rounding error.
pub const NOMINAL_TOLERANCE: f64 = 1e-9;

/// What the first pass learned.
#[derive(Clone, Debug)]
pub struct Scan {
    /// Accelerometer samples.
    pub samples: u64,
    /// First and last accelerometer time stamps, s.
    pub span_s: (f64, f64),
    /// Median step, s.
    pub median_step_s: f64,
    /// Shortest and longest step, s.
    pub step_range_s: (f64, f64),
    /// Nominal or per-step Δt.
    pub mode: StepMode,
    /// Every GPS fix.
    pub gps: Vec<GpsFix>,
    /// Name of the GPS log in messages.
    pub gps_name: String,
}

impl Scan {
    /// Half the median step: how far from a sample a fix may lie, s.
    pub fn tolerance_s(&self) -> f64 {
        0.5 * self.median_step_s
    }

    /// The accepted steps, s.
    pub fn accepted_step_s(&self) -> (f64, f64) {
        (
            ACCEPTED_STEP_RATIO.0 * self.median_step_s,
            ACCEPTED_STEP_RATIO.1 * self.median_step_s,
        )
    }

    /// Checks the step from `previous` to `next` of the accelerometer log `file`.
    ///
    /// # Errors
    /// [`LogProblem::Gap`] at `next`'s line when the step is outside the accepted band.
    pub fn check_step(
        &self,
        file: &str,
        previous: &AccelSample,
        next: &AccelSample,
    ) -> Result<(), LogError> {
        let step_s = next.t_s - previous.t_s;
        let (lo, hi) = self.accepted_step_s();
        if (lo..=hi).contains(&step_s) {
            return Ok(());
        }
        Err(LogError::at(
            file,
            next.line,
            LogProblem::Gap {
                previous_s: previous.t_s,
                t_s: next.t_s,
                step_s,
                ratio: step_s / self.median_step_s,
                median_s: self.median_step_s,
            },
        ))
    }
}

/// Reads the GPS log and streams the accelerometer log once: headers, numbers, increasing time
/// stamps, the median step, the Δt mode against `nominal_dt_s`, and every fix inside the span.
///
/// # Errors
/// [`LogError`] naming the file and line of the first problem.
pub fn scan(
    accel: &dyn LogSource,
    gps: &dyn LogSource,
    nominal_dt_s: f64,
) -> Result<Scan, LogError> {
    let fixes = read_gps(gps)?;
    let mut reader = AccelReader::open(accel)?;
    let mut median = StepMedian::new();
    let (mut first, mut last) = (None, None);
    let mut range = (f64::INFINITY, 0.0f64);
    let mut nominal = true;
    let mut samples = 0u64;
    while let Some(s) = reader.next_sample()? {
        if let Some(p) = last {
            let step = s.t_s - p;
            median.add(step);
            range = (range.0.min(step), range.1.max(step));
            nominal &= (step - nominal_dt_s).abs() <= NOMINAL_TOLERANCE * nominal_dt_s;
        }
        first.get_or_insert(s.t_s);
        last = Some(s.t_s);
        samples += 1;
    }
    let (Some(first), Some(last), Some(median_step_s)) = (first, last, median.median()) else {
        return Err(LogError::of_file(
            reader.file(),
            LogProblem::TooFewRows {
                found: samples,
                needed: 2,
            },
        ));
    };
    let tolerance_s = 0.5 * median_step_s;
    for f in &fixes {
        if f.t_s < first - tolerance_s || f.t_s > last + tolerance_s {
            return Err(LogError::at(
                gps.name(),
                f.line,
                LogProblem::FixOutsideSpan {
                    t_s: f.t_s,
                    first_s: first,
                    last_s: last,
                    tolerance_s,
                },
            ));
        }
    }
    Ok(Scan {
        samples,
        span_s: (first, last),
        median_step_s,
        step_range_s: range,
        mode: if nominal {
            StepMode::Nominal
        } else {
            StepMode::PerStep
        },
        gps: fixes,
        gps_name: gps.name().to_string(),
    })
}

/// Assigns each fix to the accelerometer sample nearest to it, as the samples stream past.
pub struct FixMatcher<'a> {
    scan: &'a Scan,
    next: usize,
    previous_s: Option<f64>,
}

impl<'a> FixMatcher<'a> {
    /// Before the first sample.
    pub fn new(scan: &'a Scan) -> Self {
        Self {
            scan,
            next: 0,
            previous_s: None,
        }
    }

    fn error(&self, fix: &GpsFix, problem: LogProblem) -> LogError {
        LogError::at(&self.scan.gps_name, fix.line, problem)
    }

    /// The index of the fix that belongs to the sample at `t_s` (followed by one at `next_s`, if
    /// any): the next fix within half the median step of it and nearer to it than to the next.
    ///
    /// # Errors
    /// [`LogProblem::FixBetweenSamples`] for a fix that no sample took, and
    /// [`LogProblem::FixOnTakenSample`] for a second fix on one sample.
    pub fn at_sample(&mut self, t_s: f64, next_s: Option<f64>) -> Result<Option<usize>, LogError> {
        let tol = self.scan.tolerance_s();
        let belongs = |f: &GpsFix| {
            let d = (f.t_s - t_s).abs();
            d <= tol && next_s.is_none_or(|n| d <= (n - f.t_s).abs())
        };
        let previous_s = self.previous_s.replace(t_s);
        let Some(fix) = self.scan.gps.get(self.next) else {
            return Ok(None);
        };
        if fix.t_s < t_s - tol {
            return Err(self.error(
                fix,
                LogProblem::FixBetweenSamples {
                    t_s: fix.t_s,
                    before_s: previous_s.unwrap_or(t_s),
                    after_s: t_s,
                    tolerance_s: tol,
                },
            ));
        }
        if !belongs(fix) {
            return Ok(None);
        }
        let index = self.next;
        self.next += 1;
        if let Some(second) = self.scan.gps.get(self.next)
            && belongs(second)
        {
            return Err(self.error(
                second,
                LogProblem::FixOnTakenSample {
                    t_s: second.t_s,
                    sample_s: t_s,
                    other_line: fix.line,
                },
            ));
        }
        Ok(Some(index))
    }

    /// Checks that every fix found its sample.
    ///
    /// # Errors
    /// [`LogProblem::FixOutsideSpan`] for the first fix left over.
    pub fn finish(&self) -> Result<(), LogError> {
        match self.scan.gps.get(self.next) {
            None => Ok(()),
            Some(fix) => Err(self.error(
                fix,
                LogProblem::FixOutsideSpan {
                    t_s: fix.t_s,
                    first_s: self.scan.span_s.0,
                    last_s: self.scan.span_s.1,
                    tolerance_s: self.scan.tolerance_s(),
                },
            )),
        }
    }
}
