//! The study's configuration: one TOML file holding every parameter, each with its unit in its name.
//!
//! Parsing ([`Config::from_toml_str`]) rejects unknown fields; a missing field takes its default.
//! Validation happens once, when a [`crate::model::Model`] is built from the parsed configuration,
//! and names the offending field with its accepted range.
//!
//! The noise statistics (the truth's and the `[filter]` keys that fall back to them) are the rows
//! of [`STATISTICS`] ([`statistics`]): the fallback, the default file ([`DEFAULT_TOML`]) and
//! everything else that lists them read that table.

mod bias;
mod case;
mod default_toml;
mod false_alarm;
pub mod ins;
mod keys;
mod sensitivity;
pub mod source;
pub mod statistics;

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::error::{ConfigError, Position};
pub use case::{AccelerometerOutput, BiasModelKind, Case, TruthModel};
pub use default_toml::DEFAULT_TOML;
pub use false_alarm::{MIN_FALSE_ALARM_RATE, validate_false_alarm_rate};
pub use sensitivity::SensitivityConfig;
pub use source::{ConfigText, MAX_CONFIG_BYTES};
pub use statistics::{FILTER_FLOOR, STATISTICS, Statistic};

/// Every parameter of the study.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    /// The true acceleration and the length of the run.
    pub profile: ProfileConfig,
    /// The accelerometer as it really is.
    pub accelerometer: AccelerometerConfig,
    /// The GPS receiver as it really is.
    pub gps: GpsConfig,
    /// The prior of the initial position and velocity.
    pub initial: InitialConfig,
    /// The statistics the filter assumes.
    pub filter: FilterConfig,
    /// The Monte Carlo ensemble.
    pub ensemble: EnsembleConfig,
    /// The statistical verdicts.
    pub checks: ChecksConfig,
    /// The sensitivity study.
    pub sensitivity: SensitivityConfig,
}

/// The true acceleration a(t) = A·sin(ω·t) and the length of the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProfileConfig {
    /// Amplitude A of the acceleration, m/s².
    pub accel_amplitude_m_s2: f64,
    /// Angular frequency ω of the acceleration, rad/s. The statement writes sin(2π·0.1·t) in one
    /// place and sin(ω·t) with ω = 0.1 rad/s in another; the default 2π·0.1 rad/s follows the first.
    pub accel_angular_freq_rad_s: f64,
    /// Length of the run, s.
    pub duration_s: f64,
}

impl Default for ProfileConfig {
    fn default() -> Self {
        Self {
            accel_amplitude_m_s2: 10.0,
            accel_angular_freq_rad_s: 2.0 * PI * 0.1,
            duration_s: 30.0,
        }
    }
}

/// The accelerometer as it really is (the truth).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AccelerometerConfig {
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Variance W of the white measurement noise w, (m/s²)².
    pub noise_var_m2_s4: f64,
    /// Variance of the zero-mean Gaussian prior of the constant bias b, (m/s²)².
    pub bias_var_m2_s4: f64,
    /// What each sample reports: the acceleration at the sample time, or its mean over the
    /// sample interval.
    pub output: AccelerometerOutput,
    /// How the bias moves between samples (left out of a written configuration when constant).
    #[serde(skip_serializing_if = "BiasModelKind::is_constant")]
    pub bias_model: BiasModelKind,
    /// K of a random-walk bias, b(t + Δt) − b(t) ~ N(0, K²·Δt), m/s² per √s; only with
    /// `bias_model = "random_walk"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_random_walk_m_s2_per_sqrt_s: Option<f64>,
    /// τ_b of a Gauss–Markov bias, ḃ = −b/τ_b + w_b with stationary variance `bias_var_m2_s4`, s;
    /// only with `bias_model = "gauss_markov"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_correlation_time_s: Option<f64>,
}

impl Default for AccelerometerConfig {
    fn default() -> Self {
        Self {
            sample_rate_hz: 200.0,
            noise_var_m2_s4: Statistic::ACCEL_NOISE_VAR.default,
            bias_var_m2_s4: Statistic::BIAS_VAR.default,
            output: AccelerometerOutput::Sample,
            bias_model: BiasModelKind::Constant,
            bias_random_walk_m_s2_per_sqrt_s: None,
            bias_correlation_time_s: None,
        }
    }
}

