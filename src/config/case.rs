//! The simulated worlds: which truth model produces the trajectory, and what the accelerometer
//! reports.

use std::fmt;

use serde::{Deserialize, Serialize};

/// Which model produces the true position and velocity.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TruthModel {
    /// Closed-form integral of the acceleration profile, eq. (1) of the problem statement.
    Analytic,
    /// The true acceleration integrated with the accelerometer's Euler formula, eq. (4): the error
    /// dynamics of eq. (5) are then exact.
    Euler,
}

impl TruthModel {
    /// Both models, in the order the report presents them.
    pub const ALL: [TruthModel; 2] = [TruthModel::Analytic, TruthModel::Euler];

    /// The lowercase name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TruthModel::Analytic => "analytic",
            TruthModel::Euler => "euler",
        }
    }
}

impl fmt::Display for TruthModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which model the accelerometer bias follows (`bias_model`); its parameters are keys of their
/// own (see [`crate::state::BiasModel`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BiasModelKind {
    /// A constant bias, the problem statement's model.
    #[default]
    Constant,
    /// A random walk of `bias_random_walk_m_s2_per_sqrt_s`.
    RandomWalk,
    /// A first-order Gauss–Markov process of `bias_correlation_time_s`.
    GaussMarkov,
}

impl BiasModelKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            BiasModelKind::Constant => "constant",
            BiasModelKind::RandomWalk => "random_walk",
            BiasModelKind::GaussMarkov => "gauss_markov",
        }
    }

    /// Whether this is the default constant bias (left out when a configuration is written, so
    /// that every output of a constant-bias study stays as it was).
    pub fn is_constant(&self) -> bool {
        *self == BiasModelKind::Constant
    }
}

impl fmt::Display for BiasModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the accelerometer reports at each sample t_j.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelerometerOutput {
    /// The acceleration at the sample time: a_c(t_j) = a(t_j) + b + w(t_j), eq. (2) of the
    /// problem statement.
    #[default]
    Sample,
    /// The mean acceleration over the sample interval, as a strapdown IMU's delta-velocity
    /// output gives it: a_c(t_j) = (1/Δt)∫ a dt over [t_j, t_j + Δt] + b + w(t_j). The Euler
    /// velocity integration is then exact.
    IntervalMean,
}

impl AccelerometerOutput {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            AccelerometerOutput::Sample => "sample",
            AccelerometerOutput::IntervalMean => "interval_mean",
        }
    }
}

impl fmt::Display for AccelerometerOutput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One simulated world: a truth model and an accelerometer output. Each case draws from its own
/// random streams, so the verdicts of different cases are independent evidence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Case {
    /// How the true position and velocity are produced.
    pub truth: TruthModel,
    /// What the accelerometer reports.
    pub output: AccelerometerOutput,
}

impl Case {
    /// The world the filter's model assumes: the Euler truth with point samples.
    pub const MODEL_WORLD: Case = Case {
        truth: TruthModel::Euler,
        output: AccelerometerOutput::Sample,
    };

    /// The closed-form physics with point samples.
    pub const POINT_SAMPLES: Case = Case {
        truth: TruthModel::Analytic,
        output: AccelerometerOutput::Sample,
    };

    /// The closed-form physics with interval means.
    pub const INTERVAL_MEANS: Case = Case {
        truth: TruthModel::Analytic,
        output: AccelerometerOutput::IntervalMean,
    };

    /// The cases of the report, in order.
    pub const REPORT: [Case; 3] = [Self::MODEL_WORLD, Self::POINT_SAMPLES, Self::INTERVAL_MEANS];

    /// A number that tells the case's random streams apart from every other case's.
    pub fn stream_key(self) -> u64 {
        match (self.truth, self.output) {
            (TruthModel::Analytic, AccelerometerOutput::Sample) => 0,
            (TruthModel::Euler, AccelerometerOutput::Sample) => 1,
            (TruthModel::Analytic, AccelerometerOutput::IntervalMean) => 2,
            (TruthModel::Euler, AccelerometerOutput::IntervalMean) => 3,
        }
    }

    /// A stable identifier, e.g. `analytic-interval_mean`.
    pub fn id(self) -> String {
        format!("{}-{}", self.truth, self.output)
    }
}

impl fmt::Display for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} truth, {} output", self.truth, self.output)
    }
}
