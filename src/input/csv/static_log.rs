//! A static accelerometer log read into memory (`allan --accel`), with the step checks of
//! `calibrate`: strictly increasing time stamps, and every step within [`ACCEPTED_STEP_RATIO`]
//! of the median step.
//!
//! # Format
//! The CSV text of [`super`]: `t_s` and the column read (`accel_m_s2`, or any one column named).

use crate::input::container::{Kind, not_a_log};
use crate::input::csv::piped::CSV_EXPECTED;
use crate::input::csv::read::{AccelReader, LogSource};
use crate::input::csv::steps::ACCEPTED_STEP_RATIO;
use crate::input::{LogError, LogProblem};

/// The samples of one axis and the median step τ₀.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSamples {
    /// The column's value at every sample, m/s².
    pub values: Vec<f64>,
    /// The median step τ₀, s.
    pub sample_period_s: f64,
}

/// Bytes of log text per stretch parsed by one thread.
const STRETCH_BYTES: usize = 8 << 20;

/// One stretch of the log's rows with the header in front: the log reader reads it as a log of
/// its own, and its lines are shifted back to the file's.
struct Stretch<'a> {
    name: &'a str,
    header: &'a [u8],
    body: &'a [u8],
}

impl LogSource for Stretch<'_> {
    fn name(&self) -> &str {
        self.name
    }

    fn open(&self) -> Result<Box<dyn std::io::BufRead + '_>, LogError> {
        Ok(Box::new(std::io::Read::chain(self.header, self.body)))
    }
}

/// The samples of one stretch, up to its first problem (lines counted within the stretch).
struct Parsed {
    times: Vec<f64>,
    values: Vec<f64>,
    first_line: Option<u64>,
    error: Option<LogError>,
}

fn parse(stretch: &Stretch<'_>, column: &'static str) -> Parsed {
    let mut p = Parsed {
        times: Vec::with_capacity(stretch.body.len() / 24),
        values: Vec::with_capacity(stretch.body.len() / 24),
        first_line: None,
        error: None,
    };
    let mut reader = match AccelReader::with_column(stretch, column) {
        Ok(r) => r,
        Err(e) => {
            p.error = Some(e);
            return p;
        }
    };
    loop {
        match reader.next_sample() {
            Ok(Some(s)) => {
                p.first_line.get_or_insert(s.line);
                p.times.push(s.t_s);
                p.values.push(s.accel_m_s2);
            }
            Ok(None) => return p,
            Err(e) => {
                p.error = Some(e);
                return p;
            }
        }
    }
}