/// The GPS receiver as it really is (the truth).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GpsConfig {
    /// Fix rate, Hz; must divide the accelerometer rate (fixes are synchronized with samples).
    pub sample_rate_hz: f64,
    /// Standard deviation of the position noise η_p, m.
    pub position_sigma_m: f64,
    /// Standard deviation of the velocity noise η_v, m/s.
    pub velocity_sigma_m_s: f64,
    /// Take a fix at t = 0 too; by default the first fix is one GPS period after the start.
    pub fix_at_start: bool,
    /// The throwaway statistic of the registry's test ([`Statistic::THROWAWAY`]), m.
    #[cfg(feature = "throwaway-statistic")]
    pub throwaway_sigma_m: f64,
}

impl Default for GpsConfig {
    fn default() -> Self {
        Self {
            sample_rate_hz: 5.0,
            position_sigma_m: Statistic::GPS_POSITION_SIGMA.default,
            velocity_sigma_m_s: Statistic::GPS_VELOCITY_SIGMA.default,
            fix_at_start: false,
            #[cfg(feature = "throwaway-statistic")]
            throwaway_sigma_m: Statistic::THROWAWAY.default,
        }
    }
}

/// Gaussian prior of the vehicle's initial position p(0) and velocity v(0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InitialConfig {
    /// Mean of p(0), m; also the integration's start p_c(0).
    pub position_mean_m: f64,
    /// Standard deviation of p(0), m.
    pub position_sigma_m: f64,
    /// Mean of v(0), m/s; also the integration's start v_c(0).
    pub velocity_mean_m_s: f64,
    /// Standard deviation of v(0), m/s.
    pub velocity_sigma_m_s: f64,
}

impl Default for InitialConfig {
    fn default() -> Self {
        Self {
            position_mean_m: 0.0,
            position_sigma_m: Statistic::INITIAL_POSITION_SIGMA.default,
            velocity_mean_m_s: 100.0,
            velocity_sigma_m_s: Statistic::INITIAL_VELOCITY_SIGMA.default,
        }
    }
}

/// The statistics the Kalman filter assumes. Each missing field takes the truth's value, so a
/// mistuned filter is made by setting only the fields that differ.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FilterConfig {
    /// Assumed accelerometer noise variance, (m/s²)².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_noise_var_m2_s4: Option<f64>,
    /// Assumed bias prior variance, (m/s²)².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_var_m2_s4: Option<f64>,
    /// Assumed GPS position noise standard deviation, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gps_position_sigma_m: Option<f64>,
    /// Assumed GPS velocity noise standard deviation, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gps_velocity_sigma_m_s: Option<f64>,
    /// Assumed initial position standard deviation, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_position_sigma_m: Option<f64>,
    /// Assumed initial velocity standard deviation, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_velocity_sigma_m_s: Option<f64>,
    /// Assumed bias model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_model: Option<BiasModelKind>,
    /// Assumed K of a random-walk bias, m/s² per √s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_random_walk_m_s2_per_sqrt_s: Option<f64>,
    /// Assumed τ_b of a Gauss–Markov bias, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_correlation_time_s: Option<f64>,
    /// The throwaway statistic of the registry's test ([`Statistic::THROWAWAY`]), m.
    #[cfg(feature = "throwaway-statistic")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub throwaway_sigma_m: Option<f64>,
}

/// The Monte Carlo ensemble.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnsembleConfig {
    /// Number of realizations N.
    pub realizations: u64,
    /// Seed of the random streams; realization l of a case draws from the stream (seed, case, l).
    pub seed: u64,
    /// Truth model of the ensemble.
    pub truth: TruthModel,
}

impl Default for EnsembleConfig {
    fn default() -> Self {
        Self {
            realizations: 10_000,
            seed: 2017,
            truth: TruthModel::Analytic,
        }
    }
}

/// The statistical verdicts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChecksConfig {
    /// Study-wide false-alarm rate: the probability that a consistent filter fails any check. Each
    /// of the checks gets an equal share, split over its distinct members (Bonferroni).
    pub false_alarm_rate: f64,
    /// The single pair (t_m, t_i), t_m < t_i, of GPS fix times whose residual correlation the
    /// problem statement asks for, s. Default: the fixes nearest one third and two thirds of
    /// the run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_pair_s: Option<[f64; 2]>,
    /// Largest lag, in fixes, of the residual whiteness check. Left out, every pair of fixes is
    /// tested while there are at most 1000 fixes, and pairs up to 50 fixes apart beyond.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_max_lag: Option<u32>,
}

