//! The calibration's filter: the increments of a part of an IMU step, the filter's start from the
//! alignment, a fix's record, and the σ's a record gives.

use nalgebra::{Matrix3, SVector, Vector3};

use super::Settings;
use super::align::{self, Alignment};
use crate::input::records::GnssRow;
use crate::ins::discrete::NoiseDensities;
use crate::ins::error_state::{
    ACCEL_BIAS, ATTITUDE, BiasDecay, GYRO_BIAS, POSITION, STATES, Square, holds, start_of,
};
use crate::ins::filter::{Ekf, LinearView, NOISE_GROUPS};
use crate::ins::gnss::Fix;
use crate::ins::mech::{Increment, Pva};
use crate::ins::state::Block;

/// The innovation components' names, in the record's order.
pub const COMPONENTS: [&str; 6] = [
    "position_north",
    "position_east",
    "position_down",
    "velocity_north",
    "velocity_east",
    "velocity_down",
];

/// One fix's filtered estimates.
#[derive(Clone, Debug, PartialEq)]
pub struct FixRecord<const N: usize = STATES> {
    /// The fix's line in the GNSS log.
    pub line: u64,
    /// Its time, s.
    pub t_s: f64,
    /// The navigation solution after the update.
    pub pva: Pva,
    /// The gyro bias estimate, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer bias estimate, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The gyro scale factor estimates (zero without the scale states).
    pub gyro_scale: Vector3<f64>,
    /// The accelerometer scale factor estimates (zero without the scale states).
    pub accel_scale: Vector3<f64>,
    /// The covariance after the update.
    pub covariance: Square<N>,
    /// The covariance before it.
    pub prior_covariance: Square<N>,
    /// Φ from the previous fix's update (or the start) to this fix.
    pub transition: Square<N>,
    /// The errors the update took out of the solution.
    pub correction: SVector<f64, N>,
    /// The innovation: position NED (m), velocity NED (m/s); NaN where not measured.
    pub innovation: [f64; 6],
    /// √S of each component; NaN where not measured.
    pub innovation_sigma: [f64; 6],
    /// νᵀS⁻¹ν.
    pub nis: f64,
    /// ln det S.
    pub log_det_s: f64,
    /// The components measured.
    pub rows: usize,
    /// Whether the filter took the fix: false when the χ² gate rejected its innovation (its
    /// covariance is then the prior, its correction zero).
    pub accepted: bool,
    /// What a likelihood linearized about this run needs of the fix; `None` unless the run
    /// tracked it ([`crate::calibrate::imu::run::filter_tracked`]).
    pub linear: Option<Box<LinearRecord<N>>>,
}

/// One fix's part of a likelihood linearized about the filter's run.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearRecord<const N: usize = STATES> {
    /// Q_d from the previous fix (or the start) split by noise group at unit density.
    pub noise_parts: [Square<N>; NOISE_GROUPS],
    /// H and the predicted measurement's rate before the update.
    pub view: LinearView<N>,
}

/// The increments of `inc` over the part of its step from `lo` to `hi` (its end `end`).
pub(super) fn part(inc: &Increment, end: f64, lo: f64, hi: f64) -> Increment {
    let frac = (hi - lo) / inc.dt_s;
    debug_assert!(hi <= end + 1e-9);
    Increment {
        dtheta_rad: inc.dtheta_rad * frac,
        dvel_m_s: inc.dvel_m_s * frac,
        dt_s: hi - lo,
    }
}

/// The filter's noise densities and decays from `s`.
pub(super) fn noise(s: &Settings) -> (NoiseDensities, BiasDecay) {
    let density = |sigma: f64, k: f64, tau: Option<f64>| match tau {
        Some(t) => 2.0 * sigma * sigma / t,
        None => k * k,
    };
    let decay = |tau: Option<f64>| tau.map_or(0.0, |t| 1.0 / t);
    (
        NoiseDensities {
            accel_vrw_m_s_per_sqrt_s: s.accel_vrw_m_s_per_sqrt_s,
            gyro_arw_rad_per_sqrt_s: s.gyro_arw_rad_per_sqrt_s,
            gyro_bias_density: density(
                s.gyro_bias_sigma_rad_s,
                s.gyro_bias_random_walk_rad_s_per_sqrt_s,
                s.gyro_bias_correlation_time_s,
            ),
            accel_bias_density: density(
                s.accel_bias_sigma_m_s2,
                s.accel_bias_random_walk_m_s2_per_sqrt_s,
                s.accel_bias_correlation_time_s,
            ),
        },
        BiasDecay {
            gyro_per_s: decay(s.gyro_bias_correlation_time_s),
            accel_per_s: decay(s.accel_bias_correlation_time_s),
        },
    )
}

/// The fix of `row` with the σ's of the log or of `s`, and which velocity components it
/// measures.
pub(super) fn fix_of(row: &GnssRow, s: &Settings) -> (Fix, [bool; 3]) {
    let measured = row.velocity_ned_m_s.map(|v| v.is_some());
    let v = row.velocity_ned_m_s.map(|v| v.unwrap_or(0.0));
    let ps = row.position_sigma_m;
    let vs = row.velocity_sigma_m_s;
    let fix = Fix {
        t_s: row.t_s,
        position: row.position,
        velocity_ned_m_s: measured.contains(&true).then(|| Vector3::from(v)),
        position_sigma_m: Vector3::from(
            [0, 1, 2].map(|i| ps[i].unwrap_or(s.gnss_position_sigma_m[i])),
        ),
        velocity_sigma_m_s: Vector3::from(
            [0, 1, 2].map(|i| vs[i].unwrap_or(s.gnss_velocity_sigma_m_s)),
        ),
    };
    (fix, measured)
}

