//! A static accelerometer log read into memory, with the step checks of `calibrate`: strictly
//! increasing time stamps, and every step within [`ACCEPTED_STEP_RATIO`] of the median step.

use crate::logs::read::{AccelReader, LogSource};
use crate::logs::steps::{ACCEPTED_STEP_RATIO, StepMedian};
use crate::logs::{LogError, LogProblem};

/// The samples of one axis and the median step τ₀.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSamples {
    /// The column's value at every sample, m/s².
    pub values: Vec<f64>,
    /// The median step τ₀, s.
    pub sample_period_s: f64,
}

/// Reads `column` of the accelerometer log `source` (every row checked by the log reader) and
/// checks its steps against the median, as `calibrate` does.
///
/// # Errors
/// [`LogError`] naming the file and the line of the first problem: a malformed row, a time
/// stamp not after the previous, fewer than two rows, or a step outside the accepted band
/// (a gap or an extra sample).
pub fn read_static_log(
    source: &dyn LogSource,
    column: &'static str,
) -> Result<StaticSamples, LogError> {
    let mut reader = AccelReader::with_column(source, column)?;
    let (mut times, mut values) = (Vec::new(), Vec::new());
    let mut median = StepMedian::new();
    while let Some(s) = reader.next_sample()? {
        if let Some(&p) = times.last() {
            median.add(s.t_s - p);
        }
        times.push(s.t_s);
        values.push(s.accel_m_s2);
    }
    let Some(median_s) = median.median() else {
        return Err(LogError::of_file(
            source.name(),
            LogProblem::TooFewRows {
                found: times.len() as u64,
                needed: 2,
            },
        ));
    };
    let (lo, hi) = (
        ACCEPTED_STEP_RATIO.0 * median_s,
        ACCEPTED_STEP_RATIO.1 * median_s,
    );
    if let Some(i) = times
        .windows(2)
        .position(|w| !(lo..=hi).contains(&(w[1] - w[0])))
    {
        let (previous_s, t_s) = (times[i], times[i + 1]);
        let step_s = t_s - previous_s;
        let problem = LogProblem::Gap {
            previous_s,
            t_s,
            step_s,
            ratio: step_s / median_s,
            median_s,
        };
        return Err(LogError::at(
            source.name(),
            line_of(source, column, i + 1)?,
            problem,
        ));
    }
    Ok(StaticSamples {
        values,
        sample_period_s: median_s,
    })
}

/// The line of sample `index` (counted from 0), read again: lines are kept only when needed.
fn line_of(source: &dyn LogSource, column: &'static str, index: usize) -> Result<u64, LogError> {
    let mut reader = AccelReader::with_column(source, column)?;
    let mut k = 0;
    while let Some(s) = reader.next_sample()? {
        if k == index {
            return Ok(s.line);
        }
        k += 1;
    }
    Err(LogError::of_file(source.name(), LogProblem::Changed))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logs::read::LogText;

    #[test]
    fn a_gap_names_its_line() {
        let src = LogText::new(
            "s.csv",
            "t_s,accel_m_s2\n0,1\n0.01,1\n\n0.02,1\n0.04,1\n0.05,1\n",
        );
        let e = read_static_log(&src, "accel_m_s2").unwrap_err();
        assert_eq!(e.line, Some(6));
        assert!(matches!(e.problem, LogProblem::Gap { .. }));
        let ok = LogText::new("s.csv", "t_s,accel_m_s2\n0,1\n0.01,2\n0.02,3\n");
        let s = read_static_log(&ok, "accel_m_s2").unwrap();
        assert_eq!(s.values, vec![1.0, 2.0, 3.0]);
        assert_eq!(s.sample_period_s, 0.01);
    }
}
