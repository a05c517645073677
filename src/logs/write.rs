//! Writing logs: numbers that read back bit for bit, and the logs of a simulated realization.

use std::fmt::Write as _;
use std::io::Write;

use super::{ACCEL_COLUMNS, GPS_COLUMNS, TRUTH_COLUMNS};
use crate::model::Timeline;
use crate::simulation::{FixState, Observer, SampleState};

/// Appends `x` to `out` in the shortest form that parses back to the same double: plain decimals
/// (Rust's `{}`) between 10⁻⁵ and 10¹⁶, exponent form (`{:e}`) outside, where plain decimals
/// would run to hundreds of digits. Both are shortest round-trip representations.
///
/// # Examples
/// ```
/// let mut s = String::new();
/// for x in [0.1 + 0.2, -3.0, 1e-300, 0.005 * 3.0] {
///     accelcal::logs::write::push_number(&mut s, x);
///     s.push(' ');
/// }
/// assert_eq!(s, "0.30000000000000004 -3 1e-300 0.015 ");
/// ```
pub fn push_number(out: &mut String, x: f64) {
    let a = x.abs();
    // Writing into a String cannot fail.
    let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}

/// Appends one CSV row of `values` and a line end.
pub fn push_row(out: &mut String, values: &[f64]) {
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_number(out, x);
    }
    out.push('\n');
}

/// The header line of a log with `columns`.
pub fn header(columns: &[&str]) -> String {
    format!("{}\n", columns.join(","))
}

/// An [`Observer`] that writes a realization's logs while it runs: the accelerometer's output at
/// every sample, the GPS fix at every fix, and the truth at every sample. Memory stays bounded
/// whatever the run's length.
pub struct LogWriter<'a> {
    timeline: &'a Timeline,
    accel: &'a mut dyn Write,
    gps: &'a mut dyn Write,
    truth: &'a mut dyn Write,
    row: String,
    samples: usize,
    fixes: usize,
    error: Option<std::io::Error>,
}

impl<'a> LogWriter<'a> {
    /// Writes the three headers and returns the observer.
    ///
    /// # Errors
    /// The first error of a writer.
    pub fn new(
        timeline: &'a Timeline,
        accel: &'a mut dyn Write,
        gps: &'a mut dyn Write,
        truth: &'a mut dyn Write,
    ) -> std::io::Result<Self> {
        accel.write_all(header(&ACCEL_COLUMNS).as_bytes())?;
        gps.write_all(header(&GPS_COLUMNS).as_bytes())?;
        truth.write_all(header(&TRUTH_COLUMNS).as_bytes())?;
        Ok(Self {
            timeline,
            accel,
            gps,
            truth,
            row: String::with_capacity(128),
            samples: 0,
            fixes: 0,
            error: None,
        })
    }

    /// Samples and fixes written; or the first write error.
    ///
    /// # Errors
    /// The first error a writer returned while the realization ran.
    pub fn finish(self) -> std::io::Result<(usize, usize)> {
        match self.error {
            Some(e) => Err(e),
            None => Ok((self.samples, self.fixes)),
        }
    }

    fn emit(&mut self, values: &[f64], to: Target) {
        if self.error.is_some() {
            return;
        }
        self.row.clear();
        push_row(&mut self.row, values);
        let writer: &mut dyn Write = match to {
            Target::Accel => self.accel,
            Target::Gps => self.gps,
            Target::Truth => self.truth,
        };
        if let Err(e) = writer.write_all(self.row.as_bytes()) {
            self.error = Some(e);
        }
    }
}

#[derive(Clone, Copy)]
enum Target {
    Accel,
    Gps,
    Truth,
}

impl Observer for LogWriter<'_> {
    const SAMPLES: bool = true;

    fn sample(&mut self, s: &SampleState) {
        let t_s = self.timeline.time_s(s.step);
        self.emit(&[t_s, s.accel_output_m_s2], Target::Accel);
        self.emit(
            &[t_s, s.truth_p_m, s.truth_v_m_s, s.bias_m_s2],
            Target::Truth,
        );
        self.samples += 1;
    }

    fn fix(&mut self, f: &FixState) {
        // The fix time is its sample's time, computed the same way: they match exactly.
        let t_s = self.timeline.time_s(self.timeline.fix_steps[f.index]);
        self.emit(&[t_s, f.z[0], f.z[1]], Target::Gps);
        self.fixes += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_bit_for_bit() {
        let mut s = String::new();
        let values = [
            0.0,
            -0.0,
            1.0 / 3.0,
            -2.5e-7,
            123456.789e10,
            f64::MIN_POSITIVE,
            f64::MAX,
            1e16 - 2.0,
            1e16,
        ];
        for x in values {
            s.clear();
            push_number(&mut s, x);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x} written as {s}");
            assert!(s.len() <= 24, "{s}");
        }
    }
}
