//! One filter step's transition Φ and process noise Q_d from the error dynamics F, held
//! constant over the step.
//!
//! Φ = I + FΔt + (FΔt)²/2, the matrix exponential to second order (Groves §3.2.3 and §14.2.4:
//! the first-order form loses the δv–δψ–δb coupling's second-order terms, which a bias drives
//! through \[f^n×\] within the step); Q_d = (Φ·S·Φᵀ + S)·Δt/2 with S = G·Q_c·Gᵀ, the trapezoidal
//! rule of the integral ∫₀^Δt Φ(s)·S·Φ(s)ᵀ ds (Groves §3.2.3; KF-GINS does the same). Both are
//! tested against Van Loan's exact discretization (Van Loan, "Computing integrals involving the
//! matrix exponential", IEEE TAC 23(3), 1978) over one step.

use nalgebra::SVector;

use super::error_state::{
    ACCEL_BIAS, ATTITUDE, GYRO_BIAS, POSITION, STATES, STATES_WITH_SCALE, Square, VELOCITY,
    offset_of,
};
use super::state::Block;

/// Where the scale factors start in the 21-state layout.
const GYRO_SCALE: usize = offset_of::<STATES_WITH_SCALE>(Block::GyroScale).unwrap();
const ACCEL_SCALE: usize = offset_of::<STATES_WITH_SCALE>(Block::AccelScale).unwrap();

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
        self.diagonal_of::<STATES>().into()
    }

    /// S's diagonal over an error state of `N` (the scale factors, constants, undriven).
    pub fn diagonal_of<const N: usize>(&self) -> SVector<f64, N> {
        let mut s = SVector::<f64, N>::zeros();
        let mut fill = |first: usize, value: f64| s.fixed_rows_mut::<3>(first).fill(value);
        fill(VELOCITY, self.accel_vrw_m_s_per_sqrt_s.powi(2));
        fill(ATTITUDE, self.gyro_arw_rad_per_sqrt_s.powi(2));
        fill(GYRO_BIAS, self.gyro_bias_density);
        fill(ACCEL_BIAS, self.accel_bias_density);
        s
    }
}

/// Φ = I + FΔt + (FΔt)²/2.
pub fn transition<const N: usize>(f: &Square<N>, dt: f64) -> Square<N> {
    let a = f * dt;
    Square::<N>::identity() + a + 0.5 * a * a
}

/// Q_d = (Φ·S·Φᵀ + S)·Δt/2 for the diagonal S of `noise`.
pub fn process_noise<const N: usize>(
    phi: &Square<N>,
    noise: &NoiseDensities,
    dt: f64,
) -> Square<N> {
    let s = Square::<N>::from_diagonal(&noise.diagonal_of::<N>());
    let q = (phi * s * phi.transpose() + s) * (0.5 * dt);
    // Symmetric to the last bit, as a covariance must be.
    (q + q.transpose()) * 0.5
}

/// Φ over an interval T of several IMU steps, F held at its mean over them: the matrix
/// exponential to third order, Φ = I + A + A²/2 + A³/6 with A = F·T (Groves §3.2.3, eq. 3.34's
/// power series). Third order because the longest chain of the error dynamics, δb_g → δψ → δv →
/// δr, has three links: its leading term, −\[f^n×\]·C·T³/6 from δb_g into δr, is kept.
pub fn transition_third_order<const N: usize>(f: &Square<N>, t: f64) -> Square<N> {
    let a = f * t;
    let a2 = dynamics_times(&a, &a);
    let a3 = dynamics_times(&a, &a2);
    Square::<N>::identity() + a + a2 * 0.5 + a3 * (1.0 / 6.0)
}

