//! One accelerometer step of the error state, written once: the accelerometer's output (eq. 2),
//! its Euler integration (eq. 3, and eq. 4 for the truth), the step's transition Φ and noise input
//! Γ (eq. 5), its process noise Q = Γ·W·Γᵀ, and Q over a piece of a step that a GPS fix cuts.
//! Equation numbers are the problem statement's (MAE 271A, "Calibration of an Accelerometer
//! Using GPS Measurements").
//!
//! The per-realization formulas (eqs. 2 and 3) are generic over [`Real`], so that a single
//! realization (`f64`) and a lane group ([`crate::lanes::Lanes`]) perform the same operations in
//! the same order and give the same bits; they are `#[inline(always)]` so that the engines'
//! vectorized loops compile them in place. The simulation, both engines, the calibration's pass
//! and forward filter call them; the filter, the likelihood's intervals and the epoch engine take
//! Φ and Q through [`super::StateModel`], which [`super::ErrorState`] answers from here.

use super::{ErrorState, StateMatrix, StateModel, StateVector};
use crate::lanes::Real;

/// The constants of one Euler step of Δt: Δt and Δt²/2, computed once per step length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Euler {
    /// Δt, s.
    pub dt_s: f64,
    /// Δt²/2, s².
    pub half_dt2_s2: f64,
}

impl Euler {
    /// The step of `dt_s` seconds, Δt²/2 written as 0.5·Δt·Δt.
    #[inline(always)]
    pub fn new(dt_s: f64) -> Self {
        Self {
            dt_s,
            half_dt2_s2: 0.5 * dt_s * dt_s,
        }
    }

    /// eq. (3): (p, v) advanced over the step by the acceleration `a` held over it,
    /// p ← p + (v·Δt + a·Δt²/2), v ← v + a·Δt (position with the velocity before the step). The
    /// accelerometer's (p_c, v_c) with its output a_c; the Euler truth's (p_E, v_E) of eq. (4)
    /// with the true acceleration a.
    ///
    /// # Examples
    /// ```
    /// use accelcal::state::step::Euler;
    /// let (p, v) = Euler::new(0.5).step((1.0, 2.0), 4.0);
    /// assert_eq!((p, v), (1.0 + (2.0 * 0.5 + 4.0 * 0.125), 2.0 + 4.0 * 0.5));
    /// ```
    #[inline(always)]
    pub fn step<R: Real>(self, (p, v): (R, R), a: R) -> (R, R) {
        let dt = R::splat(self.dt_s);
        (p + (v * dt + a * R::splat(self.half_dt2_s2)), v + a * dt)
    }
}

/// eq. (2): the accelerometer's output a_c = (a + b) + σ_w·n for the true acceleration `a`, the
/// bias `bias`, the white noise's σ `w_sigma` and a standard normal number `normal`.
#[inline(always)]
pub fn accel_output<R: Real>(a: R, bias: R, w_sigma: R, normal: R) -> R {
    (a + bias) + w_sigma * normal
}

/// Noise input Γ(τ) = −(τ²/2, τ, 0)ᵀ of eq. (5): how the accelerometer's white noise w of one
/// step of τ seconds enters the error state (position with −τ²/2, velocity with −τ, not the
/// bias).
pub fn noise_input(tau_s: f64) -> StateVector {
    let mut gamma = StateVector::zeros();
    gamma[ErrorState::POSITION] = -0.5 * tau_s * tau_s;
    gamma[ErrorState::VELOCITY] = -tau_s;
    gamma
}

/// Transition Φ(τ) of the error state over τ seconds, eq. (5) composed over τ/Δt steps.
///
/// # Formula
/// ```text
/// Φ(τ) = [1  τ  −τ²/2]
///        [0  1  −τ   ]
///        [0  0   1   ]
/// ```
/// Φ is unipotent (Φ − I is nilpotent), so Φ(Δt)ⁿ = Φ(n·Δt) exactly.
///
/// # Examples
/// ```
/// use accelcal::state::transition;
/// let phi = transition(0.005);
/// let phi40 = transition(0.2);
/// assert!((phi.pow(40) - phi40).norm() < 1e-12);
/// ```
pub fn transition(tau_s: f64) -> StateMatrix {
    let mut phi = StateMatrix::identity();
    // eq. (5): velocity error moves position, the bias enters velocity with −τ and position
    // with −τ²/2.
    phi[(ErrorState::POSITION, ErrorState::VELOCITY)] = tau_s;
    phi[(ErrorState::POSITION, ErrorState::BIAS)] = -0.5 * tau_s * tau_s;
    phi[(ErrorState::VELOCITY, ErrorState::BIAS)] = -tau_s;
    phi
}

/// Process noise covariance Q(τ) = Γ·W·Γᵀ of one accelerometer step of τ seconds, (m, m/s, m/s²)².
///
/// # Formula
/// Γ = [`noise_input`]`(τ)` (eq. 5), W the accelerometer's white-noise variance
/// `accel_noise_var_m2_s4`.
pub fn process_noise(tau_s: f64, accel_noise_var_m2_s4: f64) -> StateMatrix {
    let gamma = noise_input(tau_s);
    gamma * gamma.transpose() * accel_noise_var_m2_s4
}

