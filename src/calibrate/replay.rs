//! The log read again, sample by sample: the integration and the filter per sample
//! (`forward`), for `--every-sample`'s rows and its per-sample recursion.

use std::io::Write;

use crate::input::csv::read::AccelReader;
use crate::input::{LogError, LogProblem};
use crate::state::ErrorState;

use super::forward::{FilteredFix, Forward};
use super::integration::update_time_s;
use super::scan::FixMatcher;
use super::summary::{self, EstimateRow};
use super::{CalibrateError, Prepared, StepMode, smoother};

/// One sample of the forward pass as a visitor sees it, with the fixes applied since the
/// sample before it (in the step before it, or at the sample itself).
type Visit<'v> = dyn FnMut(&Forward<'_>, &[FilteredFix]) -> Result<(), CalibrateError> + 'v;

/// The overflow of the step from the row at `line` of `file`.
fn step_overflow(file: &str, line: u64) -> CalibrateError {
    let what = "the step to the next row, the integrated velocity and position or their \
                covariance is no longer a finite number: a time stamp or acceleration here is \
                too large"
        .to_string();
    LogError::at(file, line, LogProblem::Overflow { what }).into()
}

impl Prepared<'_> {
    /// One pass of the integration and the filter over the accelerometer log, handing every
    /// sample (after a fix at its time, if any) to `visit`. A fix between two samples is
    /// applied at its own time inside the step. Returns the number of samples.
    fn forward_pass(&self, visit: &mut Visit<'_>) -> Result<u64, CalibrateError> {
        let mut reader = AccelReader::open(self.accel)?;
        let changed = || LogError::of_file(self.accel.name(), LogProblem::Changed);
        let mut matcher = FixMatcher::new(&self.scan);
        let Some(mut current) = reader.next_sample()? else {
            return Err(changed().into());
        };
        // The accelerometer line of the previous fix: the rows integrated since are behind the
        // next fix's prediction.
        let mut since_line = current.line;
        let state = ErrorState {
            stats: self.settings.filter_stats,
        };
        let mut fw = Forward::new(&self.model, state, self.scan.mode, self.start, current.t_s);
        // The fixes applied since the last row.
        let mut applied: Vec<FilteredFix> = Vec::new();
        loop {
            let next = reader.next_sample()?;
            if let Some(n) = &next {
                self.scan.check_step(reader.file(), &current, n)?;
            }
            let fixes = matcher.in_step(current.t_s, next.map(|n| n.t_s))?;
            let mut within = Vec::with_capacity(fixes.len());
            for i in fixes {
                let t_fix = update_time_s(self.scan.gps[i].t_s, current.t_s, next.is_none());
                if t_fix == current.t_s {
                    let place = (reader.file(), since_line, None);
                    applied.push(self.update_finite(&mut fw, i, place)?);
                    since_line = current.line;
                } else {
                    within.push((i, t_fix));
                }
            }
            visit(&fw, &applied)?;
            applied.clear();
            // A fix inside the step has a next sample.
            let step_s = next.map_or(0.0, |n| n.t_s - current.t_s);
            for (i, t_fix) in within {
                let inside = (current.accel_m_s2, t_fix, step_s);
                let place = (reader.file(), since_line, Some(inside));
                applied.push(self.update_finite(&mut fw, i, place)?);
                since_line = current.line;
            }
            let Some(n) = next else { break };
            fw.advance(current.accel_m_s2, n.t_s);
            // Overflow in the step or the integration: the row integrated is to blame.
            if !fw.is_finite() {
                return Err(step_overflow(reader.file(), current.line));
            }
            current = n;
        }
        matcher.finish()?;
        if fw.k + 1 != self.scan.samples {
            return Err(changed().into());
        }
        Ok(fw.k + 1)
    }

    /// The measurement update with fix `i` of the scan, at the current sample or, with
    /// `within` = (the sample's output, the fix's time, the step), inside its step; `accel` is the
    /// accelerometer log's name and the line of the previous fix's sample.
    ///
    /// # Errors
    /// [`crate::error::FilterError`] as [`Forward::update`]; [`LogProblem::Overflow`] when the
    /// fix's residual, NIS or estimate is not finite: naming the fix's line when the fix is the
    /// larger of the fix and the integrated (p_c, v_c) it is compared with, else the
    /// accelerometer rows integrated since the previous fix.
    fn update_finite(
        &self,
        fw: &mut Forward<'_>,
        i: usize,
        (accel, since_line, within): (&str, u64, Option<(f64, f64, f64)>),
    ) -> Result<FilteredFix, CalibrateError> {
        let gps = &self.scan.gps[i];
        let fix = match within {
            None => fw.update(gps)?,
            Some((a, t_fix_s, step_s)) => fw.update_within(gps, a, (t_fix_s, step_s))?,
        };
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
    /// The reduced pass's fixes and their smoothed estimates are freed before the pass, so that
    /// the two sets are never held together (a million fixes: 400 MB each).
    ///
    /// # Errors
    /// As [`Prepared::write_estimates`]; the calibration holds no fixes then and is to be
    /// prepared again.
    pub fn per_sample(&mut self) -> Result<(), CalibrateError> {
        if self.scan.mode == StepMode::Nominal {
            return Ok(());
        }
        let count = self.fixes.len();
        (self.fixes, self.smoothed) = (Vec::new(), Vec::new());
        let mut fixes = Vec::with_capacity(count);
        let mut end = self.end;
        self.forward_pass(&mut |fw, applied| {
            fixes.extend_from_slice(applied);
            end = (fw.x, fw.p);
            Ok(())
        })?;
        if fixes.len() != count {
            return Err(LogError::of_file(self.accel.name(), LogProblem::Changed).into());
        }
        self.smoothed = smoother::backward(&fixes);
        self.fixes = fixes;
        self.end = end;
        Ok(())
    }

    /// Writes `estimates.csv` to `out`, one row per sample in time order (`--every-sample`):
    /// the log read again. `gps_fix` is 1 on a sample whose estimate took a fix since the
    /// sample before it (at the sample, or inside the step before it).
    ///
    /// # Errors
    /// [`CalibrateError::Write`] when `out` fails; [`LogProblem::Changed`] when the log no longer
    /// reads as it did.
    pub fn write_estimates(&self, out: &mut dyn Write) -> Result<(), CalibrateError> {
        let header = format!("{}\n", summary::ESTIMATES_COLUMNS.join(","));
        out.write_all(header.as_bytes())?;
        let mut rows = summary::EstimateChunks::new(out);
        let (mut seen, mut next) = (0usize, 0usize);
        // λ and Λ of the fix `next`, formed when its first sample comes.
        let mut carry: Option<(usize, smoother::Carry)> = None;
        let changed = || LogError::of_file(self.accel.name(), LogProblem::Changed);
        self.forward_pass(&mut |fw, applied| {
            for f in applied {
                if self.fixes.get(seen) != Some(f) {
                    return Err(changed().into());
                }
                seen += 1;
            }
            // The first fix after this sample: its smoothed estimate carries back to here.
            while self.fixes.get(next).is_some_and(|f| f.t_s <= fw.t_s) {
                next += 1;
            }
            let (xs, ps) = match (self.fixes.get(next), self.smoothed.get(next)) {
                (Some(f), Some(sm)) => {
                    if carry.as_ref().is_none_or(|(at, _)| *at != next) {
                        carry = Some((next, sm.carry(f)));
                    }
                    let (_, c) = carry.as_ref().expect("formed above");
                    c.smooth(&fw.x, &fw.p, &fw.transition_to(f))
                }
                _ => (fw.x, fw.p),
            };
            let row = EstimateRow {
                t_s: fw.t_s,
                fix: !applied.is_empty(),
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
