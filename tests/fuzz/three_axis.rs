//! The three-axis configuration surface (`ensemble` and `simulate` on mutated `config --model
//! ins` and `--model car` files, with and without `--model`) and the meridian surface (the
//! shipped recording's fixes with every longitude written another way, which must calibrate to
//! the unmutated numbers).

use super::{Rng, SIZE_TOKENS, mutate_bytes, set_key, value};
use std::path::Path;

/// The keys of the three-axis file (`config --model car`), and whether each sizes the run.
pub const INS_KEYS: &[(&str, &str, bool)] = &[
    ("drive", "duration_s", true),
    ("drive", "start_lat_deg", false),
    ("drive", "start_lon_deg", false),
    ("drive", "start_height_m", false),
    ("imu", "imu_rate_hz", true),
    ("imu", "gyro_arw_rad_per_sqrt_s", false),
    ("imu", "accel_vrw_m_s_per_sqrt_s", false),
    ("imu", "gyro_bias_model", false),
    ("imu", "gyro_bias_sigma_rad_s", false),
    ("imu", "gyro_bias_correlation_time_s", false),
    ("imu", "gyro_bias_random_walk_rad_s_per_sqrt_s", false),
    ("imu", "accel_bias_model", false),
    ("imu", "accel_bias_sigma_m_s2", false),
    ("imu", "accel_bias_correlation_time_s", false),
    ("imu", "accel_bias_random_walk_m_s2_per_sqrt_s", false),
    ("imu", "gyro_scale_factor_sigma_ppm", false),
    ("imu", "accel_scale_factor_sigma_ppm", false),
    ("gnss", "gnss_rate_hz", true),
    ("gnss", "gnss_lever_arm_m", false),
    ("gnss", "gnss_position_sigma_m", false),
    ("gnss", "gnss_velocity_sigma_m_s", false),
    ("initial", "position_sigma_m", false),
    ("initial", "velocity_sigma_m_s", false),
    ("initial", "tilt_sigma_deg", false),
    ("initial", "yaw_sigma_deg", false),
    ("ensemble", "realizations", true),
    ("ensemble", "seed", false),
    ("checks", "false_alarm_rate", false),
    ("checks", "residual_max_lag", true),
    ("vehicle", "mounting_rpy_deg", false),
    ("vehicle", "mounting_sigma_deg", false),
    ("vehicle", "nhc_sigma_m_s", false),
    ("vehicle", "nhc_rate_hz", true),
    ("vehicle", "nhc_min_speed_m_s", false),
];

/// Values of the three-axis file's keys that have been wrong before: longitudes at and past
/// the antimeridian, poles, bias models, vectors of other lengths, right-angle mountings.
const INS_TOKENS: &[&str] = &[
    "-180.0",
    "180.0",
    "360.0",
    "-180.0001",
    "89.999",
    "-90.0",
    "\"constant\"",
    "\"random_walk\"",
    "\"gauss_markov\"",
    "\"walk\"",
    "[0.0, 0.0]",
    "[1e308, 0.0, 0.0]",
    "[90.0, 0.0, 0.0]",
    "[0.0, 180.0, 0.0]",
    "[-90.0, 90.0, 180.0]",
    "[nan, 0.0, 0.0]",
];

/// `config --model MODEL`'s file without its comments, sized to a few seconds: 20 s at 50 Hz,
/// 8 realizations.
pub fn tiny_three_axis(dir: &Path, model: &str) -> String {
    let out = crate::common::run_in(dir, &["config", "--model", model], Some(1));
    assert!(out.status.success(), "config --model {model}: {out:?}");
    let text: String = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| format!("{l}\n"))
        .collect();
    let text = set_key(&text, "drive", "duration_s", "20.0");
    let text = set_key(&text, "imu", "imu_rate_hz", "50.0");
    set_key(&text, "ensemble", "realizations", "8")
}

