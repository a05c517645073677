//! The statistics the filter assumes that the sensitivity study scales: the rows of
//! [`STATISTICS`], each scaled by its kind.

use crate::config::{Config, STATISTICS, Statistic};

/// A statistic the filter assumes (a key of the configuration's `[filter]` section): a row of
/// [`STATISTICS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AssumedStatistic(pub &'static Statistic);

/// The number of statistics.
const COUNT: usize = STATISTICS.len();

#[allow(non_upper_case_globals)]
impl AssumedStatistic {
    /// Every assumed statistic, in the configuration's order (the bias model's parameters last,
    /// so that the others keep their seeds).
    pub const ALL: [AssumedStatistic; COUNT] = {
        let mut all = [AssumedStatistic(&STATISTICS[0]); COUNT];
        let mut i = 0;
        while i < COUNT {
            all[i] = AssumedStatistic(&STATISTICS[i]);
            i += 1;
        }
        all
    };

    /// Accelerometer noise variance W.
    pub const AccelNoise: Self = Self(&Statistic::ACCEL_NOISE_VAR);
    /// Bias prior variance.
    pub const BiasPrior: Self = Self(&Statistic::BIAS_VAR);
    /// GPS position noise σ.
    pub const GpsPosition: Self = Self(&Statistic::GPS_POSITION_SIGMA);
    /// GPS velocity noise σ.
    pub const GpsVelocity: Self = Self(&Statistic::GPS_VELOCITY_SIGMA);
    /// Initial position σ.
    pub const InitialPosition: Self = Self(&Statistic::INITIAL_POSITION_SIGMA);
    /// Initial velocity σ.
    pub const InitialVelocity: Self = Self(&Statistic::INITIAL_VELOCITY_SIGMA);
    /// K of a random-walk bias (only for a filter that assumes one).
    pub const BiasRandomWalk: Self = Self(&Statistic::BIAS_RANDOM_WALK);
    /// τ_b of a Gauss–Markov bias (only for a filter that assumes one).
    pub const BiasCorrelationTime: Self = Self(&Statistic::BIAS_CORRELATION_TIME);

    /// The statistics the filter of `config` assumes: every one but the bias model's
    /// parameters, of which only the filter's own model's is (K for `"random_walk"`, τ_b for
    /// `"gauss_markov"`).
    pub fn of(config: &Config) -> Vec<Self> {
        Self::ALL
            .into_iter()
            .filter(|s| s.0.assumed_by(config))
            .collect()
    }

    /// The `[filter]` key.
    pub fn name(self) -> &'static str {
        self.0.key()
    }

    /// The statistic in words, as a standard deviation (the factor scales it).
    pub fn title(self) -> &'static str {
        self.0.title
    }

    /// The statistic named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// `config` with the filter assuming this statistic's standard deviation times `factor` (a
    /// variance times `factor²`, a time times `factor`), starting from the value the filter
    /// assumes in `config`. A bias model's parameter the filter does not assume starts from no
    /// walk (K) or no time (τ_b): the filter gets the key anyway, and validation refuses it.
    pub fn scaled(self, config: &Config, factor: f64) -> Config {
        let s = self.0;
        let from = config.filter_value(s).unwrap_or(s.kind.when_absent());
        // One multiplication per power, (x·f)·f for a variance, as the study always has.
        let scaled = (0..s.kind.factor_power()).fold(from, |x, _| x * factor);
        let mut c = config.clone();
        *(s.filter)(&mut c.filter) = Some(scaled);
        c
    }
}
