//! The process noise of an interval between fixes per unit of each noise statistic, accumulated
//! step by step by the pass over the accelerometer log.

use crate::model::NoiseStats;
use crate::state::{BiasModel, ErrorState, StateMatrix, transition};

// The unit contributions below are written out for the error state's (δp, δv, b).
const _: () = assert!(
    ErrorState::DIM == 3,
    "calibrate/units.rs: add the new state's noise units to NoiseUnits"
);

/// The process noise of an interval per unit of each noise statistic: Q = W·U_W + s_b·U_b for
/// the accelerometer's white-noise variance W and the bias's noise scale s_b (K² for a random
/// walk, σ_b² for Gauss–Markov; no U_b for a constant bias). A search over the statistics
/// rescales the units without reading the log (for Gauss–Markov, at the τ_b of the pass).
///
/// # Formula
/// Over steps Δt_1 … Δt_n from the fix at t_a to the one at t_b, with Φ_j = Φ(Δt_j) the step's
/// transition (the bias's φ_j = φ(Δt_j) of [`BiasModel::step`]),
/// U ← Φ_j·U·Φ_jᵀ + u_j step by step, where
/// - U_W: u_j = γ_j·γ_jᵀ, γ_j = −(Δt_j²/2, Δt_j, 0)ᵀ. γ has no bias part, so U_W has none and
///   only Φ's (δp, δv) block [[1, Δt], [0, 1]] acts on it: three numbers per step;
/// - U_b: u_j = e_b·e_bᵀ·q_b(Δt_j)/s_b: Δt_j for a random walk (q_b = K²·Δt_j),
///   1 − φ_j² for Gauss–Markov (q_b = σ_b²·(1 − φ_j²)).
///
/// The interval's transition is Φ(t_b − t_a) when the bias's Φ composes; for Gauss–Markov its
/// bias column is the product of the steps' (`phi_bias`), (0, 0, 1) before the first step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseUnits {
    /// U_W's (δp δp, δp δv, δv δv) entries, (m², m²/s, m²/s²) per (m/s²)².
    white: [f64; 3],
    /// U_b, per unit of s_b (zero for a constant bias).
    bias: StateMatrix,
    /// The bias column of Π_j Φ_j over the interval (Gauss–Markov only).
    phi_bias: [f64; 3],
}

impl Default for NoiseUnits {
    fn default() -> Self {
        Self {
            white: [0.0; 3],
            bias: StateMatrix::zeros(),
            phi_bias: [0.0, 0.0, 1.0],
        }
    }
}

impl NoiseUnits {
    /// Adds one step of `tau_s`.
    #[inline]
    pub fn add_step(&mut self, tau_s: f64) {
        let [pp, pv, vv] = self.white;
        let tau2 = tau_s * tau_s;
        self.white = [
            pp + 2.0 * tau_s * pv + tau2 * vv + 0.25 * tau2 * tau2,
            pv + tau_s * vv + 0.5 * tau2 * tau_s,
            vv + tau2,
        ];
    }

    /// Adds a piece of `tau_s` of a step of `step_s` that a fix cuts: the step's white noise
    /// taken as white within the step (spectral density W·Δt_j), so that the pieces' velocity
    /// variances W·Δt_j·τ add up to the step's W·Δt_j² and no piece borrows the noise of another.
    ///
    /// # Formula
    /// U_W ← Φ(τ)·U_W·Φ(τ)ᵀ + Δt_j·[[τ³/3, τ²/2], [τ²/2, τ]].
    #[inline]
    pub fn add_piece(&mut self, tau_s: f64, step_s: f64) {
        let [pp, pv, vv] = self.white;
        let tau2 = tau_s * tau_s;
        self.white = [
            pp + 2.0 * tau_s * pv + tau2 * vv + step_s * tau2 * tau_s / 3.0,
            pv + tau_s * vv + 0.5 * step_s * tau2,
            vv + step_s * tau_s,
        ];
    }

    /// Adds the bias's part of one step of `tau_s` for a drifting `bias` model (nothing for a
    /// constant one).
    #[inline]
    pub fn add_bias_step(&mut self, tau_s: f64, bias: BiasModel) {
        // (φ, q_b/s_b): q_b = K²·Δt is linear in K², q_b = σ_b²·(1 − φ²) in σ_b² (the
        // Gauss–Markov step at σ_b² = 1).
        let (phi, unit) = match bias {
            BiasModel::Constant => return,
            BiasModel::RandomWalk { .. } => (1.0, tau_s),
            gauss_markov => gauss_markov.step(tau_s, 1.0),
        };
        let mut step = transition(tau_s);
        step[(ErrorState::BIAS, ErrorState::BIAS)] = phi;
        let mut u = step * self.bias * step.transpose();
        u[(ErrorState::BIAS, ErrorState::BIAS)] += unit;
        self.bias = u;
        if !bias.composes() {
            let [p, v, b] = self.phi_bias;
            // Φ_j·(p, v, b)ᵀ: eq. (5) with the bias held over the step, then decayed.
            self.phi_bias = [
                p + tau_s * v - 0.5 * tau_s * tau_s * b,
                v - tau_s * b,
                phi * b,
            ];
        }
    }

