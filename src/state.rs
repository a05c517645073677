//! The state model: what the filter estimates and what the GPS measures.
//!
//! A [`StateModel`] owns everything that depends on the choice of state: its dimension `N` and the
//! measurement's `M` (nalgebra static sizes), the names, symbols and units of every variable, the
//! transition Φ(t, τ), the process noise Q(t, τ), the observation matrix H, the measurement noise
//! R and the prior covariance P(0). The filter, the engines, the ensemble statistics, the checks
//! and the report ask the model; none of them writes a dimension or a state index.
//!
//! [`ErrorState`] is the accelerometer's error state δx = (δp, δv, b) of the problem statement:
//! position error (m), velocity error (m/s) and accelerometer bias (m/s²), measured by GPS through
//! (δp, δv). Its named indices ([`ErrorState::POSITION`], [`ErrorState::VELOCITY`],
//! [`ErrorState::BIAS`]) and sizes ([`ErrorState::DIM`], [`ErrorState::MEAS`]) are the only place
//! the numbers 0, 1, 2, 3 of the state appear.
//!
//! One accelerometer step — its output (eq. 2), its Euler integration (eq. 3), Φ, Γ and Q of
//! eq. (5) — is written once, in [`step`], for every caller.

use nalgebra::{SMatrix, SVector};

mod bias;
pub mod step;

pub use bias::BiasModel;
pub use step::{process_noise, transition};

/// Noise statistics of the error-state system: the truth's, or the ones the filter assumes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseStats {
    /// Accelerometer white-noise variance W, (m/s²)².
    pub accel_noise_var_m2_s4: f64,
    /// Bias prior variance, (m/s²)².
    pub bias_var_m2_s4: f64,
    /// GPS position noise σ, m.
    pub gps_position_sigma_m: f64,
    /// GPS velocity noise σ, m/s.
    pub gps_velocity_sigma_m_s: f64,
    /// Initial position σ, m.
    pub initial_position_sigma_m: f64,
    /// Initial velocity σ, m/s.
    pub initial_velocity_sigma_m_s: f64,
    /// How the bias moves between samples.
    pub bias_model: BiasModel,
}

/// One variable of a state or of a measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variable {
    /// Machine name, used in JSON fields and CSV columns (`"position"`, `"bias"`).
    pub key: &'static str,
    /// Name in words, for prose and table headers (`"position error"`).
    pub name: &'static str,
    /// Symbol in the report's notation (`"δp"`).
    pub symbol: &'static str,
    /// SI unit (`"m/s²"`).
    pub unit: &'static str,
}

/// The sizes of a state model: what a check's null distribution depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Dims {
    /// Number of states N.
    pub states: usize,
    /// Number of measured components M.
    pub measurements: usize,
}

/// A linear Gaussian state model with `N` states and `M` measured components.
///
/// Between fixes the state moves as x(t + τ) = Φ(t, τ)·x(t) + w, w ~ N(0, Q(t, τ)); a fix measures
/// z = H·x + η, η ~ N(0, R); the prior is x(0) ~ N(0, P(0)). Φ and Q may depend on the time t at
/// which the step starts (a state that multiplies a known input), never on the realization.
pub trait StateModel<const N: usize, const M: usize> {
    /// The state's variables, in state order.
    const STATES: [Variable; N];
    /// The measurement's components, in measurement order.
    const MEASUREMENTS: [Variable; M];
    /// Whether Φ(t, τ) and Q(t, τ) do not depend on t, so that a filter may compute one step
    /// once and reuse it.
    const TIME_INVARIANT: bool = false;

    /// Whether the transition over an interval of n steps of Δt is Φ(t, n·Δt) itself, so that a
    /// time-invariant model may compute it in one piece instead of as the product of its steps.
    fn transition_composes(&self) -> bool {
        false
    }

    /// Transition Φ(t, τ) of the state over [t, t + τ].
    fn transition(&self, t_s: f64, tau_s: f64) -> SMatrix<f64, N, N>;
    /// Process noise covariance Q(t, τ) accumulated over [t, t + τ].
    fn process_noise(&self, t_s: f64, tau_s: f64) -> SMatrix<f64, N, N>;
    /// Observation matrix H.
    fn observation(&self) -> SMatrix<f64, M, N>;
    /// Measurement noise covariance R.
    fn measurement_noise(&self) -> SMatrix<f64, M, M>;
    /// Prior covariance P(0).
    fn initial_covariance(&self) -> SMatrix<f64, N, N>;

