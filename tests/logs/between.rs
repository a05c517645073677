//! Fixes between samples: a simulated log whose fixes are moved off their samples by known
//! offsets calibrates to the on-sample log's numbers, and the nearest-sample processing of the
//! same moved fixes does not.
//!
//! The `euler` truth holds each sample's acceleration a_k over its step, so the truth between
//! samples is known exactly: at t_k + δ, p = p_k + v_k·δ + a_k·δ²/2 and v = v_k + a_k·δ, with
//! a_k = (v_{k+1} − v_k)/Δt from `truth.csv`. Moving a fix by δ moves its measurement by the
//! same amounts and keeps its noise, so the moved log carries the same information. The two
//! calibrations then differ only through the accelerometer's white noise over the fractions
//! τ = δ (the moved log sees the error state at t_k + δ, the on-sample log at t_k): its σ in
//! velocity is √W·τ ≤ √W·Δt per fix, and the smoothed trajectory, a weighted mean over the
//! fixes, moves by less than that.

use std::path::Path;

use crate::{calibrate_with, column, full_config, read_csv, run, stderr};

/// 50 Hz samples, 5 Hz fixes, 30 s: ten samples per fix and a 20 ms step, long enough for the
/// offsets to matter (A·δ up to 0.2 m/s in velocity, 5σ of the GPS's 0.04 m/s).
const CONFIG: &str = "[accelerometer]\nsample_rate_hz = 50.0\n";

/// The white noise's σ, m/s² (the default W = 4·10⁻⁴ (m/s²)²).
const NOISE_SIGMA_M_S2: f64 = 0.02;

/// Writes `dir/moved.csv`: every fix of `logs/gps.csv` moved later by the offset `offset(i)`
/// (a fraction of the step), the measurement moved with the truth; stamped at
/// `stamp(t_sample, t_next_sample, t_moved)`.
fn moved_fixes(
    dir: &Path,
    name: &str,
    offset: &dyn Fn(usize) -> f64,
    stamp: &dyn Fn(f64, f64, f64) -> f64,
) {
    let truth = read_csv(&dir.join("logs/truth.csv"));
    let (t, v) = (column(&truth, "t_s"), column(&truth, "velocity_m_s"));
    let gps = read_csv(&dir.join("logs/gps.csv"));
    let dt = t[1] - t[0];
    let mut text = String::from("t_s,position_m,velocity_m_s\n");
    for (i, row) in gps.1.iter().enumerate() {
        let k = t
            .iter()
            .position(|&s| s == row[0])
            .expect("a fix on a sample");
        // The last sample starts no step: its fix stays there.
        let delta = if k + 1 < t.len() { offset(i) * dt } else { 0.0 };
        let a = v.get(k + 1).map_or(0.0, |&next| (next - v[k]) / dt);
        let z_p = row[1] + v[k] * delta + 0.5 * a * delta * delta;
        let z_v = row[2] + a * delta;
        let next = t.get(k + 1).copied().unwrap_or(t[k]);
        text.push_str(&format!(
            "{},{z_p},{z_v}\n",
            stamp(t[k], next, t[k] + delta)
        ));
    }
    std::fs::write(dir.join(name), text).unwrap();
}

/// The largest difference of the smoothed velocity between two calibrations of `dir`, m/s, and
/// their bias estimates' difference over the bias σ.
fn differences(dir: &Path, a: &str, b: &str) -> (f64, f64) {
    let read = |o: &str| read_csv(&dir.join(o).join("estimates.csv"));
    let (ea, eb) = (read(a), read(b));
    let (va, vb) = (column(&ea, "v_smoothed_m_s"), column(&eb, "v_smoothed_m_s"));
    assert_eq!(va.len(), vb.len());
    let worst = va
        .iter()
        .zip(&vb)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let summary = |o: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(o).join("summary.json")).unwrap())
            .unwrap()
    };
    let (sa, sb) = (summary(a), summary(b));
    let bias = |s: &serde_json::Value| s["bias_m_s2"].as_f64().unwrap();
    let sigma = sa["bias_sigma_m_s2"].as_f64().unwrap();
    (worst, (bias(&sa) - bias(&sb)).abs() / sigma)
}

#[test]
fn fixes_moved_off_their_samples_calibrate_as_on_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    full_config(d, "c.toml", CONFIG);
    let o = run(
        &[
            "simulate", "--config", "c.toml", "--truth", "euler", "--logs", "logs",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let dt = 1.0 / 50.0;
    // Offsets of 0.1 to 0.9 of a step, a different one at every fix.
    let offset = |i: usize| 0.1 + 0.8 * ((i as f64 * 0.618_034) % 1.0);
    moved_fixes(d, "moved.csv", &offset, &|_, _, moved| moved);
    // The old processing: each moved fix applied at the sample nearest to it.
    let nearest = |sample: f64, next: f64, moved: f64| {
        if moved - sample <= next - moved {
            sample
        } else {
            next
        }
    };
    moved_fixes(d, "nearest.csv", &offset, &nearest);
    let config = ["--config", "c.toml"];
    let accel = "logs/accelerometer.csv";
    let (on, _) = calibrate_with(d, &config, (accel, "logs/gps.csv"), "on");
    assert_eq!(on["dt_mode"], "nominal");
    let (moved, _) = calibrate_with(d, &config, (accel, "moved.csv"), "moved");
    assert_eq!(moved["dt_mode"], "per_step");
    calibrate_with(d, &config, (accel, "nearest.csv"), "nearest");
    // The bound: the accelerometer noise over one whole step, in velocity.
    let bound_m_s = NOISE_SIGMA_M_S2 * dt;
    let (worst, bias_sigmas) = differences(d, "on", "moved");
    let (worst_nearest, bias_nearest) = differences(d, "on", "nearest");
    eprintln!(
        "smoothed velocity: moved fixes differ by at most {worst:.2e} m/s, applied at the \
         nearest sample by {worst_nearest:.2e} m/s (bound {bound_m_s:.1e}); bias: {bias_sigmas:.3}σ \
         and {bias_nearest:.3}σ"
    );
    assert!(worst < bound_m_s, "{worst} ≥ {bound_m_s}");
    // The same noise moves the bias estimate by about (√W·Δt / σ_v) ≈ 1 % of its σ; allowed 10 %.
    assert!(bias_sigmas < 0.1, "{bias_sigmas}");
    // Negative control: the nearest-sample processing misses the bound (by 4.6 times here).
    assert!(worst_nearest > 2.0 * bound_m_s, "{worst_nearest}");
}
