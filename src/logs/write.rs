//! Writing the logs of a simulated realization, every number in the form that reads back bit
//! for bit ([`crate::input::csv::text`]).

use std::io::Write;

use super::TRUTH_COLUMNS;
use crate::input::csv::text::{header, push_row};
use crate::input::csv::{ACCEL_COLUMNS, GPS_COLUMNS};
use crate::model::Timeline;
use crate::simulation::{FixState, Observer, SampleState};

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
