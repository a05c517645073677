//! A statistic the filter assumes, scaled in the filter's noise statistics themselves: the
//! sensitivity study's mistuned filters are not held to the range a configuration may set.

use super::AssumedStatistic;
use crate::state::NoiseStats;

impl AssumedStatistic {
    /// `stats` with this statistic's standard deviation times `factor` (a variance times
    /// `factor²`), as [`AssumedStatistic::scaled`] does to a configuration. A statistic the
    /// statistics hold no value of (a bias parameter of a model the filter does not assume)
    /// leaves them as they are (the plan offers only the filter's own parameter).
    pub fn scaled_stats(self, stats: &NoiseStats, factor: f64) -> NoiseStats {
        let mut s = *stats;
        if let Some(value) = (self.0.stats)(&mut s) {
            *value *= factor.powi(self.0.kind.factor_power());
        }
        s
    }

    /// The value this statistic takes in `stats` (NaN when they hold none).
    pub fn value(self, stats: &NoiseStats) -> f64 {
        self.0.stats_value(stats).unwrap_or(f64::NAN)
    }
}