    /// Q = W·U_W for the white-noise variance `accel_noise_var_m2_s4`.
    pub fn process_noise(&self, accel_noise_var_m2_s4: f64) -> StateMatrix {
        let (p, v) = (ErrorState::POSITION, ErrorState::VELOCITY);
        let [pp, pv, vv] = self.white.map(|u| u * accel_noise_var_m2_s4);
        let mut q = StateMatrix::zeros();
        q[(p, p)] = pp;
        q[(p, v)] = pv;
        q[(v, p)] = pv;
        q[(v, v)] = vv;
        q
    }

    /// The interval's Q = W·U_W + s_b·U_b for the filter's statistics `stats` (W·U_W alone,
    /// the same bits, for a constant bias).
    pub fn interval_noise(&self, stats: &NoiseStats) -> StateMatrix {
        let q = self.process_noise(stats.accel_noise_var_m2_s4);
        match stats.bias_model {
            BiasModel::Constant => q,
            BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: k,
            } => q + self.bias * (k * k),
            BiasModel::GaussMarkov { .. } => q + self.bias * stats.bias_var_m2_s4,
        }
    }

    /// The interval's transition Φ over `tau_s` = t_b − t_a for the bias model `bias`:
    /// [`transition`] (the same bits) when it composes, else with the product's bias column.
    pub fn interval_transition(&self, tau_s: f64, bias: BiasModel) -> StateMatrix {
        let mut phi = transition(tau_s);
        if !bias.composes() {
            for (r, value) in self.phi_bias.into_iter().enumerate() {
                phi[(r, ErrorState::BIAS)] = value;
            }
        }
        phi
    }

    /// U_W's (δp δp, δp δv, δv δv) entries, (m², m²/s, m²/s²) per (m/s²)².
    pub fn white(&self) -> [f64; 3] {
        self.white
    }

    /// U_b, per unit of the bias's noise scale s_b (zero for a constant bias).
    pub fn bias(&self) -> StateMatrix {
        self.bias
    }

    /// Whether every unit is finite.
    pub fn is_finite(&self) -> bool {
        self.white.iter().all(|u| u.is_finite())
            && self.bias.iter().all(|u| u.is_finite())
            && self.phi_bias.iter().all(|u| u.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::process_noise;

    #[test]
    fn unit_noise_is_the_step_by_step_propagation_of_the_process_noise() {
        let steps = [0.005, 0.0049, 0.0052, 0.005, 0.0048];
        let w = 3e-4;
        let mut units = NoiseUnits::default();
        let mut q = StateMatrix::zeros();
        for &tau in &steps {
            units.add_step(tau);
            let phi = transition(tau);
            q = phi * q * phi.transpose() + process_noise(tau, w);
        }
        let d = units.process_noise(w) - q;
        assert!(d.norm() <= 1e-14 * q.norm(), "{d}");
        // A wrong unit (the noise entering velocity alone) is told apart.
        let mut wrong = NoiseUnits::default();
        wrong.white[2] = units.white[2];
        assert!((wrong.process_noise(w) - q).norm() > 1e-3 * q.norm());
    }

    /// With a drifting bias the units and the interval's transition are the step-by-step
    /// propagation of the filter's own Φ(Δt_j) and Q(Δt_j), for both drifting models.
    #[test]
    fn bias_units_are_the_step_by_step_propagation_of_a_drifting_bias() {
        use crate::state::{NoiseStats, StateModel};
        let steps = [0.005, 0.0049, 0.0052, 0.005, 0.0048, 0.0051];
        for bias_model in [
            BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: 0.03,
            },
            BiasModel::GaussMarkov {
                correlation_time_s: 0.02,
            },
        ] {
            let stats = NoiseStats {
                accel_noise_var_m2_s4: 3e-4,
                bias_var_m2_s4: 0.01,
                gps_position_sigma_m: 1.0,
                gps_velocity_sigma_m_s: 0.04,
                initial_position_sigma_m: 10.0,
                initial_velocity_sigma_m_s: 1.0,
                bias_model,
            };
            let state = ErrorState { stats };
            let mut units = NoiseUnits::default();
            let (mut q, mut phi) = (StateMatrix::zeros(), StateMatrix::identity());
            for &tau in &steps {
                units.add_step(tau);
                units.add_bias_step(tau, bias_model);
                let step = state.transition(0.0, tau);
                q = step * q * step.transpose() + state.process_noise(0.0, tau);
                phi = step * phi;
            }
            let d = units.interval_noise(&stats) - q;
            assert!(d.norm() <= 1e-13 * q.norm(), "{bias_model:?}: {d}");
            let total: f64 = steps.iter().sum();
            let d = units.interval_transition(total, bias_model) - phi;
            assert!(d.norm() <= 1e-14, "{bias_model:?}: {d}");
            // The bias's part left out is told apart.
            let white = units.process_noise(stats.accel_noise_var_m2_s4);
            assert!((white - q).norm() > 1e-3 * q[(2, 2)], "{bias_model:?}");
        }
        // Gauss–Markov's interval Φ is not the one-step formula at the interval's length.
        let gm = BiasModel::GaussMarkov {
            correlation_time_s: 0.02,
        };
        let mut units = NoiseUnits::default();
        steps.iter().for_each(|&tau| units.add_bias_step(tau, gm));
        let total: f64 = steps.iter().sum();
        let mut one_piece = transition(total);
        one_piece[(2, 2)] = gm.step(total, 1.0).0;
        assert!((units.interval_transition(total, gm) - one_piece).norm() > 1e-4);
    }
}
