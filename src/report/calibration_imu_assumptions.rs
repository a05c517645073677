//! The assumptions' table of a three-axis calibration's page: every field of `summary.json`'s
//! `assumptions` with its unit and whether it is the default.

use serde::Serialize;

use crate::calibrate::imu::{CONSUMER, Settings};
use crate::format::{short, sig};

/// An assumption: its `summary.json` key, its value with unit, where it came from.
#[derive(Clone, Debug, Serialize)]
pub struct AssumptionRow {
    /// The key in `summary.json`'s `assumptions`.
    pub key: &'static str,
    /// What it is.
    pub meaning: &'static str,
    /// Its value with its unit.
    pub value: String,
    /// "default" when it equals the consumer default, else "--config".
    pub source: &'static str,
}

/// A row per field of `a` (`$field: "meaning" => formatter`), "default" where the field equals
/// the consumer default's.
macro_rules! assumption_rows {
    ($a:ident, $d:ident, $e:ident; $($field:ident: $meaning:literal => $format:expr),* $(,)?) => {
        vec![$(AssumptionRow {
            key: stringify!($field),
            meaning: $meaning,
            value: ($format)($a.$field),
            source: if $e.contains(&stringify!($field)) {
                "estimated"
            } else if $a.$field == $d.$field {
                "default"
            } else {
                "--config"
            },
        }),*]
    };
}

/// Every assumption of `a` with its unit, marked "estimated" for the fields `estimated` names
/// (`--estimate-noise`), "default" where it equals the consumer default ([`CONSUMER`]) and
/// "--config" elsewhere.
pub fn rows(a: &Settings, estimated: &[&str]) -> Vec<AssumptionRow> {
    // Exhaustive: a new field of `Settings` does not compile until it has its row below.
    let Settings {
        axes: _,
        gyro_arw_rad_per_sqrt_s: _,
        accel_vrw_m_s_per_sqrt_s: _,
        gyro_bias_sigma_rad_s: _,
        gyro_bias_random_walk_rad_s_per_sqrt_s: _,
        gyro_bias_correlation_time_s: _,
        accel_bias_sigma_m_s2: _,
        accel_bias_random_walk_m_s2_per_sqrt_s: _,
        accel_bias_correlation_time_s: _,
        gnss_position_sigma_m: _,
        gnss_velocity_sigma_m_s: _,
        gnss_lever_arm_m: _,
        vertical_velocity_sigma_m_s: _,
        heading_speed_m_s: _,
        alignment_window_s: _,
        heading_offset_sigma_deg: _,
        false_alarm_rate: _,
        gnss_time_offset_s: _,
        error_states: _,
        innovation_gate: _,
        gyro_scale_factor_sigma_ppm: _,
        accel_scale_factor_sigma_ppm: _,
    } = *a;
    let d = CONSUMER;
    let unit = |unit: &'static str| move |x: f64| format!("{} {unit}", value(x));
    let tau = |t: Option<f64>| match t {
        Some(t) => format!("{} s (Gauss–Markov)", value(t)),
        None => "none (a random walk)".to_string(),
    };
    let metres = |v: [f64; 3]| format!("[{}, {}, {}] m", value(v[0]), value(v[1]), value(v[2]));
    let axes = |x: crate::config::ins::Axes| {
        serde_json::to_value(x)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    };
    assumption_rows!(a, d, estimated;
        axes: "the IMU log's body axes" => axes,
        gyro_arw_rad_per_sqrt_s: "gyro angle random walk" => unit("rad/√s"),
        accel_vrw_m_s_per_sqrt_s: "accelerometer velocity random walk" => unit("m/s/√s"),
        gyro_bias_sigma_rad_s: "gyro biases' prior σ" => unit("rad/s"),
        gyro_bias_random_walk_rad_s_per_sqrt_s: "their random walk" => unit("rad/s/√s"),
        gyro_bias_correlation_time_s: "their correlation time" => tau,
        accel_bias_sigma_m_s2: "accelerometer biases' prior σ" => unit("m/s²"),
        accel_bias_random_walk_m_s2_per_sqrt_s: "their random walk" => unit("m/s²/√s"),
        accel_bias_correlation_time_s: "their correlation time" => tau,
        gnss_position_sigma_m: "a fix's position σ north, east, down where the log gives none" => metres,
        gnss_velocity_sigma_m_s: "a fix's velocity σ per component where the log gives none" => unit("m/s"),
        gnss_lever_arm_m: "the antenna from the IMU in body axes" => metres,
        gnss_time_offset_s: "the receiver's time offset (a fix stamped t is at t + offset)" => unit("s"),
        vertical_velocity_sigma_m_s: "σ of the vertical velocity 0 assumed at the start when the log has none" => unit("m/s"),
        heading_speed_m_s: "the lowest speed whose course gives the heading" => unit("m/s"),
        alignment_window_s: "the alignment's window" => unit("s"),
        heading_offset_sigma_deg: "σ of the IMU's heading about the course" => unit("°"),
        false_alarm_rate: "each test's false-alarm rate α" => value,
        error_states: "the filter's error states (21: the scale factors estimated too)" => |n: usize| n.to_string(),
        innovation_gate: "a χ² gate at α on each fix's innovation (a rejected fix is left out)" => |on: bool| if on { "on" } else { "off" }.to_string(),
        gyro_scale_factor_sigma_ppm: "gyro scale factors' prior σ (with 21 states)" => unit("ppm"),
        accel_scale_factor_sigma_ppm: "accelerometer scale factors' prior σ (with 21 states)" => unit("ppm"),
    )
}

/// `x` with up to 4 significant digits and no trailing zeros, also in powers of ten:
/// 5·10⁻⁵ → "5 × 10⁻⁵".
fn value(x: f64) -> String {
    let s = short(x);
    match s.split_once(" × ") {
        Some((m, e)) if m.contains('.') => {
            format!("{} × {e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => {
            if s.contains('×') {
                sig(x, 4)
            } else {
                s
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{rows, value};
    use crate::calibrate::imu::CONSUMER;

    #[test]
    fn values_drop_trailing_zeros_also_in_powers_of_ten() {
        assert_eq!(value(5e-5), "5 × 10⁻⁵");
        assert_eq!(value(1.25e-7), "1.25 × 10⁻⁷");
        assert_eq!(value(0.05), "0.05");
        assert_eq!(value(2.0), "2");
    }

    #[test]
    fn a_changed_assumption_is_marked_as_the_configuration_s() {
        assert!(rows(&CONSUMER, &[]).iter().all(|r| r.source == "default"));
        let mut s = CONSUMER;
        s.gnss_position_sigma_m = [1.0, 1.0, 2.0];
        let changed: Vec<_> = rows(&s, &[])
            .into_iter()
            .filter(|r| r.source == "--config")
            .map(|r| (r.key, r.value))
            .collect();
        assert_eq!(
            changed,
            vec![("gnss_position_sigma_m", "[1, 1, 2] m".to_string())]
        );
    }
}
