//! The bias model's keys: each model takes only its own parameter, in its accepted range.

use super::{finite_in, positive, show};
use crate::config::{BiasModelKind, Config, Statistic};
use crate::error::ConfigError;

/// Largest accepted K of a random-walk bias, m/s² per √s.
const MAX_RANDOM_WALK_M_S2_PER_SQRT_S: f64 = Statistic::BIAS_RANDOM_WALK.truth_range.hi;
/// Largest accepted τ_b of a Gauss–Markov bias, s.
const MAX_CORRELATION_TIME_S: f64 = Statistic::BIAS_CORRELATION_TIME.truth_range.hi;

/// The keys of one side (the accelerometer's truth or the filter's assumption).
struct BiasKeys {
    /// `accelerometer` or `filter`.
    section: &'static str,
    model_field: &'static str,
    k_field: &'static str,
    tau_field: &'static str,
}

const TRUTH: BiasKeys = BiasKeys {
    section: "accelerometer",
    model_field: "accelerometer.bias_model",
    k_field: "accelerometer.bias_random_walk_m_s2_per_sqrt_s",
    tau_field: "accelerometer.bias_correlation_time_s",
};

const FILTER: BiasKeys = BiasKeys {
    section: "filter",
    model_field: "filter.bias_model",
    k_field: "filter.bias_random_walk_m_s2_per_sqrt_s",
    tau_field: "filter.bias_correlation_time_s",
};

/// The truth's and the filter's bias models: a key the model does not use is refused, the one it
/// uses must be set (the filter's may come from the truth) and in range: K in [0, 1000] m/s²/√s,
/// τ_b in (0, 10⁹] s.
pub(super) fn validate_bias(c: &Config) -> Result<(), ConfigError> {
    let (a, f) = (&c.accelerometer, &c.filter);
    let truth = a.bias_model;
    unused(
        &TRUTH,
        truth,
        a.bias_random_walk_m_s2_per_sqrt_s,
        a.bias_correlation_time_s,
    )?;
    let filter = c.filter_bias_model_kind();
    unused(
        &FILTER,
        filter,
        f.bias_random_walk_m_s2_per_sqrt_s,
        f.bias_correlation_time_s,
    )?;
    in_range(
        &TRUTH,
        a.bias_random_walk_m_s2_per_sqrt_s,
        a.bias_correlation_time_s,
    )?;
    in_range(
        &FILTER,
        f.bias_random_walk_m_s2_per_sqrt_s,
        f.bias_correlation_time_s,
    )?;
    required(
        &TRUTH,
        truth,
        a.bias_random_walk_m_s2_per_sqrt_s,
        a.bias_correlation_time_s,
    )?;
    required(
        &FILTER,
        filter,
        c.filter_bias_random_walk_m_s2_per_sqrt_s(),
        c.filter_bias_correlation_time_s(),
    )
}

/// A parameter set beside a model that does not use it.
fn unused(
    keys: &BiasKeys,
    kind: BiasModelKind,
    k: Option<f64>,
    tau_b: Option<f64>,
) -> Result<(), ConfigError> {
    let refuse = |field: &'static str, x: f64, wants: &str| {
        Err(ConfigError::invalid(
            field,
            show(x),
            format!(
                "is used only with {} = \"{wants}\", and the {} bias model is \"{kind}\": remove \
                 it or set {} = \"{wants}\"",
                keys.model_field, keys.section, keys.model_field
            ),
        ))
    };
    match (k, tau_b) {
        (Some(x), _) if kind != BiasModelKind::RandomWalk => refuse(keys.k_field, x, "random_walk"),
        (_, Some(x)) if kind != BiasModelKind::GaussMarkov => {
            refuse(keys.tau_field, x, "gauss_markov")
        }
        _ => Ok(()),
    }
}

/// The parameters that are set, in their accepted ranges.
fn in_range(keys: &BiasKeys, k: Option<f64>, tau_b: Option<f64>) -> Result<(), ConfigError> {
    if let Some(x) = k {
        finite_in(keys.k_field, x, 0.0, MAX_RANDOM_WALK_M_S2_PER_SQRT_S, false)?;
    }
    if let Some(x) = tau_b {
        positive(keys.tau_field, x, MAX_CORRELATION_TIME_S)?;
    }
    Ok(())
}

/// The parameter the model uses is set.
fn required(
    keys: &BiasKeys,
    kind: BiasModelKind,
    k: Option<f64>,
    tau_b: Option<f64>,
) -> Result<(), ConfigError> {
    let missing = |field: &'static str, what: &str| {
        Err(ConfigError::invalid(
            field,
            "missing",
            format!("must be set with {} = \"{kind}\": {what}", keys.model_field),
        ))
    };
    match kind {
        BiasModelKind::RandomWalk if k.is_none() => {
            missing(keys.k_field, "K, m/s² per √s, a finite number in [0, 1000]")
        }
        BiasModelKind::GaussMarkov if tau_b.is_none() => {
            missing(keys.tau_field, "τ_b, s, a finite number in (0, 1e9]")
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use crate::config::{BiasModelKind, Config};
    use crate::error::ConfigError;
    use crate::model::Model;

    fn refused(c: &Config) -> (&'static str, String) {
        match Model::new(c) {
            Err(e @ ConfigError::Invalid { .. }) => {
                let ConfigError::Invalid { field, .. } = &e else {
                    unreachable!()
                };
                (*field, e.to_string())
            }
            Err(e) => panic!("unexpected {e}"),
            Ok(_) => panic!("accepted an invalid configuration"),
        }
    }

    #[test]
    fn each_model_takes_only_its_own_parameter_in_range() {
        let mut c = Config::default();
        c.accelerometer.bias_correlation_time_s = Some(10.0);
        assert_eq!(refused(&c).0, "accelerometer.bias_correlation_time_s");
        let mut c = Config::default();
        c.accelerometer.bias_model = BiasModelKind::RandomWalk;
        assert_eq!(
            refused(&c).0,
            "accelerometer.bias_random_walk_m_s2_per_sqrt_s"
        );
        c.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(-1.0);
        assert_eq!(
            refused(&c).0,
            "accelerometer.bias_random_walk_m_s2_per_sqrt_s"
        );
        c.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(f64::NAN);
        assert_eq!(
            refused(&c).0,
            "accelerometer.bias_random_walk_m_s2_per_sqrt_s"
        );
        c.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(0.0);
        assert!(Model::new(&c).is_ok());
        c.filter.bias_correlation_time_s = Some(5.0);
        let (field, message) = refused(&c);
        assert_eq!(field, "filter.bias_correlation_time_s");
        assert!(message.contains("gauss_markov"), "{message}");
        c.filter.bias_model = Some(BiasModelKind::GaussMarkov);
        assert!(Model::new(&c).is_ok());
        c.filter.bias_correlation_time_s = Some(0.0);
        assert_eq!(refused(&c).0, "filter.bias_correlation_time_s");
        c.filter.bias_correlation_time_s = Some(f64::INFINITY);
        assert_eq!(refused(&c).0, "filter.bias_correlation_time_s");
        let mut c = Config::default();
        c.filter.bias_model = Some(BiasModelKind::GaussMarkov);
        assert_eq!(refused(&c).0, "filter.bias_correlation_time_s");
    }
}