    /// The model's sizes.
    fn dims(&self) -> Dims {
        Dims {
            states: N,
            measurements: M,
        }
    }

    /// Which states are constant between fixes: row k of Φ is the unit row and Q has nothing in
    /// row k (read off one step of a second at t = 0). The a priori error and estimate of such a
    /// state at a fix are the a posteriori ones of the previous fix, so the checks count them once.
    fn constant_states(&self) -> [bool; N] {
        let phi = self.transition(0.0, 1.0);
        let q = self.process_noise(0.0, 1.0);
        std::array::from_fn(|k| {
            (0..N).all(|c| phi[(k, c)] == if k == c { 1.0 } else { 0.0 } && q[(k, c)] == 0.0)
        })
    }
}

/// The accelerometer's error state δx = (δp, δv, b) for one set of noise statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorState {
    /// The noise statistics (the truth's, or the ones a filter assumes).
    pub stats: NoiseStats,
}

impl ErrorState {
    /// Number of states.
    pub const DIM: usize = 3;
    /// Number of measured components.
    pub const MEAS: usize = 2;
    /// Index of the position error δp = p − p_c, m.
    pub const POSITION: usize = 0;
    /// Index of the velocity error δv = v − v_c, m/s.
    pub const VELOCITY: usize = 1;
    /// Index of the accelerometer bias b, m/s².
    pub const BIAS: usize = 2;
    /// Index of the GPS position in a measurement or residual.
    pub const GPS_POSITION: usize = 0;
    /// Index of the GPS velocity in a measurement or residual.
    pub const GPS_VELOCITY: usize = 1;
    /// The sizes of the error state and the GPS measurement.
    pub const DIMS: Dims = Dims {
        states: Self::DIM,
        measurements: Self::MEAS,
    };
    /// The error state's variables (see [`StateModel::STATES`]).
    pub const VARIABLES: [Variable; Self::DIM] =
        <Self as StateModel<{ Self::DIM }, { Self::MEAS }>>::STATES;
    /// The GPS measurement's components (see [`StateModel::MEASUREMENTS`]).
    pub const MEASURED: [Variable; Self::MEAS] =
        <Self as StateModel<{ Self::DIM }, { Self::MEAS }>>::MEASUREMENTS;
}

/// A vector of the error state (m, m/s, m/s²).
pub type StateVector = SVector<f64, { ErrorState::DIM }>;
/// A state-space matrix: covariance or transition.
pub type StateMatrix = SMatrix<f64, { ErrorState::DIM }, { ErrorState::DIM }>;
/// A GPS measurement or residual (m, m/s).
pub type MeasVector = SVector<f64, { ErrorState::MEAS }>;
/// A measurement-space matrix: R, S.
pub type MeasMatrix = SMatrix<f64, { ErrorState::MEAS }, { ErrorState::MEAS }>;

impl StateModel<{ ErrorState::DIM }, { ErrorState::MEAS }> for ErrorState {
    const STATES: [Variable; ErrorState::DIM] = [
        Variable {
            key: "position",
            name: "position error",
            symbol: "δp",
            unit: "m",
        },
        Variable {
            key: "velocity",
            name: "velocity error",
            symbol: "δv",
            unit: "m/s",
        },
        Variable {
            key: "bias",
            name: "bias",
            symbol: "b",
            unit: "m/s²",
        },
    ];
    const MEASUREMENTS: [Variable; ErrorState::MEAS] = [
        Variable {
            key: "position",
            name: "GPS position",
            symbol: "δz_p",
            unit: "m",
        },
        Variable {
            key: "velocity",
            name: "GPS velocity",
            symbol: "δz_v",
            unit: "m/s",
        },
    ];

    const TIME_INVARIANT: bool = true;

    /// Φ(τ) = [[1, τ, −τ²/2], [0, 1, −τ], [0, 0, φ(τ)]]: [`transition`] with the bias's own
    /// φ(τ) of [`BiasModel::step`] (1 for a constant bias, the same matrix bit for bit).
    fn transition(&self, _t_s: f64, tau_s: f64) -> StateMatrix {
        match self.stats.bias_model {
            BiasModel::Constant => transition(tau_s),
            drifting => {
                let mut phi = transition(tau_s);
                phi[(Self::BIAS, Self::BIAS)] = drifting.step(tau_s, self.stats.bias_var_m2_s4).0;
                phi
            }
        }
    }

