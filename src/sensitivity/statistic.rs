//! The statistics the filter assumes that the sensitivity study scales.

use crate::config::{BiasModelKind, Config};

/// A statistic the filter assumes (a key of the configuration's `[filter]` section).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AssumedStatistic {
    /// Accelerometer noise variance W.
    AccelNoise,
    /// Bias prior variance.
    BiasPrior,
    /// GPS position noise σ.
    GpsPosition,
    /// GPS velocity noise σ.
    GpsVelocity,
    /// Initial position σ.
    InitialPosition,
    /// Initial velocity σ.
    InitialVelocity,
    /// K of a random-walk bias (only for a filter that assumes one).
    BiasRandomWalk,
    /// τ_b of a Gauss–Markov bias (only for a filter that assumes one).
    BiasCorrelationTime,
}

impl AssumedStatistic {
    /// Every assumed statistic, in the configuration's order (the bias model's parameter last,
    /// so that the others keep their seeds).
    pub const ALL: [AssumedStatistic; 8] = [
        AssumedStatistic::AccelNoise,
        AssumedStatistic::BiasPrior,
        AssumedStatistic::GpsPosition,
        AssumedStatistic::GpsVelocity,
        AssumedStatistic::InitialPosition,
        AssumedStatistic::InitialVelocity,
        AssumedStatistic::BiasRandomWalk,
        AssumedStatistic::BiasCorrelationTime,
    ];

    /// The statistics the filter of `config` assumes: every one but the bias model's
    /// parameters, of which only the filter's own model's is (K for `"random_walk"`, τ_b for
    /// `"gauss_markov"`).
    pub fn of(config: &Config) -> Vec<Self> {
        let kind = config.filter_bias_model_kind();
        Self::ALL
            .into_iter()
            .filter(|s| match s {
                AssumedStatistic::BiasRandomWalk => kind == BiasModelKind::RandomWalk,
                AssumedStatistic::BiasCorrelationTime => kind == BiasModelKind::GaussMarkov,
                _ => true,
            })
            .collect()
    }

    /// The `[filter]` key.
    pub fn name(self) -> &'static str {
        match self {
            AssumedStatistic::AccelNoise => "accel_noise_var_m2_s4",
            AssumedStatistic::BiasPrior => "bias_var_m2_s4",
            AssumedStatistic::GpsPosition => "gps_position_sigma_m",
            AssumedStatistic::GpsVelocity => "gps_velocity_sigma_m_s",
            AssumedStatistic::InitialPosition => "initial_position_sigma_m",
            AssumedStatistic::InitialVelocity => "initial_velocity_sigma_m_s",
            AssumedStatistic::BiasRandomWalk => "bias_random_walk_m_s2_per_sqrt_s",
            AssumedStatistic::BiasCorrelationTime => "bias_correlation_time_s",
        }
    }

    /// The statistic in words, as a standard deviation (the factor scales it).
    pub fn title(self) -> &'static str {
        match self {
            AssumedStatistic::AccelNoise => "accelerometer noise σ",
            AssumedStatistic::BiasPrior => "bias prior σ",
            AssumedStatistic::GpsPosition => "GPS position σ",
            AssumedStatistic::GpsVelocity => "GPS velocity σ",
            AssumedStatistic::InitialPosition => "initial position σ",
            AssumedStatistic::InitialVelocity => "initial velocity σ",
            AssumedStatistic::BiasRandomWalk => "bias random walk K",
            AssumedStatistic::BiasCorrelationTime => "bias correlation time τ_b",
        }
    }

    /// The statistic named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// `config` with the filter assuming this statistic's standard deviation times `factor` (a
    /// variance times `factor²`), starting from the value the filter assumes in `config`.
    pub fn scaled(self, config: &Config, factor: f64) -> Config {
        let mut c = config.clone();
        let f = &mut c.filter;
        match self {
            AssumedStatistic::AccelNoise => {
                f.accel_noise_var_m2_s4 =
                    Some(config.filter_accel_noise_var_m2_s4() * factor * factor)
            }
            AssumedStatistic::BiasPrior => {
                f.bias_var_m2_s4 = Some(config.filter_bias_var_m2_s4() * factor * factor)
            }
            AssumedStatistic::GpsPosition => {
                f.gps_position_sigma_m = Some(config.filter_gps_position_sigma_m() * factor)
            }
            AssumedStatistic::GpsVelocity => {
                f.gps_velocity_sigma_m_s = Some(config.filter_gps_velocity_sigma_m_s() * factor)
            }
            AssumedStatistic::InitialPosition => {
                f.initial_position_sigma_m = Some(config.filter_initial_position_sigma_m() * factor)
            }
            AssumedStatistic::InitialVelocity => {
                f.initial_velocity_sigma_m_s =
                    Some(config.filter_initial_velocity_sigma_m_s() * factor)
            }
            // K is the σ of the walk over a second: it scales like a standard deviation. A
            // filter without a random walk gets the key anyway, and validation refuses it.
            AssumedStatistic::BiasRandomWalk => {
                f.bias_random_walk_m_s2_per_sqrt_s = Some(
                    config
                        .filter_bias_random_walk_m_s2_per_sqrt_s()
                        .unwrap_or(0.0)
                        * factor,
                )
            }
            // τ_b is a time, not a σ: the factor multiplies it.
            AssumedStatistic::BiasCorrelationTime => {
                f.bias_correlation_time_s =
                    Some(config.filter_bias_correlation_time_s().unwrap_or(f64::NAN) * factor)
            }
        }
        c
    }
}
