//! The filter's start with no configuration: heading from the GNSS velocity once the vehicle
//! moves fast enough, roll and pitch from the mean specific force over a window before that fix
//! with the GNSS acceleration over the same window taken out, and the prior covariance of those
//! errors to first order — the accelerometer bias, the receiver's velocity noise and the
//! heading's offset from the course all enter it, with their correlations to the initial
//! velocity and to the accelerometer bias state.
//!
//! Coarse alignment on a moving vehicle: the mean specific force over [t_a, t_h] resolved in
//! NED is the mean acceleration minus gravity, f̄^n = (v_h − v_a)/(t_h − t_a) − g^n, so with the
//! yaw ψ from the course, R_y(θ)R_x(φ)f̄^b ∥ R_z(ψ)ᵀf̄^n fixes roll φ and pitch θ (Groves (2013)
//! §14.1.3, "Initialization"; the acceleration-aided leveling of in-motion alignment:
//! Titterton & Weston (2004) §10.3).

use nalgebra::{SMatrix, Vector3};

use crate::input::records::GnssRow;
use crate::ins::earth::{self, Geodetic};
use crate::ins::error_state::{ACCEL_BIAS, ATTITUDE, Matrix15, VELOCITY};

/// Which fixes the alignment uses: the window's first fix a and the fix h the filter starts at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// Index of fix a.
    pub first: usize,
    /// Index of fix h.
    pub start: usize,
}

/// What the alignment needs of the recording besides the fixes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignSettings {
    /// The lowest horizontal speed at which the course gives the heading, m/s.
    pub speed_m_s: f64,
    /// The window of the mean specific force, s (the fix nearest this far before h).
    pub window_s: f64,
    /// The σ of the IMU's heading about the course (mounting, sideslip), rad.
    pub heading_offset_sigma_rad: f64,
}

/// The first fix h whose horizontal speed is at least `s.speed_m_s`, with a fix a at least
/// `s.window_s` before it (the latest such) measuring the horizontal velocity, no earlier than
/// `imu_first_s`.
pub fn plan(fixes: &[GnssRow], imu_first_s: f64, s: &AlignSettings) -> Option<Plan> {
    let speed = |r: &GnssRow| r.horizontal_velocity().map(|(n, e)| n.hypot(e));
    (0..fixes.len()).find_map(|h| {
        if speed(&fixes[h])? < s.speed_m_s {
            return None;
        }
        let latest = fixes[h].t_s - s.window_s;
        let a = (0..h).rev().find(|&a| fixes[a].t_s <= latest)?;
        (fixes[a].t_s >= imu_first_s && speed(&fixes[a]).is_some())
            .then_some(Plan { first: a, start: h })
    })
}

/// The σ's of the sources of the alignment's errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sources {
    /// The receiver's velocity σ north, east, down at a fix (down: the σ of the assumption 0
    /// when the log has no vertical velocity), m/s.
    pub velocity_sigma_m_s: Vector3<f64>,
    /// The accelerometer bias's prior σ, m/s².
    pub accel_bias_sigma_m_s2: f64,
    /// The velocity random walk, m/s/√s.
    pub vrw_m_s_per_sqrt_s: f64,
    /// The heading's σ about the course, rad.
    pub heading_offset_sigma_rad: f64,
}

/// The alignment: the attitude at fix h and the prior covariance of the errors it leaves in
/// velocity, attitude and the accelerometer bias (the other blocks zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// Roll, pitch and yaw, rad.
    pub euler_rad: [f64; 3],
    /// The horizontal speed at h, m/s.
    pub speed_m_s: f64,
    /// The window's length, s.
    pub window_s: f64,
    /// The mean acceleration over the window in NED, m/s².
    pub acceleration_ned_m_s2: Vector3<f64>,
    /// The covariance of the velocity, attitude and accelerometer-bias errors.
    pub covariance: Matrix15,
}

/// Wraps an angle into (−π, π].
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// Roll and pitch with R_y(θ)R_x(φ)f ∥ w (the vectors normalized): R_x keeps f's x, so
/// w_y fixes the rotated y, and the rotations in the (x, z) and (y, z) planes follow.
pub fn level(f: &Vector3<f64>, w: &Vector3<f64>) -> (f64, f64) {
    let (f, w) = (f.normalize(), w.normalize());
    let rho2 = f.y * f.y + f.z * f.z;
    // max/min, not clamp: a NaN (f or w zero) carries through to the caller's check.
    let y = w.y.max(-rho2.sqrt()).min(rho2.sqrt());
    let z = (rho2 - y * y).max(0.0).sqrt().copysign(w.z);
    let pitch = wrap(z.atan2(f.x) - w.z.atan2(w.x));
    let roll = wrap(z.atan2(y) - f.z.atan2(f.y));
    (roll, pitch)
}

