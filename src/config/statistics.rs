//! The noise statistics the truth has and the filter assumes, one row each in [`STATISTICS`].
//!
//! A row ([`Statistic`]) names the statistic's `[filter]` key and the truth's key it falls back
//! to, its unit, its kind (a variance, a σ, a random walk's K or a correlation time τ), its
//! default, the ranges each side accepts, what it scales in the state model (Q, R or P(0)), its
//! datasheet unit, its words in the report, and where its value lives (the configuration's
//! fields and [`NoiseStats`]). Everything that lists the statistics reads this table: the
//! fallback of a `[filter]` key to the truth ([`Config::filter_value`]), the default TOML file
//! ([`super::DEFAULT_TOML`]), the validation of both sides (`model::validate`), the sensitivity
//! study's statistics and factors (`sensitivity::AssumedStatistic`), the likelihood's searchable
//! keys (`likelihood::Key`) and the report's parameter table (`report::params`).
//!
//! Adding a statistic takes its row here, its fields in the configuration's sections (and in
//! [`NoiseStats`] with its use in Q or R when the model uses it); `tests/statistic_registry.rs`
//! adds one so (`--features throwaway-statistic`) and finds it in each of those places.

mod table;

use super::{BiasModelKind, Config, FilterConfig};
use crate::state::{BiasModel, NoiseStats};

pub use table::STATISTICS;

/// Smallest variance or standard deviation the filter may assume: below it the covariance
/// recursion cannot stay positive definite in double precision.
pub const FILTER_FLOOR: f64 = 1e-12;

/// What a statistic is: how a factor on a standard deviation scales it, and how wide the
/// likelihood's search around it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// A variance, (unit)²: a factor on σ scales it by the factor squared.
    Variance,
    /// A standard deviation σ.
    Sigma,
    /// K of a random walk, b(t + Δt) − b(t) ~ N(0, K²·Δt): the walk's σ over a second, scaled
    /// like a standard deviation.
    RandomWalk,
    /// A correlation time τ: a time, which a factor multiplies.
    CorrelationTime,
}

impl Kind {
    /// The power of a factor on σ that scales a statistic of this kind.
    pub const fn factor_power(self) -> i32 {
        match self {
            Kind::Variance => 2,
            Kind::Sigma | Kind::RandomWalk | Kind::CorrelationTime => 1,
        }
    }

    /// The likelihood search's half-width in decades around the configured value: 3 for a σ or
    /// K, 6 for a variance (3 decades of its σ).
    pub const fn decades(self) -> f64 {
        match self {
            Kind::Variance => 6.0,
            Kind::Sigma | Kind::RandomWalk | Kind::CorrelationTime => 3.0,
        }
    }

    /// The value the sensitivity study scales when the filter assumes none (a bias model's
    /// parameter of another model): no walk for K, no time for τ.
    pub const fn when_absent(self) -> f64 {
        match self {
            Kind::CorrelationTime => f64::NAN,
            Kind::Variance | Kind::Sigma | Kind::RandomWalk => 0.0,
        }
    }
}

/// Which covariance of the state model a statistic sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scales {
    /// The process noise Q between fixes.
    ProcessNoise,
    /// The measurement noise R of a fix.
    MeasurementNoise,
    /// The prior covariance P(0).
    Prior,
}

/// A closed-above interval of accepted values, lo ≤ x ≤ hi (lo < x ≤ hi when `lo_open`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The lower end.
    pub lo: f64,
    /// The upper end (included).
    pub hi: f64,
    /// Whether the lower end is excluded.
    pub lo_open: bool,
}

impl Range {
    /// [lo, hi].
    pub const fn closed(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: false,
        }
    }

    /// (lo, hi].
    pub const fn open_below(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: true,
        }
    }

    /// Whether `x` is a finite number in the range.
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite()
            && (if self.lo_open {
                x > self.lo
            } else {
                x >= self.lo
            })
            && x <= self.hi
    }
}

/// Where a statistic stands in the report's parameter table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamRow {
    /// A row of its own, with this quantity (in the report's `_{…}` notation).
    Own(&'static str),
    /// Inside the row of its prior, N(mean, σ²), which the table writes with the mean.
    WithMean,
    /// Not in the table (a bias model's parameter, which the drift section shows).
    Hidden,
}

