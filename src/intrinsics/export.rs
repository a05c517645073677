//! `intrinsics.json`: the calibration as `calibrate --imu` and `allan --imu` take it, with the
//! convention written in the file. Pure: the text, no IO.

use serde_json::{Value, json};

use super::Intrinsics;
use super::accel::{DERIVED_NAMES, Estimate, MATRIX_ENTRIES};
use super::gyro::EARTH_RATE_RAD_S;
use super::gyro_matrix::MISALIGNMENT_NAMES;

/// The convention, as the file states it.
pub const CONVENTION: &str = "corrected = matrix · (measured − bias), matrix row-major. The \
accelerometers' matrix is lower triangular: the corrected frame's x axis is the sensor's x axis, \
its y axis lies in the plane of the sensor's x and y axes. The gyros' matrix is full: it \
carries their axes into that frame. scale_ppm is each sensing axis's gain |row i of matrix⁻¹| \
− 1; the accelerometers' misalignment_rad is each pair of sensing axes' departure from 90° \
(positive when closer), the gyros' each sensing axis's lean towards another corrected axis. A value the poses do not determine is null, with determined = false.";

/// A number, or null when the poses leave it undetermined.
fn number(value: f64, determined: bool) -> Value {
    if determined && value.is_finite() {
        json!(value)
    } else {
        Value::Null
    }
}

/// One estimate as the file writes it.
fn estimate(name: &str, key: &str, e: &Estimate) -> Value {
    json!({
        key: name,
        "value": number(e.value, e.determined),
        "sigma": number(e.sigma, e.determined),
        "lower": number(e.lower, e.determined),
        "upper": number(e.upper, e.determined),
        "determined": e.determined,
    })
}

/// The accelerometers' part.
fn accel_json(x: &Intrinsics) -> Value {
    let a = &x.accel;
    let sigma = |i: usize| a.covariance[(i, i)].sqrt();
    let zero = || [json!(0.0), json!(0.0), json!(0.0)];
    let mut matrix = [zero(), zero(), zero()];
    let mut matrix_sigma = [zero(), zero(), zero()];
    for (i, &(r, c)) in MATRIX_ENTRIES.iter().enumerate() {
        matrix[r][c] = number(a.params[3 + i], a.determined[3 + i]);
        matrix_sigma[r][c] = number(sigma(3 + i), a.determined[3 + i]);
    }
    let undetermined: Vec<&str> = super::accel::PARAMETER_NAMES
        .iter()
        .zip(a.determined)
        .filter(|(_, d)| !d)
        .map(|(n, _)| *n)
        .collect();
    let threshold = super::accel::goodness_threshold(a, x.settings.alpha);
    json!({
        "bias": {
            "value": (0..3).map(|i| number(a.params[i], a.determined[i])).collect::<Vec<_>>(),
            "sigma": (0..3).map(|i| number(sigma(i), a.determined[i])).collect::<Vec<_>>(),
            "unit": "m/s^2",
        },
        "matrix": { "value": matrix, "sigma": matrix_sigma },
        "scale_ppm": (0..3)
            .map(|i| estimate(DERIVED_NAMES[i], "axis", &a.scale_ppm[i]))
            .collect::<Vec<_>>(),
        "misalignment_rad": (0..3)
            .map(|i| estimate(DERIVED_NAMES[3 + i], "pair", &a.misalignment_rad[i]))
            .collect::<Vec<_>>(),
        "undetermined": undetermined,
        "suggested_pose_up": a.suggested_up.map(|u| u.as_slice().to_vec()),
        "goodness": {
            "chi_squared": a.chi_squared,
            "dof": a.dof,
            "p_value": a.p_value,
            "alpha": x.settings.alpha,
            "threshold": threshold,
            "rejected": a.p_value.map(|p| p < x.settings.alpha),
        },
    })
}

