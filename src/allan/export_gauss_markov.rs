//! The `gauss_markov` record of `allan.json` ([`crate::allan::gauss_markov_fit`]).

use serde::Serialize;

use super::TermRecord;
use crate::allan::GaussMarkov;

/// An interval whose ends may all be absent: `correlation_time_s` of `gauss_markov`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntervalRecord {
    /// The estimate, or null.
    pub value: Option<f64>,
    /// Lower end, or null.
    pub lower: Option<f64>,
    /// Upper end, or null.
    pub upper: Option<f64>,
}

/// `gauss_markov.test` of `allan.json`: the fit with the term against the fit without.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GaussMarkovTestRecord {
    /// ΔT/g, the drop of the weighted residual over the goodness test's scale.
    pub statistic: f64,
    /// P(χ²₂ > ΔT/g).
    pub p_value: f64,
    /// The goodness-of-fit p-value of the fit with the term.
    pub goodness_p_value: f64,
    /// The stated false-alarm rate.
    pub alpha: f64,
}

/// `gauss_markov` of `allan.json`: the first-order Gauss–Markov bias where a hump shows one
/// ([`crate::allan::gauss_markov_fit`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GaussMarkovRecord {
    /// Whether the log resolves the term.
    pub resolved: bool,
    /// σ of the process in the samples' unit: value and interval, or (not resolved) null and the
    /// upper bound at the best-fitting T_c.
    pub sigma: TermRecord,
    /// T_c, s, with its interval; null when not resolved.
    pub correlation_time_s: IntervalRecord,
    /// Why the term is not resolved; null when it is.
    pub reason: Option<String>,
    /// The test.
    pub test: GaussMarkovTestRecord,
}

impl From<&GaussMarkov> for GaussMarkovRecord {
    fn from(g: &GaussMarkov) -> Self {
        Self {
            resolved: g.resolved,
            sigma: TermRecord {
                value: g.sigma,
                lower: g.sigma_lower,
                upper: g.sigma_upper,
            },
            correlation_time_s: IntervalRecord {
                value: g.correlation_time_s,
                lower: g.correlation_time_lower_s,
                upper: g.correlation_time_upper_s,
            },
            reason: g.reason.clone(),
            test: GaussMarkovTestRecord {
                statistic: g.statistic,
                p_value: g.p_value,
                goodness_p_value: g.goodness_p_value,
                alpha: g.alpha,
            },
        }
    }
}
