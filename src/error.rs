//! The library's error types.

use thiserror::Error;

/// A configuration that cannot be read, parsed or accepted.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConfigError {
    /// The configuration file could not be read.
    #[error("cannot read configuration file {path}: {message}")]
    Read { path: String, message: String },
    /// The text is not a valid configuration (syntax, type, or unknown field).
    #[error("invalid configuration: {message}")]
    Parse { message: String },
    /// A field holds a value outside its accepted range.
    #[error("invalid configuration: `{field}` = {value}: {expected}")]
    Invalid {
        /// Dotted path of the field, e.g. `gps.sample_rate_hz`.
        field: &'static str,
        /// The value as given.
        value: String,
        /// The accepted range, in words.
        expected: String,
    },
}

impl ConfigError {
    pub(crate) fn invalid(
        field: &'static str,
        value: impl ToString,
        expected: impl Into<String>,
    ) -> Self {
        ConfigError::Invalid {
            field,
            value: value.to_string(),
            expected: expected.into(),
        }
    }
}

/// A covariance the filter computed stopped being symmetric positive definite.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FilterError {
    /// The innovation covariance S = H·P⁻·Hᵀ + R has no Cholesky factor.
    #[error("innovation covariance at t = {time_s} s is not positive definite")]
    InnovationNotPositiveDefinite { time_s: f64 },
    /// The state covariance P has no Cholesky factor.
    #[error("{which} covariance at t = {time_s} s is not positive definite")]
    CovarianceNotPositiveDefinite { which: &'static str, time_s: f64 },
}
