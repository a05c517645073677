//! What `calibrate` takes from a configuration: only the keys it uses are checked (a recording's
//! configuration need not invent a run length or a GPS rate), none at all runs, the keys it does
//! use keep their error's file, line and range, and without `[initial]` the prior is the first
//! fix with the GPS σ's.

use std::path::Path;

use accelcal::calibrate::Settings;
use accelcal::config::Config;

use crate::{run, simulate_logs, stderr};

/// Calibrates the logs of `simulate_logs` with `config` (TOML text; `None`: no `--config`) into
/// `out`; the output.
fn calibrate(dir: &Path, config: Option<&str>, out: &str) -> std::process::Output {
    let mut args = vec![
        "calibrate",
        "--accel",
        "logs/accelerometer.csv",
        "--gps",
        "logs/gps.csv",
        "--out",
        out,
        "-q",
    ];
    let name = format!("{out}.toml");
    if let Some(text) = config {
        std::fs::write(dir.join(&name), text).unwrap();
        args.extend(["--config", &name]);
    }
    run(&args, dir)
}

fn summary(dir: &Path, out: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap())
        .unwrap()
}

#[test]
fn only_the_keys_calibrate_uses_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    // The rate of a real drive, which the study's run length and GPS rate do not divide.
    let rate = "[accelerometer]\nsample_rate_hz = 104.35668282688978\n";
    let o = calibrate(d, Some(rate), "rate");
    assert!(o.status.success(), "{}", stderr(&o));
    let unused = "[profile]\nduration_s = 31.3\n\n[gps]\nsample_rate_hz = 7.0\n\n[ensemble]\n\
                  realizations = 1\n";
    let o = calibrate(d, Some(unused), "unused");
    assert!(o.status.success(), "{}", stderr(&o));
    let o = calibrate(d, None, "none");
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(d, "none");
    assert_eq!(s["dt_mode"], "per_step");
    assert_eq!(s["nominal_dt_s"], s["median_step_s"]);
    // A key calibrate uses keeps its error: file and line, key, range, exit code 2.
    let cases: [(&str, &str, &[&str]); 3] = [
        (
            "[accelerometer]\nsample_rate_hz = -5.0\n",
            "bad-rate",
            &[
                "bad-rate.toml:2",
                "accelerometer.sample_rate_hz",
                "(0, 1000000]",
            ],
        ),
        (
            "\n[filter]\ngps_velocity_sigma_m_s = 0.0\n",
            "bad-sigma",
            &[
                "bad-sigma.toml:3",
                "filter.gps_velocity_sigma_m_s",
                "[1e-12, 1000000]",
            ],
        ),
        (
            "[filter]\ninitial_velocity_sigma_m_s = 2.0\n",
            "alone",
            &[
                "alone.toml:2",
                "filter.initial_velocity_sigma_m_s",
                "[initial]",
            ],
        ),
    ];
    for (text, out, words) in cases {
        let o = calibrate(d, Some(text), out);
        let msg = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{msg}");
        for w in words {
            assert!(msg.contains(w), "{out}: lacks {w:?}: {msg}");
        }
        assert!(!d.join(out).exists());
    }
}

/// Without `[initial]` the integration starts at the first fix carried back to the first sample,
/// and P(0) takes the GPS σ's; with it, the configured prior as before.
#[test]
fn without_initial_the_prior_is_the_first_fix() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    let gps = crate::read_csv(&d.join("logs/gps.csv"));
    let accel = crate::read_csv(&d.join("logs/accelerometer.csv"));
    let o = calibrate(d, Some("[filter]\ngps_position_sigma_m = 2.0\n"), "first");
    assert!(o.status.success(), "{}", stderr(&o));
    let f = &summary(d, "first")["filter"];
    let (t0, a0) = (accel.1[0][0], accel.1[0][1]);
    let (tf, zp, zv) = (gps.1[0][0], gps.1[0][1], gps.1[0][2]);
    let dt = tf - t0;
    let (p0, v0) = (zp - zv * dt + 0.5 * a0 * dt * dt, zv - a0 * dt);
    assert!((f["initial_velocity_mean_m_s"].as_f64().unwrap() - v0).abs() < 1e-12);
    assert!((f["initial_position_mean_m"].as_f64().unwrap() - p0).abs() < 1e-9);
    assert_eq!(f["initial_position_sigma_m"], 2.0);
    assert_eq!(f["initial_velocity_sigma_m_s"], 0.04);
    // The truth's bias, within 4σ.
    let truth = crate::read_csv(&d.join("logs/truth.csv"));
    let b = crate::column(&truth, "bias_m_s2")[0];
    let s = summary(d, "first");
    let z = (s["bias_m_s2"].as_f64().unwrap() - b) / s["bias_sigma_m_s2"].as_f64().unwrap();
    assert!(z.abs() < 4.0, "{z}");
    assert_eq!(s["warnings"].as_array().unwrap().len(), 0);
    // A first fix 2.2 s after the start: the bias at its prior σ (0.1 m/s²) moves the velocity
    // carried back by 0.22 m/s, more than the prior's 0.04 m/s. Said, not refused.
    let late: String = std::fs::read_to_string(d.join("logs/gps.csv"))
        .unwrap()
        .lines()
        .enumerate()
        .filter(|(i, _)| *i == 0 || *i > 10)
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    std::fs::write(d.join("late.csv"), late).unwrap();
    let args = [
        "calibrate",
        "--accel",
        "logs/accelerometer.csv",
        "--gps",
        "late.csv",
        "--out",
        "late",
        "-q",
    ];
    let o = run(&args, d);
    assert!(o.status.success(), "{}", stderr(&o));
    let warnings = summary(d, "late")["warnings"].clone();
    let text = warnings[0].as_str().unwrap();
    assert!(
        text.contains("2.2 s after") && text.contains("[initial]"),
        "{text}"
    );
    assert!(stderr(&o).contains(&format!("warning: {text}")));
    // The library's settings say so, and follow new GPS σ's.
    let config = Config::from_toml_str("[filter]\ngps_position_sigma_m = 2.0\n").unwrap();
    let settings = Settings::from_config(&config, false, false).unwrap();
    assert!(settings.prior_from_first_fix);
    assert_eq!(settings.nominal_dt_s, None);
    let moved = settings.with_gps_sigmas(3.0, 0.5);
    assert_eq!(moved.filter_stats.initial_position_sigma_m, 3.0);
    assert_eq!(moved.filter_stats.initial_velocity_sigma_m_s, 0.5);
    let configured = Settings::from_config(&config, true, true).unwrap();
    assert!(!configured.prior_from_first_fix);
    assert_eq!(configured.nominal_dt_s, Some(1.0 / 200.0));
    let kept = configured.with_gps_sigmas(3.0, 0.5);
    assert_eq!(kept.filter_stats.initial_position_sigma_m, 10.0);
}