/// One noise statistic: its keys, unit, kind, default, ranges, words and storage.
#[derive(Clone, Copy, Debug)]
pub struct Statistic {
    /// The `[filter]` key's dotted path (`"filter.bias_var_m2_s4"`).
    pub filter_path: &'static str,
    /// The truth's key's dotted path, which a missing `[filter]` key falls back to
    /// (`"accelerometer.bias_var_m2_s4"`).
    pub truth_path: &'static str,
    /// The SI unit.
    pub unit: &'static str,
    /// The kind of value.
    pub kind: Kind,
    /// What it scales in the state model.
    pub scales: Scales,
    /// The unit a datasheet gives it in.
    pub datasheet_unit: &'static str,
    /// The default (for a bias model's parameter, which has none, the example the default
    /// file shows).
    pub default: f64,
    /// The default as the default file writes it (parses to `default`).
    pub default_toml: &'static str,
    /// Comment lines the default file writes above the truth's key (each ending in a newline).
    pub toml_comment: &'static str,
    /// The truth's accepted range.
    pub truth_range: Range,
    /// The filter's accepted range.
    pub filter_range: Range,
    /// The bias model the statistic belongs to (its keys are optional and only with it).
    pub bias_model: Option<BiasModelKind>,
    /// The symbol in the report's notation (`"σ_p"`).
    pub symbol: &'static str,
    /// The statistic in words, as the sensitivity study scales it (`"GPS position σ"`).
    pub title: &'static str,
    /// The statistic in words, as a difference between filter and truth names it
    /// (`"bias prior variance"`).
    pub words: &'static str,
    /// Its place in the report's parameter table.
    pub param_row: ParamRow,
    /// The truth's value in a configuration (`None`: not set).
    pub truth: fn(&Config) -> Option<f64>,
    /// The `[filter]` key's slot.
    pub filter: fn(&mut FilterConfig) -> &mut Option<f64>,
    /// Its slot in a set of noise statistics (`None`: the statistics hold none, a bias model's
    /// parameter of another model, or a statistic the state model does not use).
    pub stats: fn(&mut NoiseStats) -> Option<&mut f64>,
    /// Sets it in a set of noise statistics (a bias model's parameter makes the bias its model).
    pub set_stats: fn(&mut NoiseStats, f64),
}

impl PartialEq for Statistic {
    fn eq(&self, other: &Self) -> bool {
        self.filter_path == other.filter_path
    }
}

impl Eq for Statistic {}

impl std::hash::Hash for Statistic {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.filter_path.hash(state);
    }
}

/// The part of a dotted path after its section.
const fn after_section(path: &'static str) -> &'static str {
    let bytes = path.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'.' {
            let (_, rest) = path.split_at(i + 1);
            return rest;
        }
        i += 1;
    }
    path
}

impl Statistic {
    /// The `[filter]` key (`"bias_var_m2_s4"`).
    pub const fn key(&self) -> &'static str {
        after_section(self.filter_path)
    }

    /// The truth's section (`"accelerometer"`).
    pub fn truth_section(&self) -> &'static str {
        let key = after_section(self.truth_path);
        &self.truth_path[..self.truth_path.len() - key.len() - 1]
    }

    /// The truth's key within its section (`"bias_var_m2_s4"`).
    pub const fn truth_key(&self) -> &'static str {
        after_section(self.truth_path)
    }

    /// Whether the likelihood of the GPS innovations can estimate it: a variance, σ or K of the
    /// process or measurement noise (the prior's statistics and a correlation time are not
    /// searched).
    pub const fn searchable(&self) -> bool {
        !matches!(self.scales, Scales::Prior) && !matches!(self.kind, Kind::CorrelationTime)
    }

    /// Whether the filter of `config` assumes it: every statistic but the parameters of a bias
    /// model other than the filter's.
    pub fn assumed_by(&self, config: &Config) -> bool {
        self.bias_model
            .is_none_or(|kind| kind == config.filter_bias_model_kind())
    }

    /// The value in `stats` (`None`: they hold none).
    pub fn stats_value(&self, stats: &NoiseStats) -> Option<f64> {
        let mut s = *stats;
        (self.stats)(&mut s).map(|x| *x)
    }

    /// The statistic called `key` in `[filter]`.
    pub fn from_key(key: &str) -> Option<&'static Statistic> {
        STATISTICS.iter().find(|s| s.key() == key)
    }
}

impl Config {
    /// The value the filter assumes for `statistic`: its `[filter]` key, or the truth's where
    /// that is left out (`None` when neither is set, a bias model's parameter).
    pub fn filter_value(&self, statistic: &Statistic) -> Option<f64> {
        let mut f = self.filter.clone();
        (*(statistic.filter)(&mut f)).or((statistic.truth)(self))
    }

    /// The `[filter]` key of `statistic` as set (`None`: left out).
    pub fn filter_key(&self, statistic: &Statistic) -> Option<f64> {
        let mut f = self.filter.clone();
        *(statistic.filter)(&mut f)
    }

    /// The truth's value of `statistic` (`None`: not set, a bias model's parameter).
    pub fn truth_value(&self, statistic: &Statistic) -> Option<f64> {
        (statistic.truth)(self)
    }

