//! The rows of [`STATISTICS`]: one per noise statistic, in the configuration's order (a bias
//! model's parameters last, and a new statistic after them, so that the sensitivity study's
//! seeds of the others stay as they are).

use super::{FILTER_FLOOR, Kind, ParamRow, Range, Scales, Statistic};
use crate::config::BiasModelKind;
use crate::state::BiasModel;

/// Largest accepted variance or standard deviation, truth or filter.
const MAX_NOISE: f64 = 1e6;
/// The filter's range of a variance or σ: its covariance stays positive definite.
const FILTER_RANGE: Range = Range::closed(FILTER_FLOOR, MAX_NOISE);

impl Statistic {
    /// Accelerometer white-noise variance W.
    pub const ACCEL_NOISE_VAR: Statistic = Statistic {
        filter_path: "filter.accel_noise_var_m2_s4",
        truth_path: "accelerometer.noise_var_m2_s4",
        unit: "(m/s²)²",
        kind: Kind::Variance,
        scales: Scales::ProcessNoise,
        datasheet_unit: "µg/√Hz (velocity random walk)",
        default: 0.0004,
        default_toml: "0.0004",
        toml_comment: "# Variance W of the white noise w in a_c = a + b + w.\n",
        truth_range: Range::closed(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "W",
        title: "accelerometer noise σ",
        words: "accelerometer noise variance",
        param_row: ParamRow::Own("accelerometer noise variance W"),
        truth: |c| Some(c.accelerometer.noise_var_m2_s4),
        filter: |f| &mut f.accel_noise_var_m2_s4,
        stats: |s| Some(&mut s.accel_noise_var_m2_s4),
        set_stats: |s, x| s.accel_noise_var_m2_s4 = x,
    };

    /// Variance of the bias's prior, σ_b².
    pub const BIAS_VAR: Statistic = Statistic {
        filter_path: "filter.bias_var_m2_s4",
        truth_path: "accelerometer.bias_var_m2_s4",
        unit: "(m/s²)²",
        kind: Kind::Variance,
        scales: Scales::Prior,
        datasheet_unit: "mg (turn-on bias repeatability, 1σ)",
        default: 0.01,
        default_toml: "0.01",
        toml_comment: "# The bias b(0) is drawn once per realization from N(0, bias_var_m2_s4).\n",
        truth_range: Range::closed(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "σ_b²",
        title: "bias prior σ",
        words: "bias prior variance",
        param_row: ParamRow::Own("bias prior variance M_{b}"),
        truth: |c| Some(c.accelerometer.bias_var_m2_s4),
        filter: |f| &mut f.bias_var_m2_s4,
        stats: |s| Some(&mut s.bias_var_m2_s4),
        set_stats: |s, x| s.bias_var_m2_s4 = x,
    };

    /// σ of the GPS position noise η_p.
    pub const GPS_POSITION_SIGMA: Statistic = Statistic {
        filter_path: "filter.gps_position_sigma_m",
        truth_path: "gps.position_sigma_m",
        unit: "m",
        kind: Kind::Sigma,
        scales: Scales::MeasurementNoise,
        datasheet_unit: "m (horizontal accuracy, 1σ)",
        default: 1.0,
        default_toml: "1.0",
        toml_comment: "",
        truth_range: Range::open_below(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "σ_p",
        title: "GPS position σ",
        words: "GPS position σ",
        param_row: ParamRow::Own("GPS position noise σ_{p}"),
        truth: |c| Some(c.gps.position_sigma_m),
        filter: |f| &mut f.gps_position_sigma_m,
        stats: |s| Some(&mut s.gps_position_sigma_m),
        set_stats: |s, x| s.gps_position_sigma_m = x,
    };

    /// σ of the GPS velocity noise η_v.
    pub const GPS_VELOCITY_SIGMA: Statistic = Statistic {
        filter_path: "filter.gps_velocity_sigma_m_s",
        truth_path: "gps.velocity_sigma_m_s",
        unit: "m/s",
        kind: Kind::Sigma,
        scales: Scales::MeasurementNoise,
        datasheet_unit: "m/s (speed accuracy, 1σ)",
        default: 0.04,
        default_toml: "0.04",
        toml_comment: "",
        truth_range: Range::open_below(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "σ_v",
        title: "GPS velocity σ",
        words: "GPS velocity σ",
        param_row: ParamRow::Own("GPS velocity noise σ_{v}"),
        truth: |c| Some(c.gps.velocity_sigma_m_s),
        filter: |f| &mut f.gps_velocity_sigma_m_s,
        stats: |s| Some(&mut s.gps_velocity_sigma_m_s),
        set_stats: |s, x| s.gps_velocity_sigma_m_s = x,
    };

    /// σ of the initial position p(0).
    pub const INITIAL_POSITION_SIGMA: Statistic = Statistic {
        filter_path: "filter.initial_position_sigma_m",
        truth_path: "initial.position_sigma_m",
        unit: "m",
        kind: Kind::Sigma,
        scales: Scales::Prior,
        datasheet_unit: "m",
        default: 10.0,
        default_toml: "10.0",
        toml_comment: "",
        truth_range: Range::closed(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "σ_p0",
        title: "initial position σ",
        words: "initial position σ",
        param_row: ParamRow::WithMean,
        truth: |c| Some(c.initial.position_sigma_m),
        filter: |f| &mut f.initial_position_sigma_m,
        stats: |s| Some(&mut s.initial_position_sigma_m),
        set_stats: |s, x| s.initial_position_sigma_m = x,
    };

    /// σ of the initial velocity v(0).
    pub const INITIAL_VELOCITY_SIGMA: Statistic = Statistic {
        filter_path: "filter.initial_velocity_sigma_m_s",
        truth_path: "initial.velocity_sigma_m_s",
        unit: "m/s",
        kind: Kind::Sigma,
        scales: Scales::Prior,
        datasheet_unit: "m/s",
        default: 1.0,
        default_toml: "1.0",
        toml_comment: "",
        truth_range: Range::closed(0.0, MAX_NOISE),
        filter_range: FILTER_RANGE,
        bias_model: None,
        symbol: "σ_v0",
        title: "initial velocity σ",
        words: "initial velocity σ",
        param_row: ParamRow::WithMean,
        truth: |c| Some(c.initial.velocity_sigma_m_s),
        filter: |f| &mut f.initial_velocity_sigma_m_s,
        stats: |s| Some(&mut s.initial_velocity_sigma_m_s),
        set_stats: |s, x| s.initial_velocity_sigma_m_s = x,
    };

    /// K of a random-walk bias, b(t + Δt) − b(t) ~ N(0, K²·Δt).
    pub const BIAS_RANDOM_WALK: Statistic = Statistic {
        filter_path: "filter.bias_random_walk_m_s2_per_sqrt_s",
        truth_path: "accelerometer.bias_random_walk_m_s2_per_sqrt_s",
        unit: "m/s²/√s",
        kind: Kind::RandomWalk,
        scales: Scales::ProcessNoise,
        datasheet_unit: "µg/√s (rate random walk)",
        default: 0.02,
        default_toml: "0.02",
        toml_comment: "",
        truth_range: Range::closed(0.0, 1e3),
        filter_range: Range::closed(0.0, 1e3),
        bias_model: Some(BiasModelKind::RandomWalk),
        symbol: "K",
        title: "bias random walk K",
        words: "bias random walk K",
        param_row: ParamRow::Hidden,
        truth: |c| c.accelerometer.bias_random_walk_m_s2_per_sqrt_s,
        filter: |f| &mut f.bias_random_walk_m_s2_per_sqrt_s,
        stats: |s| match &mut s.bias_model {
            BiasModel::RandomWalk { k_m_s2_per_sqrt_s } => Some(k_m_s2_per_sqrt_s),
            _ => None,
        },
        set_stats: |s, x| {
            s.bias_model = BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: x,
            }
        },
    };

    /// τ_b of a Gauss–Markov bias, ḃ = −b/τ_b + w_b.
    pub const BIAS_CORRELATION_TIME: Statistic = Statistic {
        filter_path: "filter.bias_correlation_time_s",
        truth_path: "accelerometer.bias_correlation_time_s",
        unit: "s",
        kind: Kind::CorrelationTime,
        scales: Scales::ProcessNoise,
        datasheet_unit: "s (bias instability's correlation time)",
        default: 100.0,
        default_toml: "100.0",
        toml_comment: "",
        truth_range: Range::open_below(0.0, 1e9),
        filter_range: Range::open_below(0.0, 1e9),
        bias_model: Some(BiasModelKind::GaussMarkov),
        symbol: "τ_b",
        title: "bias correlation time τ_b",
        words: "bias correlation time τ_b",
        param_row: ParamRow::Hidden,
        truth: |c| c.accelerometer.bias_correlation_time_s,
        filter: |f| &mut f.bias_correlation_time_s,
        stats: |s| match &mut s.bias_model {
            BiasModel::GaussMarkov { correlation_time_s } => Some(correlation_time_s),
            _ => None,
        },
        set_stats: |s, x| {
            s.bias_model = BiasModel::GaussMarkov {
                correlation_time_s: x,
            }
        },
    };

    /// A statistic that exists only to prove that a row is all a statistic takes in the
    /// configuration, validation, sensitivity study, likelihood and report
    /// (`tests/statistic_registry.rs`, built with `--features throwaway-statistic`). The state
    /// model does not use it.
    #[cfg(feature = "throwaway-statistic")]
    pub const THROWAWAY: Statistic = Statistic {
        filter_path: "filter.throwaway_sigma_m",
        truth_path: "gps.throwaway_sigma_m",
        unit: "m",
        kind: Kind::Sigma,
        scales: Scales::MeasurementNoise,
        datasheet_unit: "m",
        default: 0.5,
        default_toml: "0.5",
        toml_comment: "# A throwaway statistic of the registry's test.\n",
        truth_range: Range::open_below(0.0, 7.0),
        filter_range: Range::closed(FILTER_FLOOR, 7.0),
        bias_model: None,
        symbol: "σ_t",
        title: "throwaway σ",
        words: "throwaway σ",
        param_row: ParamRow::Own("throwaway noise σ_{t}"),
        truth: |c| Some(c.gps.throwaway_sigma_m),
        filter: |f| &mut f.throwaway_sigma_m,
        stats: |_| None,
        set_stats: |_, _| {},
    };
}

/// Every noise statistic, in the configuration's order.
pub const STATISTICS: &[Statistic] = &[
    Statistic::ACCEL_NOISE_VAR,
    Statistic::BIAS_VAR,
    Statistic::GPS_POSITION_SIGMA,
    Statistic::GPS_VELOCITY_SIGMA,
    Statistic::INITIAL_POSITION_SIGMA,
    Statistic::INITIAL_VELOCITY_SIGMA,
    Statistic::BIAS_RANDOM_WALK,
    Statistic::BIAS_CORRELATION_TIME,
    #[cfg(feature = "throwaway-statistic")]
    Statistic::THROWAWAY,
];