impl Default for ChecksConfig {
    fn default() -> Self {
        Self {
            false_alarm_rate: 0.01,
            residual_pair_s: None,
            residual_max_lag: None,
        }
    }
}

/// `x` as a person would write it and as it reads back: the shortest decimal that round-trips,
/// in exponent notation when it is very small or very large (1e-300, not 300 digits).
pub fn show(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

impl Config {
    /// Parses a TOML document. Missing fields take their defaults; unknown fields are an error.
    ///
    /// # Errors
    /// [`ConfigError::Parse`] with the parser's message, the line and column, the field's
    /// dotted path and the offending line where the parser gives a span.
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        if let Some(err) = source::lone_carriage_return(text) {
            return Err(err);
        }
        toml::from_str(text).map_err(|e| {
            let span = e.span();
            let message = source::explain(text, span.clone(), e.message().trim_end());
            ConfigError::Parse {
                file: None,
                position: span.clone().map(|s| Box::new(Position::of(text, s))),
                field: span.and_then(|s| source::field_at(text, s.start)),
                message,
            }
        })
    }

    /// The configuration as TOML, every field written out (the filter section only where set).
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).expect("a Config always serializes to TOML")
    }

    /// The simulated case: `ensemble.truth` and `accelerometer.output`.
    pub fn case(&self) -> Case {
        Case {
            truth: self.ensemble.truth,
            output: self.accelerometer.output,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_default_file_parses_to_the_default() {
        assert_eq!(
            Config::from_toml_str(DEFAULT_TOML).unwrap(),
            Config::default()
        );
    }

    #[test]
    fn missing_fields_take_defaults() {
        let c = Config::from_toml_str("[gps]\nposition_sigma_m = 2.0\n").unwrap();
        assert_eq!(c.gps.position_sigma_m, 2.0);
        assert_eq!(c.gps.sample_rate_hz, 5.0);
        assert_eq!(c.accelerometer, AccelerometerConfig::default());
    }

    #[test]
    fn unknown_field_is_an_error_naming_it() {
        let err = Config::from_toml_str("[gps]\nposition_sigma = 2.0\n").unwrap_err();
        assert!(err.to_string().contains("position_sigma"), "{err}");
    }

    #[test]
    fn parse_errors_name_line_column_field_and_quote_the_line() {
        let cases = [
            (
                "[ensemble]\nrealizations = \"many\"\n",
                (2, 16),
                "ensemble.realizations",
            ),
            (
                "[ensemble]\nrealizations = -1\n",
                (2, 16),
                "ensemble.realizations",
            ),
            (
                "[gps]\nposition_sigma_m = 1.0\nposition_sigma_m = 2.0\n",
                (3, 1),
                "gps.position_sigma_m",
            ),
            (
                "\n[checks]\nresidual_pair_s = [1.0, \"a\"]\n",
                (3, 25),
                "checks.residual_pair_s",
            ),
        ];
        for (text, (line, column), field) in cases {
            let err = Config::from_toml_str(text).unwrap_err();
            let ConfigError::Parse {
                position: Some(p),
                field: Some(f),
                ..
            } = &err
            else {
                panic!("no position for {text:?}: {err:?}");
            };
            assert_eq!((p.line, p.column), (line, column), "{err}");
            assert_eq!(f, field, "{err}");
            let shown = err.to_string();
            assert!(
                shown.contains(&format!("at line {line}, column {column}")),
                "{shown}"
            );
            assert!(
                shown.contains(text.lines().nth(line - 1).unwrap()),
                "{shown}"
            );
        }
    }

    #[test]
    fn filter_defaults_follow_the_truth() {
        let c = Config::from_toml_str("[gps]\nposition_sigma_m = 3.0\n").unwrap();
        assert_eq!(c.filter_gps_position_sigma_m(), 3.0);
        assert!(c.filter_matches_truth());
        let c = Config::from_toml_str("[filter]\ngps_position_sigma_m = 2.0\n").unwrap();
        assert_eq!(c.filter_gps_position_sigma_m(), 2.0);
        assert_eq!(c.gps.position_sigma_m, 1.0);
        assert!(!c.filter_matches_truth());
    }

    #[test]
    fn round_trips_through_toml() {
        let mut c = Config::default();
        c.filter.gps_position_sigma_m = Some(2.0);
        c.ensemble.truth = TruthModel::Euler;
        assert_eq!(Config::from_toml_str(&c.to_toml_string()).unwrap(), c);
    }
}