/// The gyros' part: the bias from the static poses and the turns together when there are
/// turns, the matrix from the turns.
fn gyro_json(x: &Intrinsics) -> Value {
    let g = &x.gyro;
    let static_goodness = json!({
        "chi_squared": g.chi_squared,
        "dof": g.dof,
        "p_value": g.p_value,
        "alpha": x.settings.alpha,
        "rejected": g.p_value.map(|p| p < x.settings.alpha),
    });
    let Some(m) = &x.gyro_matrix else {
        return json!({
            "bias": {
                "value": g.bias.map(|e| e.value),
                "sigma": g.bias.map(|e| e.sigma),
                "unit": "rad/s",
                "from": "static poses",
            },
            "matrix": { "value": Value::Null, "sigma": Value::Null },
            "undetermined": ["matrix (no turn between two poses)"],
            "static_goodness": static_goodness,
        });
    };
    let sigma = |p: usize| m.covariance[(p, p)].sqrt();
    let matrix: Vec<Vec<Value>> = (0..3)
        .map(|r| {
            (0..3)
                .map(|c| number(m.params[3 * r + c], m.determined[3 * r + c]))
                .collect()
        })
        .collect();
    let matrix_sigma: Vec<Vec<Value>> = (0..3)
        .map(|r| {
            (0..3)
                .map(|c| number(sigma(3 * r + c), m.determined[3 * r + c]))
                .collect()
        })
        .collect();
    let undetermined: Vec<String> = (0..9)
        .filter(|&p| !m.determined[p])
        .map(|p| {
            format!(
                "matrix_{}{}",
                ["x", "y", "z"][p / 3],
                ["x", "y", "z"][p % 3]
            )
        })
        .collect();
    json!({
        "bias": {
            "value": m.bias.map(|e| e.value),
            "sigma": m.bias.map(|e| e.sigma),
            "unit": "rad/s",
            "from": "static poses and turns",
        },
        "matrix": { "value": matrix, "sigma": matrix_sigma },
        "scale_ppm": (0..3)
            .map(|i| estimate(DERIVED_NAMES[i], "axis", &m.scale_ppm[i]))
            .collect::<Vec<_>>(),
        "misalignment_rad": (0..6)
            .map(|i| estimate(MISALIGNMENT_NAMES[i], "lean", &m.misalignment_rad[i]))
            .collect::<Vec<_>>(),
        "undetermined": undetermined,
        "turns": m.turns,
        "static_goodness": static_goodness,
        "goodness": {
            "chi_squared": m.chi_squared,
            "dof": m.dof,
            "p_value": m.p_value,
            "alpha": x.settings.alpha,
            "rejected": m.p_value.map(|p| p < x.settings.alpha),
        },
    })
}

/// The text of `intrinsics.json` for `x` of the log `file`.
pub fn intrinsics_json(x: &Intrinsics, file: &str) -> String {
    let d = &x.detection;
    let intervals: Vec<Value> = d
        .intervals
        .iter()
        .zip(&x.accel.residuals)
        .map(|(i, r)| {
            json!({
                "start_s": i.first as f64 * d.sample_period_s,
                "end_s": i.last as f64 * d.sample_period_s,
                "samples": i.samples(),
                "mean_specific_force_m_s2": i.mean_specific_force.as_slice(),
                "mean_angular_rate_rad_s": i.mean_angular_rate.as_slice(),
                "normalized_residual": r,
            })
        })
        .collect();
    let out = json!({
        "log": file,
        "convention": CONVENTION,
        "confidence": x.settings.confidence,
        "gravity_m_s2": x.settings.gravity_m_s2,
        "latitude_deg": x.settings.latitude_rad.map(f64::to_degrees),
        "earth_rate_rad_s": EARTH_RATE_RAD_S,
        "detector": {
            "window_s": d.settings.window_s,
            "window_samples": d.window,
            "min_static_s": d.settings.min_static_s,
            "false_alarm": d.settings.false_alarm,
            "threshold": d.threshold,
            "noise_sigma_per_sample": d.noise_var.map(f64::sqrt),
            "noise_dof": d.noise_dof,
            "sample_period_s": d.sample_period_s,
        },
        "static_intervals": intervals,
        "accel": accel_json(x),
        "gyro": gyro_json(x),
    });
    let mut text = serde_json::to_string_pretty(&out).expect("a JSON value");
    text.push('\n');
    text
}
