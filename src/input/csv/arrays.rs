//! An accelerometer log held as two arrays (time stamps and samples), for callers that have the
//! numbers already (the Python package): calibrate's pass reads them in place, with no text in
//! between; any other reader (the per-sample replay) reads the same numbers as CSV text
//! rendered in their shortest round-trip form, which parses back to the same doubles.

use std::io::{BufRead, Cursor};

use super::ACCEL_COLUMNS;
use super::read::LogSource;
use super::text::{header, push_row};
use crate::input::{LogError, LogProblem};

/// The accelerometer's samples as arrays: `t_s` (s) and `accel_m_s2` (m/s²), of equal length.
/// Sample `i` is the log's row `i`, on line `i + 2` of the equivalent CSV (after its header).
#[derive(Clone, Copy, Debug)]
pub struct AccelArrays<'a> {
    name: &'a str,
    t_s: &'a [f64],
    accel_m_s2: &'a [f64],
}

impl<'a> AccelArrays<'a> {
    /// The samples `accel_m_s2` at `t_s`, called `name` in messages.
    ///
    /// # Errors
    /// [`LogProblem::Unreadable`] when the two arrays differ in length.
    pub fn new(name: &'a str, t_s: &'a [f64], accel_m_s2: &'a [f64]) -> Result<Self, LogError> {
        if t_s.len() != accel_m_s2.len() {
            let message = format!(
                "{} time stamps and {} samples: expected one sample per time stamp",
                t_s.len(),
                accel_m_s2.len()
            );
            return Err(LogError::of_file(name, LogProblem::Unreadable { message }));
        }
        Ok(Self {
            name,
            t_s,
            accel_m_s2,
        })
    }

    /// The time stamps (s) and the samples (m/s²).
    pub fn columns(&self) -> (&'a [f64], &'a [f64]) {
        (self.t_s, self.accel_m_s2)
    }
}

impl LogSource for AccelArrays<'_> {
    fn name(&self) -> &str {
        self.name
    }

    /// The samples as CSV text (made on each call: only a reader that needs text calls it).
    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError> {
        let mut text = header(&ACCEL_COLUMNS);
        text.reserve(48 * self.t_s.len());
        for (&t, &a) in self.t_s.iter().zip(self.accel_m_s2) {
            push_row(&mut text, &[t, a]);
        }
        Ok(Box::new(Cursor::new(text.into_bytes())))
    }

    fn accel_columns(&self) -> Option<(&[f64], &[f64])> {
        Some(self.columns())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::csv::read::AccelReader;

    #[test]
    fn the_text_reads_back_as_the_same_doubles() {
        let t = [1e-300, 0.1 + 0.2, 7.0, 1e17];
        let a = [-3.0, 0.015, 1e20, f64::MIN_POSITIVE];
        let arrays = AccelArrays::new("arrays", &t, &a).unwrap();
        let mut reader = AccelReader::open(&arrays).unwrap();
        let mut k = 0;
        while let Some(s) = reader.next_sample().unwrap() {
            assert_eq!(
                (s.t_s.to_bits(), s.accel_m_s2.to_bits()),
                (t[k].to_bits(), a[k].to_bits())
            );
            k += 1;
        }
        assert_eq!(k, t.len());
        assert!(AccelArrays::new("arrays", &t, &a[..3]).is_err());
    }
}
