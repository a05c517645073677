//! The three-axis Monte Carlo ensemble: N realizations of one drive, each with its own sensors
//! and its own EKF, whose covariance depends on its own estimate. What the checks need is summed
//! over the realizations per fix, each realization's errors normalized by its own covariance:
//! NEES eᵀP⁻¹e before and after the update (χ²(15) each when the filter is consistent) and
//! NIS νᵀS⁻¹ν (χ² of the fix's rows).
//!
//! The truth is computed once and shared (every realization drives the same road); each
//! realization's random stream depends only on the seed and its index, and the sums are folded
//! in index order, chunk by chunk: the same numbers on any thread count, memory flat in N.

use nalgebra::{SVector, UnitQuaternion, Vector3};
use rayon::prelude::*;

use super::earth::offset;
use super::error_state::{ACCEL_BIAS, ATTITUDE, GYRO_BIAS, Matrix15, POSITION, STATES, VELOCITY};
use super::filter::{Ekf, FilterError};
use super::gnss;
use super::logs::fix;
use super::mech::{Increment, Pva};
use super::sensors::Imu;
use super::setup::Study;
use super::truth::Truth;

/// Realizations run side by side before their sums are folded in.
const CHUNK: u64 = 64;

/// The drive's truth at every IMU step, shared by the realizations.
pub struct Track {
    /// The state at the start.
    pub start: Pva,
    /// The true increments over each step and the state at its end.
    pub steps: Vec<(Increment, Pva)>,
}

impl Track {
    /// The truth of `study`'s drive.
    pub fn of(study: &Study) -> Self {
        let drive = study.drive();
        let truth =
            Truth::new(&drive, study.start, 1.0 / study.imu_rate_hz).until(study.duration_s);
        let start = truth.pva();
        Track {
            start,
            steps: truth.collect(),
        }
    }
}

/// The ensemble's sums at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixSums {
    /// The fix's time, s.
    pub t_s: f64,
    /// Σ NEES before the update.
    pub nees_prior: f64,
    /// Σ NEES after the update.
    pub nees_post: f64,
    /// Σ NIS.
    pub nis: f64,
    /// Σ of the innovations' rows (the NIS sum's degrees of freedom).
    pub nis_dof: usize,
}

impl FixSums {
    fn add(&mut self, other: &FixSums) {
        self.t_s = other.t_s;
        self.nees_prior += other.nees_prior;
        self.nees_post += other.nees_post;
        self.nis += other.nis;
        self.nis_dof += other.nis_dof;
    }
}

/// The error of `ekf` against the true state and biases, in the error state's coordinates.
pub fn error(ekf: &Ekf, pva: &Pva, imu: &Imu) -> SVector<f64, STATES> {
    let mut e = SVector::<f64, STATES>::zeros();
    e.fixed_rows_mut::<3>(POSITION)
        .copy_from(&gnss::ned_difference_m(&ekf.pva.position, &pva.position));
    e.fixed_rows_mut::<3>(VELOCITY)
        .copy_from(&(ekf.pva.velocity_ned_m_s - pva.velocity_ned_m_s));
    e.fixed_rows_mut::<3>(ATTITUDE)
        .copy_from(&(ekf.pva.attitude * pva.attitude.inverse()).scaled_axis());
    e.fixed_rows_mut::<3>(GYRO_BIAS)
        .copy_from(&(ekf.gyro_bias_rad_s - imu.gyro_bias_rad_s));
    e.fixed_rows_mut::<3>(ACCEL_BIAS)
        .copy_from(&(ekf.accel_bias_m_s2 - imu.accel_bias_m_s2));
    e
}

/// eᵀP⁻¹e by a Cholesky factor of P.
fn nees(e: &SVector<f64, STATES>, p: &Matrix15) -> Result<f64, FilterError> {
    let chol = p.cholesky().ok_or(FilterError::Covariance)?;
    Ok(e.dot(&chol.solve(e)))
}

/// Realization `index`: its filter started from the truth plus a draw of its prior, run over the
/// track, with its NEES and NIS at every fix.
///
/// # Errors
/// [`FilterError`] when a covariance stops being positive definite.
pub fn realization(study: &Study, track: &Track, index: u64) -> Result<Vec<FixSums>, FilterError> {
    let drive = study.drive();
    let mut imu = study.imu(index);
    let s = &study.initial_sigma;
    let dr = imu.normals(&Vector3::new(s[0], s[1], s[2]));
    let dv = imu.normals(&Vector3::new(s[3], s[4], s[5]));
    let dpsi = imu.normals(&Vector3::new(s[6], s[7], s[8]));
    let start = Pva {
        position: offset(&track.start.position, &dr),
        velocity_ned_m_s: track.start.velocity_ned_m_s + dv,
        attitude: UnitQuaternion::from_scaled_axis(dpsi) * track.start.attitude,
    };
    let g = &study.filter_gnss;
    let mut ekf = Ekf::new(
        start,
        study.prior(),
        study.filter_noise(),
        study.filter_decay(),
        g.lever_arm_b_m,
    );
    let dt = 1.0 / study.imu_rate_hz;
    let mut out = Vec::with_capacity(track.steps.len() / study.imu_steps_per_fix);
    for (k, (inc, pva)) in track.steps.iter().enumerate() {
        let raw = imu.read(inc);
        ekf.propagate(&raw);
        if (k + 1) % study.imu_steps_per_fix != 0 {
            continue;
        }
        let t = (k + 1) as f64 * dt;
        let mut reading = fix(study, &drive, &mut imu, t, pva);
        // The filter weighs the fix with the σ's it assumes.
        reading.position_sigma_m = g.position_sigma_m;
        reading.velocity_sigma_m_s = g.velocity_sigma_m_s;
        let nees_prior = nees(&error(&ekf, pva, &imu), &ekf.covariance)?;
        let innovation = ekf.update(&reading)?;
        let nees_post = nees(&error(&ekf, pva, &imu), &ekf.covariance)?;
        out.push(FixSums {
            t_s: t,
            nees_prior,
            nees_post,
            nis: innovation.nis,
            nis_dof: innovation.residual.len(),
        });
    }
    Ok(out)
}

/// The sums over `realizations` realizations of `study` (indices 0 to N − 1), in index order.
///
/// # Errors
/// The first realization's [`FilterError`], in index order.
pub fn run(study: &Study, track: &Track, realizations: u64) -> Result<Vec<FixSums>, FilterError> {
    let mut sums: Vec<FixSums> = Vec::new();
    let mut first = 0;
    while first < realizations {
        let last = (first + CHUNK).min(realizations);
        let chunk: Vec<Result<Vec<FixSums>, FilterError>> = (first..last)
            .into_par_iter()
            .map(|l| realization(study, track, l))
            .collect();
        for r in chunk {
            let r = r?;
            if sums.is_empty() {
                sums = vec![FixSums::default(); r.len()];
            }
            for (s, x) in sums.iter_mut().zip(&r) {
                s.add(x);
            }
        }
        first = last;
    }
    Ok(sums)
}
