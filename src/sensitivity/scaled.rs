//! A statistic the filter assumes, scaled in the filter's noise statistics themselves: the
//! sensitivity study's mistuned filters are not held to the range a configuration may set.

use super::AssumedStatistic;
use crate::state::{BiasModel, NoiseStats};

impl AssumedStatistic {
    /// `stats` with this statistic's standard deviation times `factor` (a variance times
    /// `factor²`), as [`AssumedStatistic::scaled`] does to a configuration.
    pub fn scaled_stats(self, stats: &NoiseStats, factor: f64) -> NoiseStats {
        let mut s = *stats;
        let mut scratch = f64::NAN;
        let (value, power) = self.value_mut(&mut s, &mut scratch);
        *value *= factor.powi(power);
        s
    }

    /// The value this statistic takes in `stats`, and the power of a factor on σ that scales it.
    /// K scales like a standard deviation (the walk's σ over a second), τ_b like a time. A bias
    /// parameter of a model the filter does not assume has no value: a scratch slot takes the
    /// factor, and the filter stays as it is (the plan offers only the filter's own parameter).
    fn value_mut<'s>(self, s: &'s mut NoiseStats, scratch: &'s mut f64) -> (&'s mut f64, i32) {
        match self {
            AssumedStatistic::BiasRandomWalk => match &mut s.bias_model {
                BiasModel::RandomWalk { k_m_s2_per_sqrt_s } => (k_m_s2_per_sqrt_s, 1),
                _ => (scratch, 1),
            },
            AssumedStatistic::BiasCorrelationTime => match &mut s.bias_model {
                BiasModel::GaussMarkov { correlation_time_s } => (correlation_time_s, 1),
                _ => (scratch, 1),
            },
            AssumedStatistic::AccelNoise => (&mut s.accel_noise_var_m2_s4, 2),
            AssumedStatistic::BiasPrior => (&mut s.bias_var_m2_s4, 2),
            AssumedStatistic::GpsPosition => (&mut s.gps_position_sigma_m, 1),
            AssumedStatistic::GpsVelocity => (&mut s.gps_velocity_sigma_m_s, 1),
            AssumedStatistic::InitialPosition => (&mut s.initial_position_sigma_m, 1),
            AssumedStatistic::InitialVelocity => (&mut s.initial_velocity_sigma_m_s, 1),
        }
    }

    /// The value this statistic takes in `stats`.
    pub fn value(self, stats: &NoiseStats) -> f64 {
        let mut s = *stats;
        let mut scratch = f64::NAN;
        *self.value_mut(&mut s, &mut scratch).0
    }
}
