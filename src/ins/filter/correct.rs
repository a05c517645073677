//! The closed-loop correction (Groves §14.1.1): each part of the solution, the biases and the
//! scale factors has its estimated error taken out.

use nalgebra::{SMatrix, UnitQuaternion, Vector3};

use crate::ins::error_state::{ACCEL_BIAS, ATTITUDE, GYRO_BIAS, POSITION, STATES, VELOCITY};
use crate::ins::mech::Pva;

/// The closed-loop correction by the estimated errors `dx` (estimate minus truth): each part of
/// the solution and the biases has its error taken out (a smoother applies its own corrections
/// to a filtered solution the same way).
pub fn apply_correction(
    pva: &mut Pva,
    gyro_bias_rad_s: &mut Vector3<f64>,
    accel_bias_m_s2: &mut Vector3<f64>,
    dx: &SMatrix<f64, STATES, 1>,
) {
    let p = &mut pva.position;
    let (rn, re) = crate::ins::earth::radii_m(p.lat_rad);
    let dr = dx.fixed_rows::<3>(POSITION);
    p.lat_rad -= dr[0] / (rn + p.height_m);
    p.lon_rad = crate::ins::earth::wrap_longitude(
        p.lon_rad - dr[1] / ((re + p.height_m) * p.lat_rad.cos()),
    );
    p.height_m += dr[2];
    pva.velocity_ned_m_s -= dx.fixed_rows::<3>(VELOCITY);
    // Ĉ = exp([δψ×])C, so C = exp(−[δψ×])Ĉ.
    let psi = dx.fixed_rows::<3>(ATTITUDE).into_owned();
    pva.attitude = UnitQuaternion::from_scaled_axis(-psi) * pva.attitude;
    *gyro_bias_rad_s -= dx.fixed_rows::<3>(GYRO_BIAS);
    *accel_bias_m_s2 -= dx.fixed_rows::<3>(ACCEL_BIAS);
}
