//! A realization's sensors as the driver's sources ([`crate::ins::driver`]): the IMU reading the
//! shared truth's increments with its own errors, and the receiver reporting a fix at every IMU
//! step that falls on the GNSS rate, its noise drawn from the same stream after the step's.

use crate::ins::drive::Drive;
use crate::ins::driver::{ImuSource, ImuStep, Source};
use crate::ins::gnss::FixUpdate;
use crate::ins::measurement::Measurement;
use crate::ins::sensors::Imu;
use crate::ins::setup::Scenario;
use crate::ins::simulated_logs::fix;

use super::Track;

/// The realization's IMU over the shared truth.
pub struct SimulatedImu<'a> {
    /// The scenario.
    pub scenario: &'a Scenario,
    /// The truth.
    pub track: &'a Track,
    /// The drive (its motion, for the receiver's antenna).
    pub drive: Drive,
    /// The realization's sensors and random stream.
    pub imu: Imu,
    /// Steps read.
    pub steps: usize,
}

impl crate::ins::driver::Context for SimulatedImu<'_> {
    fn truth(&self) -> Option<&crate::ins::mech::Pva> {
        Some(SimulatedImu::truth(self))
    }

    fn normal(&mut self) -> f64 {
        self.imu.normal()
    }
}

impl<'a> SimulatedImu<'a> {
    /// Realization sensors `imu` over `track`, the truth of `scenario`, before its first step.
    pub fn new(scenario: &'a Scenario, track: &'a Track, imu: Imu) -> Self {
        SimulatedImu {
            scenario,
            track,
            drive: scenario.drive(),
            imu,
            steps: 0,
        }
    }

    /// The true state at the end of the last step read.
    pub fn truth(&self) -> &crate::ins::mech::Pva {
        self.steps
            .checked_sub(1)
            .map_or(&self.track.start, |k| &self.track.steps[k].1)
    }
}

impl ImuSource for SimulatedImu<'_> {
    type Error = std::convert::Infallible;

    fn next_step(&mut self) -> Result<Option<ImuStep>, Self::Error> {
        let Some((inc, _)) = self.track.steps.get(self.steps) else {
            return Ok(None);
        };
        let increment = self.imu.read(inc);
        self.steps += 1;
        Ok(Some(ImuStep {
            // The row of imu.csv it would be (the header is line 1).
            line: self.steps as u64 + 1,
            t_s: self.steps as f64 / self.scenario.imu_rate_hz,
            increment,
        }))
    }
}

/// The receiver: a fix every `imu_steps_per_fix` IMU steps, weighed with the σ's the filter
/// assumes.
pub struct SimulatedGnss {
    /// The fixes given.
    pub given: usize,
    /// IMU steps between fixes.
    pub every: usize,
    /// The IMU's rate, Hz.
    pub rate_hz: f64,
    /// The truth's steps.
    pub steps: usize,
}

impl SimulatedGnss {
    /// The receiver of `scenario` over `track`.
    pub fn of(scenario: &Scenario, track: &Track) -> Self {
        SimulatedGnss {
            given: 0,
            every: scenario.imu_steps_per_fix,
            rate_hz: scenario.imu_rate_hz,
            steps: track.steps.len(),
        }
    }
}

impl<const N: usize> Source<N, SimulatedImu<'_>> for SimulatedGnss {
    fn next_time(&self) -> Option<f64> {
        let k = (self.given + 1) * self.every;
        (k <= self.steps).then(|| k as f64 / self.rate_hz)
    }

    fn take(&mut self, imu: &mut SimulatedImu<'_>) -> Box<dyn Measurement<N>> {
        let t = Source::<N, SimulatedImu<'_>>::next_time(self).expect("a fix is due");
        self.given += 1;
        let (scenario, pva) = (imu.scenario, *imu.truth());
        let mut reading = fix(scenario, &imu.drive, &mut imu.imu, t, &pva);
        // The filter weighs the fix with the σ's it assumes.
        reading.position_sigma_m = scenario.filter_gnss.position_sigma_m;
        reading.velocity_sigma_m_s = scenario.filter_gnss.velocity_sigma_m_s;
        Box::new(FixUpdate::whole(reading))
    }
}
