//! One driver for every three-axis run: a time-ordered loop over an IMU source and any number of
//! timed measurement sources, used by the Monte Carlo ensemble (a simulated IMU and GNSS) and by
//! `calibrate --imu` (a recording) alike.
//!
//! At each IMU step (its output over (t − Δt, t]) the driver updates by every measurement due
//! within the step, earliest first (a tie in the order of the sources): the step is cut at the
//! measurement's time, its increments shared in proportion, the part before propagated, the
//! filter updated there, the rest propagated after. A measurement that falls in one of its
//! source's outages ([`Outage`]) is taken from its source (a simulation's random stream stays as
//! it would be) but withheld from the filter. The observer sees the filter before each update,
//! with P current, and the update's outcome after it.

use super::error_state::STATES;
use super::filter::{Ekf, FilterError, Innovation};
use super::measurement::{Gate, Measurement};
use super::mech::Increment;
pub use crate::input::records::ImuStep;

/// Where the IMU's steps come from, in time order.
pub trait ImuSource {
    /// Why a step cannot be read.
    type Error;
    /// The next step; `None` at the end.
    ///
    /// # Errors
    /// The source's problem at that step.
    fn next_step(&mut self) -> Result<Option<ImuStep>, Self::Error>;
}

/// What a measurement source may read of the IMU source it runs beside.
pub trait Context {
    /// The true navigation state at the last step, when the drive is simulated.
    fn truth(&self) -> Option<&super::mech::Pva>;
    /// A draw of N(0, 1) for a simulated measurement's noise from the realization's stream; 0
    /// on a recording (its measurement is what was recorded).
    fn normal(&mut self) -> f64;
}

/// A source of timed measurements, in time order, made with the IMU source `C` at hand (a
/// simulation reads the truth and draws the receiver's noise from the realization's stream).
pub trait Source<const N: usize, C: ?Sized> {
    /// The time of its next measurement, s; `None` when it has no more.
    fn next_time(&self) -> Option<f64>;
    /// Its next measurement, the one at [`Source::next_time`].
    fn take(&mut self, imu: &mut C) -> Box<dyn Measurement<N>>;
}

/// An interval in which a source's measurements are withheld from the filter: those at
/// `from_s` < t ≤ `to_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outage {
    /// The source, by its place in the driver's list.
    pub source: usize,
    /// The interval's start, s (excluded).
    pub from_s: f64,
    /// Its end, s (included).
    pub to_s: f64,
}

/// A measurement the driver is about to hand the filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Due {
    /// Its source, by its place in the driver's list.
    pub source: usize,
    /// Its place among its source's measurements, from 0.
    pub index: usize,
    /// Its time, s.
    pub t_s: f64,
}

/// What became of a measurement handed to the driver.
#[derive(Clone, Debug, PartialEq)]
pub enum Update<const N: usize = STATES> {
    /// The filter tested it, and updated by it unless the gate rejected it
    /// ([`Innovation::accepted`]).
    Tested(Innovation<N>),
    /// An outage withheld it.
    Withheld,
}

/// Who watches the run: the filter before each update (P current) and each outcome.
pub trait Observer<const N: usize, C: ?Sized> {
    /// Why the run must stop.
    type Error;
    /// The filter before the update by `due` (not called for a withheld one).
    ///
    /// # Errors
    /// The observer's, which stops the run.
    fn before(&mut self, _ekf: &mut Ekf<N>, _imu: &C, _due: &Due) -> Result<(), Self::Error> {
        Ok(())
    }
    /// The filter after the update by `due`, and what became of it.
    ///
    /// # Errors
    /// The observer's, which stops the run.
    fn after(
        &mut self,
        ekf: &Ekf<N>,
        imu: &C,
        due: &Due,
        update: Update<N>,
    ) -> Result<(), Self::Error>;
}

/// Why a run stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum DriveError<E> {
    /// The filter's covariance stopped being positive definite.
    Filter(FilterError),
    /// The IMU source's or the observer's error.
    Other(E),
}

/// The driver: its measurement sources, their outages, the χ² gate and the filter's start.
pub struct Driver<'a, const N: usize, C: ?Sized> {
    /// The measurement sources.
    pub sources: Vec<&'a mut dyn Source<N, C>>,
    /// The intervals in which a source is withheld.
    pub outages: Vec<Outage>,
    /// The gate every update is tested by; `None`: every innovation is taken.
    pub gate: Option<Gate>,
    /// The filter's start, s: the parts of steps before it are not propagated.
    pub start_s: f64,
    /// How many measurements each source has given.
    taken: Vec<usize>,
}