/// One three-axis configuration case: the ins or car file with keys set to hostile values
/// (or its model line changed, or bytes mutated), through `ensemble` or `simulate --logs`,
/// with `--model` left out, matching the file or not.
pub fn case_three_axis_config(
    rng: &mut Rng,
    files: &[String; 2],
    dir: &Path,
) -> (Vec<String>, Vec<&'static str>) {
    let mut text = files[rng.below(2)].clone();
    let mutations = if rng.chance(60) { 1 } else { 2 + rng.below(2) };
    let mut bytes = None;
    for _ in 0..mutations {
        match rng.below(6) {
            0..=2 => {
                let &(table, key, sizes) = rng.pick(INS_KEYS);
                let v = if sizes {
                    rng.pick(SIZE_TOKENS).to_string()
                } else if rng.chance(40) {
                    rng.pick(INS_TOKENS).to_string()
                } else {
                    value(rng)
                };
                text = set_key(&text, table, key, &v);
            }
            3 => {
                let model = rng.pick(&["\"ins\"", "\"car\"", "\"accelerometer\"", "1", "\"\""]);
                text = text.replacen("model = \"ins\"", &format!("model = {model}"), 1);
                text = text.replacen("model = \"car\"", &format!("model = {model}"), 1);
            }
            4 => text = text.replacen("model = ", "# model = ", 1),
            _ => {
                let mut b = text.clone().into_bytes();
                mutate_bytes(rng, &mut b);
                bytes = Some(b);
            }
        }
    }
    std::fs::write(dir.join("c3.toml"), bytes.unwrap_or(text.into_bytes())).unwrap();
    let with = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let mut args = if rng.chance(60) {
        with(&["ensemble", "-q", "--config", "c3.toml", "--json", "e3.json"])
    } else {
        with(&["simulate", "-q", "--config", "c3.toml", "--logs", "s3"])
    };
    if rng.chance(40) {
        let model = rng.pick(&["ins", "car", "accelerometer"]);
        args.extend(["--model", model].map(String::from));
    }
    (
        args,
        vec!["e3.json", "s3/imu.csv", "s3/gnss.csv", "s3/truth.csv"],
    )
}

/// The GNSS log `gnss` with every longitude written another way: past 180° (+360), across
/// the antimeridian (the drive's first fix moved onto 180° and the rest wrapped), or across it
/// in [0, 360). Every variant is the same drive.
pub fn same_meridians(rng: &mut Rng, gnss: &[u8]) -> Vec<u8> {
    let text = std::str::from_utf8(gnss).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let j = header.split(',').position(|c| c == "lon_deg").unwrap();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let first: f64 = rows[0][j].parse().unwrap();
    let how = rng.below(3);
    let mut out = format!("{header}\n");
    for mut row in rows {
        let lon: f64 = row[j].parse().unwrap();
        let moved = match how {
            0 => lon + 360.0,
            1 => {
                // 1e-6° east of the first fix's meridian the drive sits on 180°.
                let y = lon - first + 180.0 - 1e-6;
                if y > 180.0 { y - 360.0 } else { y }
            }
            _ => {
                // The same, then written in [0, 360) where it fell west of 0.
                let y = lon - first + 180.0 - 1e-6;
                let y = if y > 180.0 { y - 360.0 } else { y };
                if y < 0.0 { y + 360.0 } else { y }
            }
        };
        row[j] = format!("{moved:.10}");
        out += &row.join(",");
        out.push('\n');
    }
    out.into_bytes()
}

/// The largest relative difference of the gyro and accelerometer biases in two summaries.
pub fn bias_difference(a: &serde_json::Value, b: &serde_json::Value) -> f64 {
    let mut worst = 0.0_f64;
    for key in ["gyro_bias_rad_s", "accel_bias_m_s2"] {
        let values = |s: &serde_json::Value| -> Vec<f64> {
            s[key]["value"]
                .as_array()
                .map(|v| v.iter().filter_map(|x| x.as_f64()).collect())
                .unwrap_or_default()
        };
        let (x, y) = (values(a), values(b));
        if x.len() != 3 || y.len() != 3 {
            return f64::INFINITY;
        }
        let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (p, q) in x.iter().zip(&y) {
            worst = worst.max((p - q).abs() / scale);
        }
    }
    worst
}
