//! A statistic the filter assumes, scaled in the filter's noise statistics themselves: the
//! sensitivity study's mistuned filters are not held to the range a configuration may set.

use super::AssumedStatistic;
use crate::state::NoiseStats;

impl AssumedStatistic {
    /// `stats` with this statistic's standard deviation times `factor` (a variance times
    /// `factor²`), as [`AssumedStatistic::scaled`] does to a configuration.
    pub fn scaled_stats(self, stats: &NoiseStats, factor: f64) -> NoiseStats {
        let mut s = *stats;
        let (value, power) = self.value_mut(&mut s);
        *value *= factor.powi(power);
        s
    }

    /// The value this statistic takes in `stats`, and the power of a factor on σ that scales it.
    fn value_mut(self, s: &mut NoiseStats) -> (&mut f64, i32) {
        match self {
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
        *self.value_mut(&mut s).0
    }
}