/// The increments of `inc` (the step ending at `end`, starting at `start`) over [`lo`, `hi`],
/// in proportion; the step itself when that is the whole of it.
fn cut(inc: &Increment, (start, end): (f64, f64), lo: f64, hi: f64) -> Increment {
    if lo == start && hi == end {
        return *inc;
    }
    let frac = (hi - lo) / inc.dt_s;
    Increment {
        dtheta_rad: inc.dtheta_rad * frac,
        dvel_m_s: inc.dvel_m_s * frac,
        dt_s: hi - lo,
    }
}

impl<'a, const N: usize, C: ImuSource + ?Sized> Driver<'a, N, C> {
    /// A driver of `sources`, ungated, with no outage, from the first step on.
    pub fn new(sources: Vec<&'a mut dyn Source<N, C>>) -> Self {
        let taken = vec![0; sources.len()];
        Driver {
            sources,
            outages: Vec::new(),
            gate: None,
            start_s: f64::NEG_INFINITY,
            taken,
        }
    }

    /// The same driver testing every update by `gate`.
    #[must_use]
    pub fn with_gate(mut self, gate: Option<Gate>) -> Self {
        self.gate = gate;
        self
    }

    /// The same driver withholding the measurements in `outages`.
    #[must_use]
    pub fn with_outages(mut self, outages: Vec<Outage>) -> Self {
        self.outages = outages;
        self
    }

    /// The same driver starting the filter at `start_s`.
    #[must_use]
    pub fn starting_at(mut self, start_s: f64) -> Self {
        self.start_s = start_s;
        self
    }

    /// The earliest measurement due at or before `t_s`: its source and time.
    fn due_by(&self, t_s: f64) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (k, s) in self.sources.iter().enumerate() {
            if let Some(t) = s.next_time().filter(|&t| t <= t_s)
                && best.is_none_or(|(_, b)| t < b)
            {
                best = Some((k, t));
            }
        }
        best
    }

    /// The measurement of `source` at `t_s` taken and handed to the filter (or withheld).
    fn measure<O>(
        &mut self,
        ekf: &mut Ekf<N>,
        imu: &mut C,
        observer: &mut O,
        (source, t_s): (usize, f64),
    ) -> Result<(), DriveError<O::Error>>
    where
        O: Observer<N, C>,
    {
        let m = self.sources[source].take(imu);
        let due = Due {
            source,
            index: self.taken[source],
            t_s,
        };
        self.taken[source] += 1;
        let withheld = self
            .outages
            .iter()
            .any(|o| o.source == source && o.from_s < t_s && t_s <= o.to_s);
        let update = if withheld {
            Update::Withheld
        } else {
            ekf.flush();
            observer.before(ekf, imu, &due).map_err(DriveError::Other)?;
            let innovation = ekf
                .update_by(m.as_ref(), self.gate.as_ref())
                .map_err(DriveError::Filter)?;
            Update::Tested(innovation)
        };
        observer
            .after(ekf, imu, &due, update)
            .map_err(DriveError::Other)
    }

    /// The filter `ekf` run over every step of `imu`, updated by every measurement due within
    /// them; `observer` sees each update.
    ///
    /// # Errors
    /// The IMU source's or the observer's error, or [`DriveError::Filter`].
    pub fn run<O>(
        &mut self,
        ekf: &mut Ekf<N>,
        imu: &mut C,
        observer: &mut O,
    ) -> Result<(), DriveError<O::Error>>
    where
        O: Observer<N, C>,
        C::Error: Into<O::Error>,
    {
        while let Some(step) = imu.next_step().map_err(|e| DriveError::Other(e.into()))? {
            let (t1, inc) = (step.t_s, step.increment);
            let t0 = t1 - inc.dt_s;
            if t1 < self.start_s {
                continue;
            }
            let mut from = if t0 < self.start_s { self.start_s } else { t0 };
            while let Some((source, t)) = self.due_by(t1) {
                if t > from {
                    ekf.propagate(&cut(&inc, (t0, t1), from, t));
                    from = t;
                }
                self.measure(ekf, imu, observer, (source, t))?;
            }
            if t1 > from {
                ekf.propagate(&cut(&inc, (t0, t1), from, t1));
            }
        }
        Ok(())
    }

    /// Every measurement due at or before `until_s` handed to the filter where it stands (after
    /// the IMU's last step: the fixes just past the log's end).
    ///
    /// # Errors
    /// The observer's error, or [`DriveError::Filter`].
    pub fn drain<O>(
        &mut self,
        ekf: &mut Ekf<N>,
        imu: &mut C,
        observer: &mut O,
        until_s: f64,
    ) -> Result<(), DriveError<O::Error>>
    where
        O: Observer<N, C>,
    {
        while let Some(due) = self.due_by(until_s) {
            self.measure(ekf, imu, observer, due)?;
        }
        Ok(())
    }
}