    /// Q(τ) = Γ·W·Γᵀ + diag(0, 0, q_b(τ)): [`process_noise`] with the bias's own q_b(τ) of
    /// [`BiasModel::step`] (0 for a constant bias, the same matrix bit for bit).
    fn process_noise(&self, _t_s: f64, tau_s: f64) -> StateMatrix {
        let q = process_noise(tau_s, self.stats.accel_noise_var_m2_s4);
        match self.stats.bias_model {
            BiasModel::Constant => q,
            drifting => {
                let mut q = q;
                q[(Self::BIAS, Self::BIAS)] = drifting.step(tau_s, self.stats.bias_var_m2_s4).1;
                q
            }
        }
    }

    /// Φ composes over n·Δt unless the bias is Gauss–Markov (see [`BiasModel::composes`]).
    fn transition_composes(&self) -> bool {
        self.stats.bias_model.composes()
    }

    /// GPS sees the position and velocity errors.
    fn observation(&self) -> SMatrix<f64, { ErrorState::MEAS }, { ErrorState::DIM }> {
        let mut h = SMatrix::zeros();
        h[(Self::GPS_POSITION, Self::POSITION)] = 1.0;
        h[(Self::GPS_VELOCITY, Self::VELOCITY)] = 1.0;
        h
    }

    /// R = diag(σ_p², σ_v²).
    fn measurement_noise(&self) -> MeasMatrix {
        MeasMatrix::from_diagonal(&MeasVector::new(
            self.stats.gps_position_sigma_m.powi(2),
            self.stats.gps_velocity_sigma_m_s.powi(2),
        ))
    }

    /// P(0) = diag(σ_p0², σ_v0², σ_b²).
    fn initial_covariance(&self) -> StateMatrix {
        StateMatrix::from_diagonal(&StateVector::new(
            self.stats.initial_position_sigma_m.powi(2),
            self.stats.initial_velocity_sigma_m_s.powi(2),
            self.stats.bias_var_m2_s4,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Matrix2x3Lit = SMatrix<f64, 2, 3>;

    /// The default configuration's statistics.
    pub(super) const STATS: NoiseStats = NoiseStats {
        accel_noise_var_m2_s4: 4e-4,
        bias_var_m2_s4: 0.01,
        gps_position_sigma_m: 1.0,
        gps_velocity_sigma_m_s: 0.04,
        initial_position_sigma_m: 10.0,
        initial_velocity_sigma_m_s: 1.0,
        bias_model: BiasModel::Constant,
    };

    /// The model's matrices are the problem statement's, bit for bit.
    #[test]
    fn matrices_equal_the_filters() {
        let model = ErrorState { stats: STATS };
        let dt = 0.005;
        // eq. (5) written out.
        let phi = StateMatrix::new(1.0, dt, -0.5 * dt * dt, 0.0, 1.0, -dt, 0.0, 0.0, 1.0);
        assert_eq!(model.transition(0.0, dt), phi);
        let gamma = StateVector::new(-0.5 * dt * dt, -dt, 0.0);
        let q = gamma * gamma.transpose() * STATS.accel_noise_var_m2_s4;
        assert_eq!(model.process_noise(0.0, dt), q);
        let h = Matrix2x3Lit::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        assert_eq!(model.observation(), h);
        let s = &STATS;
        let r = MeasVector::new(
            s.gps_position_sigma_m.powi(2),
            s.gps_velocity_sigma_m_s.powi(2),
        );
        assert_eq!(model.measurement_noise(), MeasMatrix::from_diagonal(&r));
        let p0 = StateVector::new(
            s.initial_position_sigma_m.powi(2),
            s.initial_velocity_sigma_m_s.powi(2),
            s.bias_var_m2_s4,
        );
        assert_eq!(model.initial_covariance(), StateMatrix::from_diagonal(&p0));
    }

    /// Names and indices agree.
    #[test]
    fn indices_name_their_variables() {
        let states = <ErrorState as StateModel<{ ErrorState::DIM }, { ErrorState::MEAS }>>::STATES;
        assert_eq!(states[ErrorState::BIAS].key, "bias");
        assert_eq!(states[ErrorState::POSITION].unit, "m");
        assert_eq!(states[ErrorState::VELOCITY].unit, "m/s");
        let h = ErrorState { stats: STATS }.observation();
        assert_eq!(
            h.column(ErrorState::BIAS).norm(),
            0.0,
            "the bias is not measured"
        );
    }

    /// Only the bias is constant between fixes.
    #[test]
    fn the_bias_is_the_constant_state() {
        let constant = ErrorState { stats: STATS }.constant_states();
        let expected: [bool; ErrorState::DIM] = std::array::from_fn(|k| k == ErrorState::BIAS);
        assert_eq!(constant, expected);
    }
}
