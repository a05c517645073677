//! The three-axis navigation layer: the Earth ([`earth`]: WGS-84, normal gravity, Earth and
//! transport rates) and the strapdown mechanization ([`mech`]: velocity, position and attitude
//! from the IMU's increments) of the INS/GNSS error-state filter.
//!
//! Conventions, as in Groves (2013) and KF-GINS: body axes forward-right-down; the local-level
//! frame north-east-down (NED); position as geodetic latitude, longitude and ellipsoidal height on
//! WGS-84; attitude as the Hamilton quaternion q_b^n (scalar first), read as Euler angles ZYX
//! (yaw ψ, then pitch θ, then roll φ).

pub mod blocks;
pub mod discrete;
pub mod drive;
pub mod driver;
pub mod earth;
pub mod ensemble;
pub mod error_state;
pub mod extra;
pub mod filter;
pub mod gnss;
pub mod measurement;
pub mod mech;
pub mod names;
pub mod nhc;
pub mod partial;
pub mod sensors;
pub mod setup;
pub mod simulated_logs;
pub mod state;
#[cfg(feature = "throwaway-measurement")]
pub mod throwaway;
pub mod truth;

#[cfg(test)]
mod tests;

use nalgebra::UnitQuaternion;

pub use earth::Geodetic;
pub use mech::{Increment, Pva};

/// The attitude q_b^n of Euler angles ZYX: roll φ, pitch θ, yaw ψ, rad.
///
/// # Formula
/// C_b^n = R_z(ψ)·R_y(θ)·R_x(φ), the ZYX sequence (Groves §2.2.2; Titterton & Weston §3.6).
pub fn attitude_from_euler(roll_rad: f64, pitch_rad: f64, yaw_rad: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_euler_angles(roll_rad, pitch_rad, yaw_rad)
}

/// Euler angles ZYX (roll, pitch, yaw), rad, of q_b^n; yaw in (−π, π], pitch in [−π/2, π/2].
///
/// # Formula
/// φ = atan2(C₂₁, C₂₂), θ = −asin C₂₀, ψ = atan2(C₁₀, C₀₀) of C_b^n (Groves §2.2.2).
pub fn euler_of(q_bn: &UnitQuaternion<f64>) -> (f64, f64, f64) {
    let r = q_bn.to_rotation_matrix();
    let c = r.matrix();
    let roll = c[(2, 1)].atan2(c[(2, 2)]);
    let pitch = -c[(2, 0)].clamp(-1.0, 1.0).asin();
    let yaw = c[(1, 0)].atan2(c[(0, 0)]);
    (roll, pitch, yaw)
}