impl ErrorState {
    /// Q over a piece of `tau_s` seconds, from `t_s`, of a step of `step_s` that a fix cuts: the
    /// model's own Q(t, τ) for every noise but the accelerometer's, whose white noise is taken as
    /// white within the step (spectral density W·Δt_j), so that the pieces' velocity variances
    /// W·Δt_j·τ add up to the step's W·Δt_j² and no piece borrows the noise of another.
    ///
    /// # Formula
    /// Q(t, τ) with its (δp, δv) block — which only w feeds, Γ having no other component —
    /// replaced by W·Δt_j·[[τ³/3, τ²/2], [τ²/2, τ]] (∫₀^τ Φ(s)·Γ_c·Γ_cᵀ·Φ(s)ᵀ ds with
    /// Γ_c = −(0, 1, 0)ᵀ, the continuous-time input). A state added with a noise of its own keeps
    /// it; one whose noise enters δp or δv must say so here.
    pub fn piece_noise(&self, t_s: f64, tau_s: f64, step_s: f64) -> StateMatrix {
        let (p, v) = (ErrorState::POSITION, ErrorState::VELOCITY);
        let q = self.stats.accel_noise_var_m2_s4 * step_s;
        let mut m = self.process_noise(t_s, tau_s);
        m[(p, p)] = q * tau_s * tau_s * tau_s / 3.0;
        m[(p, v)] = q * 0.5 * tau_s * tau_s;
        m[(v, p)] = m[(p, v)];
        m[(v, v)] = q * tau_s;
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::{LANES, Lanes};
    use crate::state::{BiasModel, NoiseStats};

    /// A lane group's step is every lane's own step, bit for bit.
    #[test]
    fn lanes_step_as_each_realization() {
        let euler = Euler::new(0.005);
        let lane = |k: usize| 1.0 + k as f64 / 7.0;
        let p = Lanes(std::array::from_fn(|k| 100.0 * lane(k)));
        let v = Lanes(std::array::from_fn(|k| -3.0 * lane(k)));
        let a = Lanes(std::array::from_fn(|k| 0.1 / lane(k)));
        let (pl, vl) = euler.step((p, v), a);
        for k in 0..LANES {
            let (ps, vs) = euler.step((p.0[k], v.0[k]), a.0[k]);
            assert_eq!(
                (pl.0[k].to_bits(), vl.0[k].to_bits()),
                (ps.to_bits(), vs.to_bits())
            );
        }
        // Eq. (3) over one step, written out: position with the velocity before the step.
        let (ps, vs) = euler.step((1.0, 2.0), 3.0);
        assert_eq!(ps, 1.0 + (2.0 * 0.005 + 3.0 * 0.5 * 0.005 * 0.005));
        assert_eq!(vs, 2.0 + 3.0 * 0.005);
    }

    /// A constant acceleration integrates exactly: eq. (3) is exact for a held input.
    #[test]
    fn a_held_acceleration_integrates_exactly() {
        let (dt, a) = (0.25, 2.0);
        let euler = Euler::new(dt);
        let (mut p, mut v) = (0.0, 1.0);
        for _ in 0..8 {
            (p, v) = euler.step((p, v), a);
        }
        let t = 8.0 * dt;
        assert_eq!(v, 1.0 + a * t);
        assert_eq!(p, t + 0.5 * a * t * t);
    }

    /// The piece of a whole step keeps the bias's own noise and spreads w over the step.
    #[test]
    fn piece_noise_keeps_the_bias_noise() {
        let stats = NoiseStats {
            accel_noise_var_m2_s4: 4e-4,
            bias_var_m2_s4: 0.01,
            gps_position_sigma_m: 1.0,
            gps_velocity_sigma_m_s: 0.04,
            initial_position_sigma_m: 10.0,
            initial_velocity_sigma_m_s: 1.0,
            bias_model: BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: 0.02,
            },
        };
        let state = ErrorState { stats };
        let (tau, step) = (0.002, 0.005);
        let m = state.piece_noise(0.0, tau, step);
        let b = ErrorState::BIAS;
        assert_eq!(m[(b, b)], 0.02 * 0.02 * tau);
        let (p, v) = (ErrorState::POSITION, ErrorState::VELOCITY);
        approx::assert_relative_eq!(m[(v, v)], 4e-4 * step * tau, max_relative = 1e-15);
        approx::assert_relative_eq!(
            m[(p, p)],
            4e-4 * step * tau.powi(3) / 3.0,
            max_relative = 1e-15
        );
        assert_eq!(m, m.transpose());
        // Two pieces of a step carry the step's velocity variance.
        let halves = state.piece_noise(0.0, 0.5 * step, step)[(v, v)] * 2.0;
        approx::assert_relative_eq!(halves, 4e-4 * step * step, max_relative = 1e-15);
    }
}
