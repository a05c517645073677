//! One filter step's transition Φ and process noise Q_d from the error dynamics F, held
//! constant over the step.
//!
//! Φ = I + FΔt + (FΔt)²/2, the matrix exponential to second order (Groves §3.2.3 and §14.2.4:
//! the first-order form loses the δv–δψ–δb coupling's second-order terms, which a bias drives
//! through [f^n×] within the step); Q_d = (Φ·S·Φᵀ + S)·Δt/2 with S = G·Q_c·Gᵀ, the trapezoidal
//! rule of the integral ∫₀^Δt Φ(s)·S·Φ(s)ᵀ ds (Groves §3.2.3; KF-GINS does the same). Both are
//! tested against Van Loan's exact discretization (Van Loan, "Computing integrals involving the
//! matrix exponential", IEEE TAC 23(3), 1978) over one step.

use super::error_state::{ACCEL_BIAS, ATTITUDE, GYRO_BIAS, Matrix15, STATES, VELOCITY};

/// The white-noise densities that drive the error state, each the same on a sensor's three axes
/// (so that S = G·Q_c·Gᵀ is diagonal: the rotations C_b^n in G cancel).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseDensities {
    /// The accelerometers' velocity random walk, m/s/√s (its square in (m/s²)²/Hz).
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// The gyros' angle random walk, rad/√s.
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// The density driving each gyro bias, (rad/s)²/s: K² of a random walk, 2σ²/τ of a
    /// Gauss–Markov bias, 0 for a constant.
    pub gyro_bias_density: f64,
    /// The density driving each accelerometer bias, (m/s²)²/s, likewise.
    pub accel_bias_density: f64,
}

impl NoiseDensities {
    /// S = G·Q_c·Gᵀ's diagonal.
    pub fn diagonal(&self) -> [f64; STATES] {
        let mut s = [0.0; STATES];
        let mut fill = |first: usize, value: f64| s[first..first + 3].fill(value);
        fill(VELOCITY, self.accel_vrw_m_s_per_sqrt_s.powi(2));
        fill(ATTITUDE, self.gyro_arw_rad_per_sqrt_s.powi(2));
        fill(GYRO_BIAS, self.gyro_bias_density);
        fill(ACCEL_BIAS, self.accel_bias_density);
        s
    }
}

/// Φ = I + FΔt + (FΔt)²/2.
pub fn transition(f: &Matrix15, dt: f64) -> Matrix15 {
    let a = f * dt;
    Matrix15::identity() + a + 0.5 * a * a
}

/// Q_d = (Φ·S·Φᵀ + S)·Δt/2 for the diagonal S of `noise`.
pub fn process_noise(phi: &Matrix15, noise: &NoiseDensities, dt: f64) -> Matrix15 {
    let s = Matrix15::from_diagonal(&nalgebra::SVector::from(noise.diagonal()));
    let q = (phi * s * phi.transpose() + s) * (0.5 * dt);
    // Symmetric to the last bit, as a covariance must be.
    (q + q.transpose()) * 0.5
}
