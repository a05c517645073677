//! What the pass over the logs learned, and the rules it sets: the median step and the
//! steps accepted around it, whether the nominal recursion applies, and which step each GPS
//! fix falls in.

use crate::input::csv::steps::ACCEPTED_STEP_RATIO;
use crate::input::csv::{AccelSample, GpsFix};
use crate::input::{LogError, LogProblem};

use super::StepMode;
use super::integration::update_time_s;
use super::pass::Reduced;

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
    /// Half the median step: how far before the first sample or after the last a fix may lie
    /// (it is applied at that sample), s.
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

impl Scan {
    /// What the pass learned, with the GPS log's `fixes` (named `gps_name`), checked to lie in
    /// the span of the accelerometer log.
    ///
    /// # Errors
    /// [`LogProblem::FixOutsideSpan`] for the first fix beyond half the median step of the
    /// first or the last sample.
    pub fn of(reduced: &Reduced, fixes: Vec<GpsFix>, gps_name: &str) -> Result<Self, LogError> {
        let median_step_s = reduced.median.median().unwrap_or(f64::NAN);
        let (first, last) = reduced.span_s;
        let tolerance_s = 0.5 * median_step_s;
        for f in &fixes {
            if f.t_s < first - tolerance_s || f.t_s > last + tolerance_s {
                return Err(LogError::at(
                    gps_name,
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
            samples: reduced.samples,
            span_s: reduced.span_s,
            median_step_s,
            step_range_s: (reduced.step_range.0.step_s(), reduced.step_range.1.step_s()),
            mode: if reduced.nominal {
                StepMode::Nominal
            } else {
                StepMode::PerStep
            },
            gps: fixes,
            gps_name: gps_name.to_string(),
        })
    }
}

/// Places each fix in the step of the sample at or before it, as the samples stream past.
pub struct FixMatcher<'a> {
    scan: &'a Scan,
    next: usize,
}

impl<'a> FixMatcher<'a> {
    /// Before the first sample.
    pub fn new(scan: &'a Scan) -> Self {
        Self { scan, next: 0 }
    }

    fn error(&self, fix: &GpsFix, problem: LogProblem) -> LogError {
        LogError::at(&self.scan.gps_name, fix.line, problem)
    }

    /// The fixes in the step from the sample at `t_s` to the next one at `next_s` (all that
    /// remain at the last sample, `next_s` = `None`), in order: the one at `t_s` first, if any.
    ///
    /// # Errors
    /// [`LogProblem::FixOnTakenSample`] for a second fix that [`update_time_s`] puts at the time
    /// of another (two fixes beyond one end of the log).
    pub fn in_step(
        &mut self,
        t_s: f64,
        next_s: Option<f64>,
    ) -> Result<std::ops::Range<usize>, LogError> {
        let first = self.next;
        let at = |f: &GpsFix| update_time_s(f.t_s, t_s, next_s.is_none());
        while let Some(fix) = self.scan.gps.get(self.next) {
            if next_s.is_some_and(|n| fix.t_s >= n) {
                break;
            }
            if self.next > first {
                let before = &self.scan.gps[self.next - 1];
                if at(before) == at(fix) {
                    return Err(self.error(
                        fix,
                        LogProblem::FixOnTakenSample {
                            t_s: fix.t_s,
                            sample_s: at(fix),
                            other_line: before.line,
                        },
                    ));
                }
            }
            self.next += 1;
        }
        Ok(first..self.next)
    }

    /// Checks that every fix found its step.
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