    /// True when the filter assumes exactly the truth's statistics and bias model.
    pub fn filter_matches_truth(&self) -> bool {
        STATISTICS
            .iter()
            .filter(|s| s.bias_model.is_none())
            .all(|s| self.filter_value(s) == self.truth_value(s))
            && self.filter_bias_matches_truth()
    }

    /// The truth's noise statistics (of a valid configuration).
    pub fn truth_stats(&self) -> NoiseStats {
        let a = &self.accelerometer;
        let bias = bias_model(
            a.bias_model,
            a.bias_random_walk_m_s2_per_sqrt_s,
            a.bias_correlation_time_s,
        );
        stats_from(bias, |s| self.truth_value(s))
    }

    /// The statistics the filter assumes: each `[filter]` key, or the truth's value where it is
    /// left out (of a configuration whose filter keys are valid).
    pub fn filter_stats(&self) -> NoiseStats {
        let bias = bias_model(
            self.filter_bias_model_kind(),
            self.filter_bias_random_walk_m_s2_per_sqrt_s(),
            self.filter_bias_correlation_time_s(),
        );
        stats_from(bias, |s| self.filter_value(s))
    }
}

/// Noise statistics with the bias model `bias` and every other statistic's `value`.
fn stats_from(bias: BiasModel, value: impl Fn(&Statistic) -> Option<f64>) -> NoiseStats {
    let mut stats = NoiseStats {
        accel_noise_var_m2_s4: 0.0,
        bias_var_m2_s4: 0.0,
        gps_position_sigma_m: 0.0,
        gps_velocity_sigma_m_s: 0.0,
        initial_position_sigma_m: 0.0,
        initial_velocity_sigma_m_s: 0.0,
        bias_model: bias,
    };
    for s in STATISTICS.iter().filter(|s| s.bias_model.is_none()) {
        (s.set_stats)(&mut stats, value(s).expect("a truth's value is always set"));
    }
    stats
}

/// The bias model of `kind` with its parameter (validated: the one `kind` uses is set).
fn bias_model(kind: BiasModelKind, k: Option<f64>, tau_b: Option<f64>) -> BiasModel {
    match kind {
        BiasModelKind::Constant => BiasModel::Constant,
        BiasModelKind::RandomWalk => BiasModel::RandomWalk {
            k_m_s2_per_sqrt_s: k.expect("validated"),
        },
        BiasModelKind::GaussMarkov => BiasModel::GaussMarkov {
            correlation_time_s: tau_b.expect("validated"),
        },
    }
}

/// The filter's statistics under their historical names (thin wrappers of
/// [`Config::filter_value`]).
impl Config {
    /// The filter's assumed accelerometer noise variance, (m/s²)².
    pub fn filter_accel_noise_var_m2_s4(&self) -> f64 {
        self.filter_value(&Statistic::ACCEL_NOISE_VAR)
            .expect("the truth's value")
    }

    /// The filter's assumed bias prior variance, (m/s²)².
    pub fn filter_bias_var_m2_s4(&self) -> f64 {
        self.filter_value(&Statistic::BIAS_VAR)
            .expect("the truth's value")
    }

    /// The filter's assumed GPS position noise σ, m.
    pub fn filter_gps_position_sigma_m(&self) -> f64 {
        self.filter_value(&Statistic::GPS_POSITION_SIGMA)
            .expect("the truth's value")
    }

    /// The filter's assumed GPS velocity noise σ, m/s.
    pub fn filter_gps_velocity_sigma_m_s(&self) -> f64 {
        self.filter_value(&Statistic::GPS_VELOCITY_SIGMA)
            .expect("the truth's value")
    }

    /// The filter's assumed initial position σ, m.
    pub fn filter_initial_position_sigma_m(&self) -> f64 {
        self.filter_value(&Statistic::INITIAL_POSITION_SIGMA)
            .expect("the truth's value")
    }

    /// The filter's assumed initial velocity σ, m/s.
    pub fn filter_initial_velocity_sigma_m_s(&self) -> f64 {
        self.filter_value(&Statistic::INITIAL_VELOCITY_SIGMA)
            .expect("the truth's value")
    }

    /// The filter's assumed K of a random-walk bias: `filter.bias_random_walk_m_s2_per_sqrt_s`, or
    /// the truth's (`None` when neither is set).
    pub fn filter_bias_random_walk_m_s2_per_sqrt_s(&self) -> Option<f64> {
        self.filter_value(&Statistic::BIAS_RANDOM_WALK)
    }

    /// The filter's assumed τ_b of a Gauss–Markov bias: `filter.bias_correlation_time_s`, or the
    /// truth's (`None` when neither is set).
    pub fn filter_bias_correlation_time_s(&self) -> Option<f64> {
        self.filter_value(&Statistic::BIAS_CORRELATION_TIME)
    }
}