/// The alignment at fix `h` from fix `a`, with `mean_f_b` the mean specific force over
/// [t_a, t_h] in body axes, and the sources' σ's.
///
/// # Formula
/// Ĉ = (I + \[δψ×\])C applied to Ĉf̄ = û gives −\[u×\]δψ = δu − C(b_a + w̄) to first order, with
/// u = f̄^n, δu the error of the GNSS mean acceleration ((n_h − n_a)/T), b_a the accelerometer
/// bias and w̄ the window's mean white noise (σ VRW/√T); the yaw error is the course's,
/// δψ_D = (v_N n_E − v_E n_N)/s² plus the heading's offset. Its north and east rows give
/// δψ_N = (u_N δψ_D − r_E)/u_D and δψ_E = (r_N + u_E δψ_D)/u_D with r = δu − C(b_a + w̄). The
/// initial velocity is fix h's (error n_h) and the bias estimate 0 (error −b_a): P(0)'s blocks
/// are J·Σ·Jᵀ over the 13 sources (n_h, n_a, b_a, w̄, the offset).
pub fn align(a: &GnssRow, h: &GnssRow, mean_f_b: &Vector3<f64>, sources: &Sources) -> Alignment {
    let v = |r: &GnssRow| {
        let (n, e) = r.horizontal_velocity().unwrap_or((0.0, 0.0));
        Vector3::new(n, e, r.velocity_ned_m_s[2].unwrap_or(0.0))
    };
    let (va, vh) = (v(a), v(h));
    let window_s = h.t_s - a.t_s;
    let acc = (vh - va) / window_s;
    let g = earth::gravity_ned(&h.position);
    let u = acc - g;
    let yaw = vh.y.atan2(vh.x);
    let speed = vh.x.hypot(vh.y);
    let w = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -yaw) * u;
    let (roll, pitch) = level(mean_f_b, &w);
    let c = *crate::ins::attitude_from_euler(roll, pitch, yaw)
        .to_rotation_matrix()
        .matrix();
    // J: rows δv (3), δψ (3), δb_a (3); columns n_h (3), n_a (3), b_a (3), w̄ (3), offset.
    let mut j = SMatrix::<f64, 9, 13>::zeros();
    for i in 0..3 {
        j[(i, i)] = 1.0;
        j[(6 + i, 6 + i)] = -1.0;
    }
    // δψ_D row: the course's error and the offset.
    let s2 = speed * speed;
    let mut yaw_row = SMatrix::<f64, 1, 13>::zeros();
    yaw_row[0] = -vh.y / s2;
    yaw_row[1] = vh.x / s2;
    yaw_row[12] = 1.0;
    // r = δu − C(b_a + w̄) as rows over the sources.
    let mut r = SMatrix::<f64, 3, 13>::zeros();
    for i in 0..3 {
        r[(i, i)] = 1.0 / window_s;
        r[(i, 3 + i)] = -1.0 / window_s;
        for k in 0..3 {
            r[(i, 6 + k)] = -c[(i, k)];
            r[(i, 9 + k)] = -c[(i, k)];
        }
    }
    let psi_n = (yaw_row * u.x - r.row(1)) / u.z;
    let psi_e = (r.row(0) + yaw_row * u.y) / u.z;
    j.row_mut(3).copy_from(&psi_n);
    j.row_mut(4).copy_from(&psi_e);
    j.row_mut(5).copy_from(&yaw_row);
    let sv = sources.velocity_sigma_m_s;
    let mut sigma = [0.0; 13];
    for i in 0..3 {
        sigma[i] = sv[i];
        sigma[3 + i] = sv[i];
        sigma[6 + i] = sources.accel_bias_sigma_m_s2;
        sigma[9 + i] = sources.vrw_m_s_per_sqrt_s / window_s.sqrt();
    }
    sigma[12] = sources.heading_offset_sigma_rad;
    let variances = SMatrix::<f64, 13, 13>::from_diagonal(&sigma.map(|s| s * s).into());
    let block = j * variances * j.transpose();
    let mut covariance = Matrix15::zeros();
    let at = [VELOCITY, ATTITUDE, ACCEL_BIAS];
    for (bi, &ri) in at.iter().enumerate() {
        for (bj, &rj) in at.iter().enumerate() {
            covariance
                .fixed_view_mut::<3, 3>(ri, rj)
                .copy_from(&block.fixed_view::<3, 3>(3 * bi, 3 * bj));
        }
    }
    Alignment {
        euler_rad: [roll, pitch, yaw],
        speed_m_s: speed,
        window_s,
        acceleration_ned_m_s2: acc,
        covariance,
    }
}

/// The antenna's fix carried to the IMU through the lever arm `lever_b_m` at attitude C.
pub fn imu_position(
    antenna: &Geodetic,
    c_bn: &nalgebra::Matrix3<f64>,
    lever_b_m: &Vector3<f64>,
) -> Geodetic {
    earth::offset(antenna, &(-(c_bn * lever_b_m)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::attitude_from_euler;

    /// Leveling inverts the attitude it was made from, for any yaw and tilts up to 30°, with
    /// an acceleration along and across the track.
    #[test]
    fn level_inverts_the_attitude() {
        for (roll, pitch, yaw) in [(0.0, 0.0, 0.0), (0.1, -0.2, 2.0), (-0.5, 0.4, -3.0)] {
            let q = attitude_from_euler(roll, pitch, yaw);
            let u = Vector3::new(1.5, -0.7, -9.8);
            let f_b = q.inverse() * u;
            let w = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -yaw) * u;
            let (r, p) = level(&f_b, &w);
            assert!(
                (r - roll).abs() < 1e-12 && (p - pitch).abs() < 1e-12,
                "{r} {p}"
            );
        }
        // The negative control: a wrong yaw gives other angles.
        let q = attitude_from_euler(0.1, 0.1, 1.0);
        let u = Vector3::new(2.0, 0.0, -9.8);
        let w = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -1.3) * u;
        let (r, p) = level(&(q.inverse() * u), &w);
        assert!((r - 0.1).abs() + (p - 0.1).abs() > 1e-3);
    }
}
