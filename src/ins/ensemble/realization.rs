//! One realization of the three-axis ensemble: its sensors and filter drawn from its stream, run
//! through the driver over the shared truth, each fix's errors before and after its update
//! normalized by the realization's own covariances.

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use super::simulated::{SimulatedGnss, SimulatedImu};
use super::{MEASURED, Normalized, RealizationError, Track, error};
use crate::ensemble::normalized::{FixInput, NormalizedFix, StageInput};
use crate::ins::driver::{DriveError, Driver, Due, Observer, Source, Update};
use crate::ins::earth::offset;
use crate::ins::error_state::{STATES, Square};
use crate::ins::extra::GNSS;
use crate::ins::filter::Ekf;
use crate::ins::mech::Pva;
use crate::ins::sensors::Imu;
use crate::ins::setup::Scenario;

/// What one realization's filter saw at one fix, after its update.
pub struct FixView<'a, const N: usize = STATES> {
    /// The fix's time, s.
    pub t_s: f64,
    /// The fix's index.
    pub fix: usize,
    /// The errors before and after the update, the correction, P and S.
    pub input: FixInput<N, MEASURED>,
    /// The filter after the update.
    pub ekf: &'a Ekf<N>,
    /// The true IMU now (its biases).
    pub imu: &'a Imu,
}

/// Realization `index`'s true IMU (its prior's draws taken from its stream) and its filter,
/// started from the truth plus a draw of its prior: position, velocity and attitude errors of
/// the scenario's initial σ's, the biases' prior from the filter's model.
pub fn start<const N: usize>(scenario: &Scenario, track: &Track, index: u64) -> (Imu, Ekf<N>) {
    let mut imu = scenario.imu(index);
    let s = &scenario.initial_sigma;
    let dr = imu.normals(&Vector3::new(s[0], s[1], s[2]));
    let dv = imu.normals(&Vector3::new(s[3], s[4], s[5]));
    let dpsi = imu.normals(&Vector3::new(s[6], s[7], s[8]));
    let truth = imu.pva_of(&track.start);
    let start = Pva {
        position: offset(&truth.position, &dr),
        velocity_ned_m_s: truth.velocity_ned_m_s + dv,
        attitude: UnitQuaternion::from_scaled_axis(dpsi) * truth.attitude,
    };
    let ekf = Ekf::new(
        start,
        scenario.prior_of::<N>(),
        scenario.filter_noise(),
        scenario.filter_decay(),
        scenario.filter_gnss.lever_arm_b_m,
    )
    .with_earth_rotation(scenario.filter_earth_rotation_rad_s)
    .with_mounting(scenario.filter_mounting());
    (imu, ekf)
}

/// Runs realization `index` of `scenario` over `track` — its filter started from the truth plus a
/// draw of its prior — through the driver, calling `on_fix` after every update; returns the
/// filter and the IMU at the end.
///
/// # Errors
/// [`RealizationError`] when a covariance stops being positive definite, or `on_fix`'s.
pub fn filter_realization<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    index: u64,
    on_fix: impl FnMut(&FixView<N>) -> Result<(), RealizationError>,
) -> Result<(Ekf<N>, Imu), RealizationError> {
    let (imu, mut ekf) = start(scenario, track, index);
    let mut sim = SimulatedImu::new(scenario, track, imu);
    let mut gnss = SimulatedGnss::of(scenario, track);
    let mut observer = Normalizer {
        index,
        prior: None,
        on_fix,
    };
    let mut extra =
        crate::ins::extra::sources::<N, SimulatedImu>(0.0, scenario.duration_s, &scenario.aids());
    let mut list = vec![&mut gnss as &mut dyn Source<N, SimulatedImu>];
    list.extend(
        extra
            .iter_mut()
            .map(|s| &mut **s as &mut dyn Source<N, SimulatedImu>),
    );
    Driver::new(list)
        .run(&mut ekf, &mut sim, &mut observer)
        .map_err(|e| match e {
            DriveError::Filter(source) => RealizationError::Filter { index, source },
            DriveError::Other(e) => e,
        })?;
    Ok((ekf, sim.imu))
}

/// The ensemble's observer: each fix's errors before and after its update against the truth,
/// handed to `on_fix`.
struct Normalizer<F, const N: usize> {
    /// The realization.
    index: u64,
    /// The error and P before the update in progress.
    prior: Option<(SVector<f64, N>, Square<N>)>,
    /// What is done with each fix.
    on_fix: F,
}

impl<const N: usize, F> Observer<N, SimulatedImu<'_>> for Normalizer<F, N>
where
    F: FnMut(&FixView<N>) -> Result<(), RealizationError>,
{
    type Error = RealizationError;

    fn before(
        &mut self,
        ekf: &mut Ekf<N>,
        sim: &SimulatedImu,
        due: &Due,
    ) -> Result<(), Self::Error> {
        if due.source != GNSS {
            return Ok(());
        }
        self.prior = Some((error(ekf, sim.truth(), &sim.imu), ekf.covariance));
        Ok(())
    }

    fn after(
        &mut self,
        ekf: &Ekf<N>,
        sim: &SimulatedImu,
        due: &Due,
        update: Update<N>,
    ) -> Result<(), Self::Error> {
        if due.source != GNSS {
            // Judged through the fixes that follow: the sums are per GNSS fix.
            return Ok(());
        }
        let (index, fix) = (self.index, due.index);
        let (Update::Tested(innovation), Some((e_prior, p_prior))) = (update, self.prior.take())
        else {
            return Err(RealizationError::Covariance { index, fix });
        };
        if innovation.residual.len() != MEASURED {
            return Err(RealizationError::Covariance { index, fix });
        }
        let e_post = error(ekf, sim.truth(), &sim.imu);
        let input = FixInput {
            prior: StageInput {
                error: e_prior,
                // Closed loop: the error state is reset to zero after every fix.
                estimate: SVector::zeros(),
                covariance: p_prior,
            },
            post: StageInput {
                error: e_post,
                // The correction the update applied, K·ν: the error's change (to first order).
                estimate: e_prior - e_post,
                covariance: ekf.covariance,
            },
            residual: SVector::from_fn(|j, _| innovation.residual[j]),
            residual_covariance: SMatrix::from_fn(|a, b| innovation.covariance[(a, b)]),
        };
        (self.on_fix)(&FixView {
            t_s: due.t_s,
            fix,
            input,
            ekf,
            imu: &sim.imu,
        })
    }
}

/// Realization `index`, its errors, corrections and innovations at every fix normalized by its
/// own covariances.
///
/// # Errors
/// [`RealizationError`] when a covariance stops being positive definite.
pub fn realization<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    index: u64,
) -> Result<Normalized<N>, RealizationError> {
    let mut out = Vec::with_capacity(track.steps.len() / scenario.imu_steps_per_fix);
    let (ekf, imu) = filter_realization(scenario, track, index, |v| {
        let bad = RealizationError::Covariance { index, fix: v.fix };
        out.push(NormalizedFix::of(&v.input, v.fix).map_err(|_| bad)?);
        Ok(())
    })?;
    let end = track.steps.last().map_or(&track.start, |x| &x.1);
    let p = ekf.covariance;
    Ok(Normalized {
        fixes: out,
        final_error: error(&ekf, end, &imu),
        final_sigma: SVector::from_fn(|k, _| p[(k, k)].sqrt()),
    })
}
