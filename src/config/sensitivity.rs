//! The sensitivity study's section of the configuration and the sizes it accepts.

use serde::{Deserialize, Serialize};

use crate::error::ConfigError;

/// The sensitivity study: each statistic the filter assumes, scaled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensitivityConfig {
    /// Factors on the assumed standard deviations (a variance is scaled by the square).
    pub factors: Vec<f64>,
    /// Independent Monte Carlo ensembles of `ensemble.realizations` per statistic and factor.
    pub ensembles: u64,
    /// Sampled ensembles per statistic and factor that predict the detection probabilities.
    pub draws: u64,
}

impl Default for SensitivityConfig {
    fn default() -> Self {
        Self {
            factors: vec![0.25, 0.5, 2.0, 4.0],
            ensembles: 1,
            draws: 1000,
        }
    }
}

impl SensitivityConfig {
    /// The most Monte Carlo ensembles per statistic and factor.
    pub const MAX_ENSEMBLES: u64 = 10_000;
    /// The most sampled ensembles per statistic and factor.
    pub const MAX_DRAWS: u64 = 1_000_000;

    /// Checks the factors, ensembles and draws, naming them `fields` (the configuration's keys,
    /// or the command line's options that override them).
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first field out of range.
    pub fn check(&self, [factors, ensembles, draws]: [&'static str; 3]) -> Result<(), ConfigError> {
        if self.factors.is_empty() {
            return Err(ConfigError::invalid(
                factors,
                "[]",
                "must list at least one factor",
            ));
        }
        if let Some(f) = self
            .factors
            .iter()
            .find(|f| !(f.is_finite() && **f > 0.0 && **f <= 1e3))
        {
            return Err(ConfigError::invalid(
                factors,
                super::show(*f),
                "every factor must be a finite number in (0, 1000]",
            ));
        }
        if self.ensembles > Self::MAX_ENSEMBLES {
            return Err(ConfigError::invalid(
                ensembles,
                self.ensembles,
                format!("must be a whole number in [0, {}]", Self::MAX_ENSEMBLES),
            ));
        }
        if self.draws > Self::MAX_DRAWS {
            return Err(ConfigError::invalid(
                draws,
                self.draws,
                format!("must be a whole number in [0, {}]", Self::MAX_DRAWS),
            ));
        }
        Ok(())
    }
}
