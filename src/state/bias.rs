//! The accelerometer bias's model between samples: constant, random walk or Gauss–Markov.

/// How the accelerometer bias b moves between samples.
///
/// The sample at t_j reads a(t_j) + b(t_j) + w_j, held over [t_j, t_j + Δt]; between samples the
/// bias follows its continuous model exactly, an AR(1) sequence b(t + τ) = φ(τ)·b(t) + η,
/// η ~ N(0, q_b(τ)) (see [`BiasModel::step`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum BiasModel {
    /// A constant b, drawn once from N(0, σ_b²): the problem statement's model.
    #[default]
    Constant,
    /// A random walk, ḃ = w_b with w_b of spectral density K²: b(t + τ) − b(t) ~ N(0, K²·τ).
    RandomWalk {
        /// K, m/s² per √s.
        k_m_s2_per_sqrt_s: f64,
    },
    /// A first-order Gauss–Markov process, ḃ = −b/τ_b + w_b, stationary at N(0, σ_b²) (w_b of
    /// spectral density 2σ_b²/τ_b).
    GaussMarkov {
        /// τ_b, s.
        correlation_time_s: f64,
    },
}

impl BiasModel {
    /// The name used in files (`"constant"`, `"random_walk"`, `"gauss_markov"`).
    pub fn name(self) -> &'static str {
        match self {
            BiasModel::Constant => "constant",
            BiasModel::RandomWalk { .. } => "random_walk",
            BiasModel::GaussMarkov { .. } => "gauss_markov",
        }
    }

    /// Whether the bias moves at all between samples.
    pub fn drifts(self) -> bool {
        self != BiasModel::Constant
    }

    /// (φ(τ), q_b(τ)): the bias's exact discretization over τ seconds, b(t + τ) = φ·b(t) + η,
    /// η ~ N(0, q_b), for the variance σ_b² = `bias_var_m2_s4` (the Gauss–Markov model's
    /// stationary variance).
    ///
    /// # Formula
    /// constant: φ = 1, q_b = 0; random walk: φ = 1, q_b = K²·τ; Gauss–Markov: φ = e^(−τ/τ_b),
    /// q_b = σ_b²·(1 − φ²) = −σ_b²·expm1(−2τ/τ_b) (the integral ∫₀^τ φ(s)²·2σ_b²/τ_b ds, which
    /// Van Loan's method gives for the scalar system).
    ///
    /// # Examples
    /// ```
    /// use accelcal::state::BiasModel;
    /// let gm = BiasModel::GaussMarkov { correlation_time_s: 100.0 };
    /// let (phi, q) = gm.step(0.005, 0.01);
    /// assert!((phi * phi * 0.01 + q - 0.01).abs() < 1e-15); // stationary
    /// ```
    pub fn step(self, tau_s: f64, bias_var_m2_s4: f64) -> (f64, f64) {
        match self {
            BiasModel::Constant => (1.0, 0.0),
            BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: k,
            } => (1.0, k * k * tau_s),
            BiasModel::GaussMarkov {
                correlation_time_s: tau_b,
            } => (
                (-tau_s / tau_b).exp(),
                -bias_var_m2_s4 * (-2.0 * tau_s / tau_b).exp_m1(),
            ),
        }
    }

    /// Whether the transition over n steps of Δt is the one-step formula at τ = n·Δt: true for a
    /// constant bias and a random walk (Φ unipotent), false for Gauss–Markov, whose bias decays
    /// within the interval while each step holds it.
    pub fn composes(self) -> bool {
        !matches!(self, BiasModel::GaussMarkov { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::BiasModel;
    use crate::state::{ErrorState, NoiseStats, StateModel};

    /// A drifting bias changes only the bias's own entries, and the bias is then no longer a
    /// constant state.
    #[test]
    fn a_drifting_bias_has_its_own_step() {
        let dt = 0.005;
        let constant = ErrorState {
            stats: crate::state::tests::STATS,
        };
        let k = 0.02;
        let rw = ErrorState {
            stats: NoiseStats {
                bias_model: BiasModel::RandomWalk {
                    k_m_s2_per_sqrt_s: k,
                },
                ..crate::state::tests::STATS
            },
        };
        assert_eq!(rw.transition(0.0, dt), constant.transition(0.0, dt));
        let mut q = constant.process_noise(0.0, dt);
        q[(ErrorState::BIAS, ErrorState::BIAS)] = k * k * dt;
        assert_eq!(rw.process_noise(0.0, dt), q);
        assert!(rw.transition_composes());
        let tau_b = 20.0;
        let gm = ErrorState {
            stats: NoiseStats {
                bias_model: BiasModel::GaussMarkov {
                    correlation_time_s: tau_b,
                },
                ..crate::state::tests::STATS
            },
        };
        let phi = (-dt / tau_b).exp();
        assert_eq!(gm.transition(0.0, dt)[(2, 2)], phi);
        let q_b = gm.process_noise(0.0, dt)[(2, 2)];
        approx::assert_relative_eq!(
            q_b,
            crate::state::tests::STATS.bias_var_m2_s4 * (1.0 - phi * phi),
            max_relative = 1e-9
        );
        assert!(!gm.transition_composes());
        assert_eq!(rw.constant_states(), [false; ErrorState::DIM]);
        assert_eq!(gm.constant_states(), [false; ErrorState::DIM]);
    }
}