/// Q_d = ∫₀^T e^(Fs)·S·e^(Fᵀs) ds over an interval T, by the power series of Van Loan's integral
/// (Van Loan 1978, eq. 1.3, expanded): Q_d = Σ_{k=0}^{4} M_k·T^(k+1)/(k+1)! with M₀ = S and
/// M_k = F·M_(k−1) + M_(k−1)·Fᵀ. Four terms past S carry the angle random walk through
/// δψ → δv → δr (its T⁵/20 term) and the velocity random walk into δr (T³/3).
pub fn process_noise_series<const N: usize>(
    f: &Square<N>,
    noise: &NoiseDensities,
    t: f64,
) -> Square<N> {
    let mut m = Square::<N>::from_diagonal(&noise.diagonal_of::<N>());
    let mut factor = t;
    let mut q = m * factor;
    for k in 1..=4 {
        let fm = dynamics_times(f, &m);
        m = fm + fm.transpose();
        factor *= t / (k + 1) as f64;
        q += m * factor;
    }
    (q + q.transpose()) * 0.5
}

/// The 3×3 blocks the error dynamics F can hold, by block row (Groves §14.2.4; `error_state`'s
/// F): position from velocity and position; velocity from position, velocity, attitude and the
/// accelerometer biases; attitude from position, velocity, attitude and the gyro biases; each
/// bias from itself.
pub const DYNAMICS_BLOCKS: [(usize, &[usize]); 5] = [
    (POSITION, &[POSITION, VELOCITY]),
    (VELOCITY, &[POSITION, VELOCITY, ATTITUDE, ACCEL_BIAS]),
    (ATTITUDE, &[POSITION, VELOCITY, ATTITUDE, GYRO_BIAS]),
    (GYRO_BIAS, &[GYRO_BIAS]),
    (ACCEL_BIAS, &[ACCEL_BIAS]),
];

/// [`DYNAMICS_BLOCKS`] with the scale factors: velocity from the accelerometers' and attitude
/// from the gyros' (the scale factors' own rows are zero: constants).
pub const DYNAMICS_BLOCKS_WITH_SCALE: [(usize, &[usize]); 5] = [
    (POSITION, &[POSITION, VELOCITY]),
    (
        VELOCITY,
        &[POSITION, VELOCITY, ATTITUDE, ACCEL_BIAS, ACCEL_SCALE],
    ),
    (
        ATTITUDE,
        &[POSITION, VELOCITY, ATTITUDE, GYRO_BIAS, GYRO_SCALE],
    ),
    (GYRO_BIAS, &[GYRO_BIAS]),
    (ACCEL_BIAS, &[ACCEL_BIAS]),
];

/// F·X for an F of [`DYNAMICS_BLOCKS`]' pattern (or [`DYNAMICS_BLOCKS_WITH_SCALE`]' with 21
/// states): 12 of the 25 blocks, 1 620 multiply-adds against a dense product's 3 375.
pub fn dynamics_times<const N: usize>(f: &Square<N>, x: &Square<N>) -> Square<N> {
    let mut out = Square::<N>::zeros();
    let blocks: &[(usize, &[usize])] = if const { offset_of::<N>(Block::GyroScale).is_some() } {
        &DYNAMICS_BLOCKS_WITH_SCALE
    } else {
        &DYNAMICS_BLOCKS
    };
    for &(row, columns) in blocks {
        let mut rows = out.fixed_rows_mut::<3>(row);
        for &column in columns {
            rows.gemm(
                1.0,
                &f.fixed_view::<3, 3>(row, column),
                &x.fixed_rows::<3>(column),
                1.0,
            );
        }
    }
    out
}

/// ΦPΦᵀ for a symmetric P and a Φ whose bias rows are diagonal (F's bias blocks are: the
/// biases' decay), as Φ·(Φ·P)ᵀ: the first nine rows of each product dense, the last six scaled.
pub fn transition_congruence<const N: usize>(phi: &Square<N>, p: &Square<N>) -> Square<N> {
    let times = |x: &Square<N>| {
        let mut out = Square::<N>::zeros();
        out.fixed_rows_mut::<GYRO_BIAS>(0)
            .gemm(1.0, &phi.fixed_rows::<GYRO_BIAS>(0), x, 0.0);
        for i in GYRO_BIAS..N {
            out.row_mut(i).copy_from(&(x.row(i) * phi[(i, i)]));
        }
        out
    };
    let phi_p = times(p);
    let out = times(&phi_p.transpose());
    (out + out.transpose()) * 0.5
}