/// The log's text cut after its header and into stretches that end at line ends, each with the
/// number of lines before it (header included).
fn stretches<'a>(name: &'a str, text: &'a [u8]) -> Vec<(Stretch<'a>, u64)> {
    let header_end = text
        .iter()
        .position(|&b| b == b'\n')
        .map_or(text.len(), |i| i + 1);
    let (header, body) = text.split_at(header_end);
    let mut out = Vec::new();
    let (mut from, mut lines_before) = (0usize, 0u64);
    while from < body.len() || out.is_empty() {
        let target = (from + STRETCH_BYTES).min(body.len());
        let to = body[target..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(body.len(), |i| target + i + 1);
        let part = &body[from..to];
        out.push((
            Stretch {
                name,
                header,
                body: part,
            },
            lines_before,
        ));
        lines_before += part.iter().filter(|&&b| b == b'\n').count() as u64;
        from = to;
    }
    out
}

/// Reads `column` of the accelerometer log `source` (every row checked by the log reader, the
/// rows parsed in stretches on all threads) and checks its steps against the median, as
/// `calibrate` does. The median is exact here (calibrate's bounded-memory histogram gives the
/// same while a log has at most 4096 distinct steps).
///
/// # Errors
/// [`LogError`] naming the file and the line of the first problem: a malformed row, a time
/// stamp not after the previous, fewer than two rows, or a step outside the accepted band
/// (a gap or an extra sample).
pub fn read_static_log(
    source: &dyn LogSource,
    column: &'static str,
) -> Result<StaticSamples, LogError> {
    use rayon::prelude::*;
    use std::io::BufRead as _;
    let unreadable =
        |message: String| LogError::of_file(source.name(), LogProblem::Unreadable { message });
    let mut input = source.open()?;
    // Binary data (a device, a recording) is refused at its first bytes, before it is held.
    let head = input.fill_buf().map_err(|e| unreadable(e.to_string()))?;
    match Kind::of(head) {
        Kind::Text | Kind::Gzip => {}
        Kind::Binary => return Err(not_a_log(source.name(), head, CSV_EXPECTED)),
        kind => {
            let words = kind.words();
            return Err(unreadable(format!(
                "{words}, not a CSV log: expected {CSV_EXPECTED} (an IMU recording is read by \
                 `allan --imu`)"
            )));
        }
    }
    let mut text = Vec::new();
    std::io::Read::read_to_end(&mut input, &mut text).map_err(|e| unreadable(e.to_string()))?;
    let parts = stretches(source.name(), &text);
    let parsed: Vec<Parsed> = parts.par_iter().map(|(s, _)| parse(s, column)).collect();
    let (mut times, mut values) = (Vec::new(), Vec::new());
    for (p, (_, lines_before)) in parsed.into_iter().zip(&parts) {
        let shift = |line: u64| if line >= 2 { line + lines_before } else { line };
        if let (Some(&previous_s), Some(&t_s), Some(line)) =
            (times.last(), p.times.first(), p.first_line)
            && t_s <= previous_s
        {
            let problem = LogProblem::NotIncreasing { t_s, previous_s };
            return Err(LogError::at(source.name(), shift(line), problem));
        }
        if let Some(mut e) = p.error {
            e.line = e.line.map(shift);
            return Err(e);
        }
        times.extend_from_slice(&p.times);
        values.extend_from_slice(&p.values);
    }
    let Some(median_s) = median_step(&times) else {
        return Err(LogError::of_file(
            source.name(),
            LogProblem::TooFewRows {
                found: times.len() as u64,
                needed: 2,
            },
        ));
    };
    if let Some((i, problem)) = first_gap(&times, median_s) {
        return Err(LogError::at(
            source.name(),
            line_of(source, column, i)?,
            problem,
        ));
    }
    Ok(StaticSamples {
        values,
        sample_period_s: median_s,
    })
}

/// The first sample whose step from the one before leaves [`ACCEPTED_STEP_RATIO`] of the median
/// step `median_s`: its index and the problem, or `None` when every step is within.
pub(crate) fn first_gap(times: &[f64], median_s: f64) -> Option<(usize, LogProblem)> {
    use rayon::prelude::*;
    let (lo, hi) = (
        ACCEPTED_STEP_RATIO.0 * median_s,
        ACCEPTED_STEP_RATIO.1 * median_s,
    );
    let i = times
        .par_windows(2)
        .position_first(|w| !(lo..=hi).contains(&(w[1] - w[0])))?;
    let (previous_s, t_s) = (times[i], times[i + 1]);
    let step_s = t_s - previous_s;
    let problem = LogProblem::Gap {
        previous_s,
        t_s,
        step_s,
        ratio: step_s / median_s,
        median_s,
    };
    Some((i + 1, problem))
}

/// The median of the steps between consecutive `times` (the mean of the two middle ones for an
/// even count); `None` with fewer than two times.
pub fn median_step(times: &[f64]) -> Option<f64> {
    use rayon::prelude::*;
    if times.len() < 2 {
        return None;
    }
    let mut steps: Vec<f64> = times.par_windows(2).map(|w| w[1] - w[0]).collect();
    let n = steps.len();
    let (_, &mut upper, _) = steps.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        return Some(upper);
    }
    let lower = steps[..n / 2]
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    Some(0.5 * (lower + upper))
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
    use crate::input::csv::read::LogText;

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

    #[test]
    fn the_median_step_equals_calibrates_histogram() {
        let times: Vec<f64> = (0..1001)
            .map(|i| i as f64 * 0.01 + ((i * 7) % 5) as f64 * 1e-4)
            .collect();
        let mut m = crate::input::csv::steps::StepMedian::new();
        for w in times.windows(2) {
            m.add(w[1] - w[0]);
        }
        assert_eq!(median_step(&times), m.median());
        assert_eq!(median_step(&times[..1000]), {
            let mut m = crate::input::csv::steps::StepMedian::new();
            times[..1000].windows(2).for_each(|w| m.add(w[1] - w[0]));
            m.median()
        });
    }

    #[test]
    fn stretches_keep_the_files_lines() {
        // Rows across several stretches: a problem far into the file names its own line.
        let mut text = String::from("t_s,accel_m_s2\n");
        let rows = 3 * STRETCH_BYTES / 12;
        for i in 0..rows {
            text.push_str(&format!("{i},1.5\n"));
        }
        text.push_str("x,1\n");
        let e = read_static_log(&LogText::new("s.csv", text.clone()), "accel_m_s2").unwrap_err();
        assert_eq!(e.line, Some(rows as u64 + 2));
        assert!(matches!(e.problem, LogProblem::NotANumber { .. }));
        // A time stamp going back at the first row of a later stretch.
        let back = text.replacen(&format!("\n{},1.5\n", rows / 2), "\n0,1.5\n", 1);
        let e = read_static_log(&LogText::new("s.csv", back), "accel_m_s2").unwrap_err();
        assert_eq!(e.line, Some(rows as u64 / 2 + 2));
        assert!(matches!(e.problem, LogProblem::NotIncreasing { .. }));
        let ok = text.replace("x,1\n", "");
        let s = read_static_log(&LogText::new("s.csv", ok), "accel_m_s2").unwrap();
        assert_eq!(s.values.len(), rows);
    }
}