/// The prior covariance at fix `h` from the alignment `a`: the alignment's errors, the fix's
/// position σ's and the gyro biases' prior (and the scale factors' with 21 states).
pub(super) fn initial_covariance<const N: usize>(
    h: &GnssRow,
    a: &Alignment,
    s: &Settings,
) -> Square<N> {
    let (fix, _) = fix_of(h, s);
    let mut p0 = Square::<N>::zeros();
    p0.fixed_view_mut::<STATES, STATES>(0, 0)
        .copy_from(&a.covariance);
    for i in 0..3 {
        p0[(POSITION + i, POSITION + i)] = fix.position_sigma_m[i].powi(2);
        p0[(GYRO_BIAS + i, GYRO_BIAS + i)] = s.gyro_bias_sigma_rad_s.powi(2);
        if holds::<N>(Block::GyroScale) {
            p0[(
                start_of::<N>(Block::GyroScale) + i,
                start_of::<N>(Block::GyroScale) + i,
            )] = (s.gyro_scale_factor_sigma_ppm * 1e-6).powi(2);
            p0[(
                start_of::<N>(Block::AccelScale) + i,
                start_of::<N>(Block::AccelScale) + i,
            )] = (s.accel_scale_factor_sigma_ppm * 1e-6).powi(2);
        }
    }
    p0
}

/// The filter at fix `h` from the alignment `a`: the IMU carried from the antenna's fix, the
/// prior covariance of position, alignment and gyro biases; tracking Q_d by noise group when
/// `tracked`.
pub(super) fn start<const N: usize>(
    h: &GnssRow,
    a: &Alignment,
    s: &Settings,
    tracked: bool,
) -> Ekf<N> {
    let [roll, pitch, yaw] = a.euler_rad;
    let attitude = crate::ins::attitude_from_euler(roll, pitch, yaw);
    let c: Matrix3<f64> = *attitude.to_rotation_matrix().matrix();
    let v = h.velocity_ned_m_s.map(|v| v.unwrap_or(0.0));
    let pva = Pva {
        position: align::imu_position(&h.position, &c, &s.lever_arm()),
        velocity_ned_m_s: Vector3::from(v),
        attitude,
    };
    let (noise, decay) = noise(s);
    let ekf = Ekf::new(
        pva,
        initial_covariance(h, a, s),
        noise,
        decay,
        s.lever_arm(),
    )
    .with_transition();
    if tracked { ekf.with_noise_parts() } else { ekf }
}

/// The σ's of the velocity at fix `r`: the log's or the default, and for a missing vertical
/// velocity the σ of the assumption 0.
pub(super) fn velocity_sigmas(r: &GnssRow, s: &Settings) -> Vector3<f64> {
    Vector3::from([0, 1, 2].map(|i| match r.velocity_ned_m_s[i] {
        Some(_) => r.velocity_sigma_m_s[i].unwrap_or(s.gnss_velocity_sigma_m_s),
        None => s.vertical_velocity_sigma_m_s,
    }))
}

/// The σ's of roll, pitch and yaw (rad) from the attitude error's covariance at `pva`: the
/// Euler angles' first-order response to a small rotation about north, east and down, found
/// by central differences.
pub fn euler_sigmas<const N: usize>(pva: &Pva, p: &Square<N>) -> [f64; 3] {
    let h = 1e-7;
    let mut j = Matrix3::zeros();
    for axis in 0..3 {
        let mut d = Vector3::zeros();
        d[axis] = h;
        let plus =
            crate::ins::euler_of(&(nalgebra::UnitQuaternion::from_scaled_axis(d) * pva.attitude));
        let minus =
            crate::ins::euler_of(&(nalgebra::UnitQuaternion::from_scaled_axis(-d) * pva.attitude));
        let diff = [plus.0 - minus.0, plus.1 - minus.1, plus.2 - minus.2];
        for (k, x) in diff.iter().enumerate() {
            let wrapped =
                (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            j[(k, axis)] = wrapped / (2.0 * h);
        }
    }
    let cov = j * p.fixed_view::<3, 3>(ATTITUDE, ATTITUDE) * j.transpose();
    [0, 1, 2].map(|i| cov[(i, i)].max(0.0).sqrt())
}

/// The σ of each gyro and accelerometer bias in `p`.
pub fn bias_sigmas<const N: usize>(p: &Square<N>) -> ([f64; 3], [f64; 3]) {
    (
        [0, 1, 2].map(|i| p[(GYRO_BIAS + i, GYRO_BIAS + i)].max(0.0).sqrt()),
        [0, 1, 2].map(|i| p[(ACCEL_BIAS + i, ACCEL_BIAS + i)].max(0.0).sqrt()),
    )
}

/// The σ of each gyro and accelerometer scale factor in `p` (NaN without the scale states).
pub fn scale_sigmas<const N: usize>(p: &Square<N>) -> ([f64; 3], [f64; 3]) {
    if !holds::<N>(Block::GyroScale) {
        return ([f64::NAN; 3], [f64::NAN; 3]);
    }
    (
        [0, 1, 2].map(|i| {
            p[(
                start_of::<N>(Block::GyroScale) + i,
                start_of::<N>(Block::GyroScale) + i,
            )]
                .max(0.0)
                .sqrt()
        }),
        [0, 1, 2].map(|i| {
            p[(
                start_of::<N>(Block::AccelScale) + i,
                start_of::<N>(Block::AccelScale) + i,
            )]
                .max(0.0)
                .sqrt()
        }),
    )
}
