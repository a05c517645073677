//! `calibrate --imu --config FILE`: the assumptions a file sets, each key where it is set and
//! [`CONSUMER`] where the file is silent.
//!
//! The keys are the three-axis study's (`accelcal config --model ins`), so that the
//! `noise.toml` that `allan --imu` writes can be given as it is, and the study's statistics
//! copied over: `[imu]` the sensor's statistics, `[filter]` overriding them (and its
//! `error_states`), `[gnss]` the receiver's σ's and lever arm, `[checks]` the false-alarm rate;
//! and two of the calibration's own: `axes` in `[imu]`, and `[alignment]`. The rates
//! (`imu_rate_hz`, `gnss_rate_hz`) are the logs' and may not be set here, and the study's other
//! sections (`[drive]`, `[initial]`, `[ensemble]`, `checks.residual_max_lag`) describe a
//! simulation, not a recording: a file with them is refused (unknown key), so the study's whole
//! file is not taken as it is.

use serde::Deserialize;

use super::{CONSUMER, Settings};
use crate::config::BiasModelKind;
use crate::config::ConfigText;
use crate::config::ins::Axes;
use crate::error::{ConfigError, Position};

/// The statistics of one file section (`[imu]` or `[filter]`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Statistics {
    axes: Option<Axes>,
    gyro_arw_rad_per_sqrt_s: Option<f64>,
    accel_vrw_m_s_per_sqrt_s: Option<f64>,
    gyro_bias_model: Option<BiasModelKind>,
    gyro_bias_sigma_rad_s: Option<f64>,
    gyro_bias_correlation_time_s: Option<f64>,
    gyro_bias_random_walk_rad_s_per_sqrt_s: Option<f64>,
    accel_bias_model: Option<BiasModelKind>,
    accel_bias_sigma_m_s2: Option<f64>,
    accel_bias_correlation_time_s: Option<f64>,
    accel_bias_random_walk_m_s2_per_sqrt_s: Option<f64>,
    gnss_lever_arm_m: Option<[f64; 3]>,
    gnss_position_sigma_m: Option<[f64; 3]>,
    gnss_velocity_sigma_m_s: Option<f64>,
    gnss_time_offset_s: Option<f64>,
    gyro_scale_factor_sigma_ppm: Option<f64>,
    accel_scale_factor_sigma_ppm: Option<f64>,
    error_states: Option<u32>,
    innovation_gate: Option<bool>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Checks {
    false_alarm_rate: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Alignment {
    heading_speed_m_s: Option<f64>,
    window_s: Option<f64>,
    heading_offset_sigma_deg: Option<f64>,
    vertical_velocity_sigma_m_s: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    model: Option<String>,
    #[serde(default)]
    imu: Statistics,
    #[serde(default)]
    gnss: Statistics,
    #[serde(default)]
    filter: Statistics,
    #[serde(default)]
    checks: Checks,
    #[serde(default)]
    alignment: Alignment,
}

/// The largest GNSS time offset accepted, s.
pub const MAX_TIME_OFFSET_S: f64 = 0.5;

/// The keys' accepted ranges: (field, value, lowest, highest, words).
type Check = (&'static str, f64, f64, f64, &'static str);

/// The first value out of its range.
fn first_invalid(checks: &[Check]) -> Option<ConfigError> {
    checks.iter().find_map(|&(field, v, lo, hi, words)| {
        (!(v.is_finite() && (lo..=hi).contains(&v))).then(|| ConfigError::invalid(field, v, words))
    })
}

/// The bias process of a sensor from its model, σ, τ and K as `s` has them.
fn bias(
    model: Option<BiasModelKind>,
    sigma: Option<f64>,
    tau: Option<f64>,
    k: Option<f64>,
    default: (f64, f64, Option<f64>),
) -> (f64, f64, Option<f64>) {
    let sigma = sigma.unwrap_or(default.0);
    match model {
        Some(BiasModelKind::Constant) => (sigma, 0.0, None),
        Some(BiasModelKind::RandomWalk) => (sigma, k.unwrap_or(default.1), None),
        Some(BiasModelKind::GaussMarkov) => (sigma, 0.0, Some(tau.unwrap_or(3600.0))),
        None => (sigma, k.unwrap_or(default.1), tau.or(default.2)),
    }
}

/// The file `text` parsed, of the three-axis model.
fn parse(text: &ConfigText) -> Result<File, ConfigError> {
    let t = &text.text;
    let file: File = toml::from_str(t).map_err(|e| {
        let span = e.span();
        text.locate(ConfigError::Parse {
            file: None,
            position: span.clone().map(|s| Box::new(Position::of(t, s))),
            field: span.and_then(|s| crate::config::source::field_at(t, s.start)),
            message: e.message().trim_end().to_string(),
        })
    })?;
    if let Some(m) = file.model.as_deref().filter(|m| *m != "ins") {
        let e = ConfigError::invalid("model", m, "\"ins\": the three-axis keys");
        return Err(text.locate(e));
    }
    Ok(file)
}

/// The settings of the configuration `text`: [`CONSUMER`] with every key the file sets.
///
/// # Errors
/// [`ConfigError::Parse`] for a file that is not TOML or has an unknown key or a value of the
/// wrong type; [`ConfigError::Invalid`] naming the key, its line and its accepted range.
pub fn settings_of(text: &ConfigText) -> Result<Settings, ConfigError> {
    let t = &text.text;
    let file = parse(text)?;
    let pick = |f: fn(&Statistics) -> Option<f64>| f(&file.filter).or(f(&file.imu));
    let c = CONSUMER;
    let (g_sigma, g_k, g_tau) = bias(
        file.filter.gyro_bias_model.or(file.imu.gyro_bias_model),
        pick(|s| s.gyro_bias_sigma_rad_s),
        pick(|s| s.gyro_bias_correlation_time_s),
        pick(|s| s.gyro_bias_random_walk_rad_s_per_sqrt_s),
        (
            c.gyro_bias_sigma_rad_s,
            c.gyro_bias_random_walk_rad_s_per_sqrt_s,
            None,
        ),
    );
    let (a_sigma, a_k, a_tau) = bias(
        file.filter.accel_bias_model.or(file.imu.accel_bias_model),
        pick(|s| s.accel_bias_sigma_m_s2),
        pick(|s| s.accel_bias_correlation_time_s),
        pick(|s| s.accel_bias_random_walk_m_s2_per_sqrt_s),
        (
            c.accel_bias_sigma_m_s2,
            c.accel_bias_random_walk_m_s2_per_sqrt_s,
            None,
        ),
    );
    let gnss = |f: fn(&Statistics) -> Option<[f64; 3]>| f(&file.filter).or(f(&file.gnss));
    let al = &file.alignment;
    let s = Settings {
        axes: file.imu.axes.unwrap_or(c.axes),
        gyro_arw_rad_per_sqrt_s: pick(|s| s.gyro_arw_rad_per_sqrt_s)
            .unwrap_or(c.gyro_arw_rad_per_sqrt_s),
        accel_vrw_m_s_per_sqrt_s: pick(|s| s.accel_vrw_m_s_per_sqrt_s)
            .unwrap_or(c.accel_vrw_m_s_per_sqrt_s),
        gyro_bias_sigma_rad_s: g_sigma,
        gyro_bias_random_walk_rad_s_per_sqrt_s: g_k,
        gyro_bias_correlation_time_s: g_tau,
        accel_bias_sigma_m_s2: a_sigma,
        accel_bias_random_walk_m_s2_per_sqrt_s: a_k,
        accel_bias_correlation_time_s: a_tau,
        gnss_position_sigma_m: gnss(|s| s.gnss_position_sigma_m).unwrap_or(c.gnss_position_sigma_m),
        gnss_velocity_sigma_m_s: file
            .filter
            .gnss_velocity_sigma_m_s
            .or(file.gnss.gnss_velocity_sigma_m_s)
            .unwrap_or(c.gnss_velocity_sigma_m_s),
        gnss_lever_arm_m: gnss(|s| s.gnss_lever_arm_m).unwrap_or(c.gnss_lever_arm_m),
        gnss_time_offset_s: file
            .filter
            .gnss_time_offset_s
            .or(file.gnss.gnss_time_offset_s)
            .unwrap_or(c.gnss_time_offset_s),
        vertical_velocity_sigma_m_s: al
            .vertical_velocity_sigma_m_s
            .unwrap_or(c.vertical_velocity_sigma_m_s),
        heading_speed_m_s: al.heading_speed_m_s.unwrap_or(c.heading_speed_m_s),
        alignment_window_s: al.window_s.unwrap_or(c.alignment_window_s),
        heading_offset_sigma_deg: al
            .heading_offset_sigma_deg
            .unwrap_or(c.heading_offset_sigma_deg),
        false_alarm_rate: file.checks.false_alarm_rate.unwrap_or(c.false_alarm_rate),
        error_states: file
            .filter
            .error_states
            .map_or(c.error_states, |n| n as usize),
        innovation_gate: file.filter.innovation_gate.unwrap_or(c.innovation_gate),
        gyro_scale_factor_sigma_ppm: pick(|s| s.gyro_scale_factor_sigma_ppm)
            .unwrap_or(c.gyro_scale_factor_sigma_ppm),
        accel_scale_factor_sigma_ppm: pick(|s| s.accel_scale_factor_sigma_ppm)
            .unwrap_or(c.accel_scale_factor_sigma_ppm),
    };
    gate_in_filter(&file).map_err(|e| text.locate(e))?;
    validate(&s).map_err(|e| text.locate(in_section(e, t)))?;
    Ok(s)
}

/// The gate is the filter's: `innovation_gate` in `[imu]` or `[gnss]` is refused.
fn gate_in_filter(file: &File) -> Result<(), ConfigError> {
    for (field, stats) in [
        ("imu.innovation_gate", &file.imu),
        ("gnss.innovation_gate", &file.gnss),
    ] {
        if let Some(v) = stats.innovation_gate {
            return Err(ConfigError::invalid(
                field,
                v,
                "set in [filter] (the filter's gate)",
            ));
        }
    }
    Ok(())
}

/// `e` naming its key by the section that sets it (`filter.…` before `imu.…`, as the value is
/// taken), so that its line is found.
fn in_section(e: ConfigError, text: &str) -> ConfigError {
    let ConfigError::Invalid {
        field,
        value,
        expected,
        file,
        position,
    } = e
    else {
        return e;
    };
    let path = ["filter", "imu", "gnss", "alignment", "checks"]
        .iter()
        .map(|section| format!("{section}.{field}"))
        .find(|p| crate::config::source::span_of(text, p).is_some());
    // A message's field is static: the path of an error that ends the run is leaked once.
    let field = path.map_or(field, |p| &*Box::leak(p.into_boxed_str()));
    ConfigError::Invalid {
        field,
        value,
        expected,
        file,
        position,
    }
}

/// Every value within its accepted range.
///
/// # Errors
/// [`ConfigError::Invalid`] naming the first key out of range.
pub fn validate(s: &Settings) -> Result<(), ConfigError> {
    let [pn, pe, pd] = s.gnss_position_sigma_m;
    let [lx, ly, lz] = s.gnss_lever_arm_m;
    // A scale factor's prior σ matters with 21 states only (0, the study's ideal scale, is
    // accepted with 15).
    let (scale_lo, scale_words) = if s.error_states > 15 {
        (1.0, "in [1, 10⁵] ppm with error_states = 21")
    } else {
        (0.0, "in [0, 10⁵] ppm")
    };
    // One row per key: the key, its value, its range and the range in words.
    #[rustfmt::skip]
    let mut checks: Vec<Check> = vec![
        ("gyro_arw_rad_per_sqrt_s", s.gyro_arw_rad_per_sqrt_s, 1e-9, 1.0, "in [1e-9, 1] rad/√s"),
        ("accel_vrw_m_s_per_sqrt_s", s.accel_vrw_m_s_per_sqrt_s, 1e-9, 10.0, "in [1e-9, 10] m/s/√s"),
        ("gyro_bias_sigma_rad_s", s.gyro_bias_sigma_rad_s, 1e-9, 10.0, "in [1e-9, 10] rad/s"),
        ("gyro_bias_random_walk_rad_s_per_sqrt_s", s.gyro_bias_random_walk_rad_s_per_sqrt_s, 0.0, 1.0, "in [0, 1] rad/s/√s"),
        ("accel_bias_sigma_m_s2", s.accel_bias_sigma_m_s2, 1e-9, 100.0, "in [1e-9, 100] m/s²"),
        ("accel_bias_random_walk_m_s2_per_sqrt_s", s.accel_bias_random_walk_m_s2_per_sqrt_s, 0.0, 10.0, "in [0, 10] m/s²/√s"),
        ("gnss_position_sigma_m", pn.min(pe).min(pd), 1e-4, 1e4, "each in [1e-4, 1e4] m"),
        ("gnss_position_sigma_m", pn.max(pe).max(pd), 1e-4, 1e4, "each in [1e-4, 1e4] m"),
        ("gnss_velocity_sigma_m_s", s.gnss_velocity_sigma_m_s, 1e-5, 100.0, "in [1e-5, 100] m/s"),
        ("gnss_lever_arm_m", lx.abs().max(ly.abs()).max(lz.abs()), 0.0, 100.0, "each within ±100 m"),
        ("vertical_velocity_sigma_m_s", s.vertical_velocity_sigma_m_s, 1e-3, 100.0, "in [0.001, 100] m/s"),
        ("heading_speed_m_s", s.heading_speed_m_s, 0.5, 100.0, "in [0.5, 100] m/s"),
        ("window_s", s.alignment_window_s, 0.05, 60.0, "in [0.05, 60] s"),
        ("heading_offset_sigma_deg", s.heading_offset_sigma_deg, 0.01, 30.0, "in [0.01, 30]° (a larger offset breaks the filter's linearization)"),
        ("false_alarm_rate", s.false_alarm_rate, 1e-6, 0.5, "in [1e-6, 0.5]"),
        ("gnss_time_offset_s", s.gnss_time_offset_s, -MAX_TIME_OFFSET_S, MAX_TIME_OFFSET_S, "in [−0.5, 0.5] s"),
        ("gyro_scale_factor_sigma_ppm", s.gyro_scale_factor_sigma_ppm, scale_lo, 1e5, scale_words),
        ("accel_scale_factor_sigma_ppm", s.accel_scale_factor_sigma_ppm, scale_lo, 1e5, scale_words),
    ];
    // A car's 18 (the mounting angles) needs the vehicle's constraints, not in calibrate yet.
    if !matches!(s.error_states, 15 | 21) {
        return Err(ConfigError::invalid(
            "error_states",
            s.error_states,
            "15, or 21 with the six scale factors",
        ));
    }
    for (field, tau) in [
        (
            "gyro_bias_correlation_time_s",
            s.gyro_bias_correlation_time_s,
        ),
        (
            "accel_bias_correlation_time_s",
            s.accel_bias_correlation_time_s,
        ),
    ] {
        if let Some(t) = tau {
            checks.push((field, t, 1.0, 1e7, "in [1, 10⁷] s"));
        }
    }
    match first_invalid(&checks) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
