//! `simulate --logs` then `calibrate`: the in-memory filter's numbers bit for bit, and an
//! independent processing's to 1e-9, with and without jitter.

use std::path::Path;

use accelcal::config::{BiasModelKind, Config, TruthModel};
use accelcal::realization::record;

use accelcal::realization::SampleRecord;

use crate::reference::{AccelLog, GpsLog, Prior, Processed, process};
use crate::{calibrate, column, common, read_csv, simulate_logs};

/// The accelerometer and GPS logs of `dir` as plain rows.
pub fn logs(dir: &Path, accel: &str) -> (AccelLog, GpsLog) {
    let a = read_csv(&dir.join(accel));
    let g = read_csv(&dir.join("logs/gps.csv"));
    (
        a.1.iter().map(|r| (r[0], r[1])).collect(),
        g.1.iter().map(|r| (r[0], r[1], r[2])).collect(),
    )
}

/// The largest |library − reference| / σ over every sample and state, filtered and smoothed.
pub fn worst_differences(dir: &Path, out: &str, reference: &Processed) -> (f64, f64) {
    let est = read_csv(&dir.join(out).join("estimates.csv"));
    let names = [
        ("dp", "sigma_dp", 0),
        ("dv", "sigma_dv", 1),
        ("bias", "sigma_bias", 2),
    ];
    let (mut filtered, mut smoothed) = (0.0f64, 0.0f64);
    for (name, sigma, k) in names {
        let x = column(&est, &format!("{name}_filtered_{}", unit(k)));
        let s = column(&est, &format!("{sigma}_filtered_{}", unit(k)));
        let xs = column(&est, &format!("{name}_smoothed_{}", unit(k)));
        assert_eq!(x.len(), reference.x.len());
        for j in 0..x.len() {
            filtered = filtered.max((x[j] - reference.x[j][k]).abs() / s[j]);
            smoothed = smoothed.max((xs[j] - reference.xs[j][k]).abs() / s[j]);
        }
    }
    (filtered, smoothed)
}

/// A field of a recorded sample.
type Field = dyn Fn(&SampleRecord) -> f64;

fn unit(k: usize) -> &'static str {
    ["m", "m_s", "m_s2"][k]
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn simulated_logs_calibrate_to_the_in_memory_filter_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    simulate_logs(dir);
    let summary = calibrate(dir, "logs/accelerometer.csv", "logs/gps.csv", "out");
    let mut config = Config::default();
    config.ensemble.truth = TruthModel::Euler;
    in_memory_bit_for_bit(dir, &config, &summary);
}

/// A drifting bias (truth and filter alike): the nominal mode's interval Φ and Q are the
/// in-memory `FilterSchedule`'s, bit for bit (Gauss–Markov: the product of the steps).
#[test]
fn drifting_bias_logs_calibrate_to_the_in_memory_filter_bit_for_bit() {
    let drifts = [
        (
            "bias_model = \"random_walk\"\nbias_random_walk_m_s2_per_sqrt_s = 0.02\n",
            BiasModelKind::RandomWalk,
        ),
        (
            "bias_model = \"gauss_markov\"\nbias_correlation_time_s = 20.0\n",
            BiasModelKind::GaussMarkov,
        ),
    ];
    for (keys, kind) in drifts {
        let dir = tempfile::tempdir().unwrap();
        let dir = dir.path();
        crate::full_config(dir, "c.toml", &format!("[accelerometer]\n{keys}"));
        let args = [
            "simulate", "--config", "c.toml", "--truth", "euler", "--logs", "logs",
        ];
        let o = crate::run(&args, dir);
        assert!(o.status.success(), "{}", crate::stderr(&o));
        let args = [
            "calibrate",
            "--config",
            "c.toml",
            "--accel",
            "logs/accelerometer.csv",
            "--gps",
            "logs/gps.csv",
            "--out",
            "out",
            "-q",
            "--every-sample",
        ];
        let o = crate::run(&args, dir);
        assert!(o.status.success(), "{}", crate::stderr(&o));
        let text = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
        let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
        let mut config = Config::default();
        config.ensemble.truth = TruthModel::Euler;
        config.accelerometer.bias_model = kind;
        match kind {
            BiasModelKind::RandomWalk => {
                config.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(0.02);
            }
            _ => config.accelerometer.bias_correlation_time_s = Some(20.0),
        }
        in_memory_bit_for_bit(dir, &config, &summary);
    }
}

/// The logs of `dir` and their calibration `out` (with `summary`) hold the in-memory
/// realization 0 of `config` bit for bit.
fn in_memory_bit_for_bit(dir: &Path, config: &Config, summary: &serde_json::Value) {
    assert_eq!(summary["dt_mode"], "nominal");
    let (model, schedule) = common::model_of(config);
    let r = record(&model, &schedule, config.ensemble.seed, 0);

    let accel = read_csv(&dir.join("logs/accelerometer.csv"));
    let truth = read_csv(&dir.join("logs/truth.csv"));
    let est = read_csv(&dir.join("out/estimates.csv"));
    assert_eq!(est.1.len(), r.samples.len());
    let bits = |v: Vec<f64>| v.into_iter().map(f64::to_bits).collect::<Vec<_>>();
    let recorded = |f: &Field| bits(r.samples.iter().map(f).collect());
    // The logs hold the simulation's numbers.
    assert_eq!(
        bits(column(&accel, "accel_m_s2")),
        recorded(&|s| s.accel_output_m_s2)
    );
    assert_eq!(
        bits(column(&truth, "position_m")),
        recorded(&|s| s.truth_p_m)
    );
    assert_eq!(
        bits(column(&truth, "bias_m_s2")),
        recorded(&|s| s.delta_x[2])
    );
    // The calibration computes the in-memory integration and filter, bit for bit.
    let pairs: [(&str, &Field); 8] = [
        ("p_integrated_m", &|s| s.computed_p_m),
        ("v_integrated_m_s", &|s| s.computed_v_m_s),
        ("dp_filtered_m", &|s| s.estimate[0]),
        ("dv_filtered_m_s", &|s| s.estimate[1]),
        ("bias_filtered_m_s2", &|s| s.estimate[2]),
        ("sigma_dp_filtered_m", &|s| s.sigma[0]),
        ("sigma_dv_filtered_m_s", &|s| s.sigma[1]),
        ("sigma_bias_filtered_m_s2", &|s| s.sigma[2]),
    ];
    for (name, f) in pairs {
        assert_eq!(bits(column(&est, name)), recorded(f), "{name}");
    }
    let fixes = column(&est, "gps_fix")
        .iter()
        .filter(|&&x| x == 1.0)
        .count();
    assert_eq!(fixes, r.fixes.len());
    let last = r.fixes.last().unwrap();
    // The numbers of summary.json read as written (serde_json's own parsing may be an ulp off).
    let text = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    let field = |name: &str| -> f64 {
        let key = format!("\n  \"{name}\": ");
        let at = text.find(&key).unwrap() + key.len();
        let end = text[at..].find([',', '\n']).unwrap();
        text[at..at + end].parse().unwrap()
    };
    assert_eq!(field("bias_m_s2").to_bits(), last.post[2].to_bits());
    assert_eq!(
        field("bias_sigma_m_s2").to_bits(),
        last.sigma_post[2].to_bits()
    );
}

#[test]
fn calibration_agrees_with_an_independent_processing_with_and_without_jitter() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    simulate_logs(dir);
    let prior = Prior::default_config();

    let summary = calibrate(dir, "logs/accelerometer.csv", "logs/gps.csv", "out");
    let (accel, gps) = logs(dir, "logs/accelerometer.csv");
    let reference = process(&accel, &gps, &prior);
    let n = accel.len() - 1;
    let (b, s) = (reference.x[n][2], reference.p[n][2][2].sqrt());
    let bias = summary["bias_m_s2"].as_f64().unwrap();
    let sigma = summary["bias_sigma_m_s2"].as_f64().unwrap();
    assert!(relative(bias, b) < 1e-9, "bias {bias} vs {b}");
    assert!(relative(sigma, s) < 1e-9, "σ {sigma} vs {s}");
    let (filtered, smoothed) = worst_differences(dir, "out", &reference);
    eprintln!(
        "nominal: bias rel. {:.1e}, σ rel. {:.1e}; worst |Δ|/σ filtered {filtered:.1e}, smoothed {smoothed:.1e}",
        relative(bias, b),
        relative(sigma, s)
    );
    assert!(filtered < 1e-9 && smoothed < 1e-6, "{filtered} {smoothed}");

    // Every time stamp moved by up to ±0.2 ms; the fixes keep theirs.
    let mut jittered = String::from("t_s,accel_m_s2\n");
    for (j, (t, a)) in accel.iter().enumerate() {
        let u = ((j as f64 * 12.9898).sin() * 43758.5453).fract();
        jittered.push_str(&format!("{},{a}\n", t + 2e-4 * u));
    }
    std::fs::write(dir.join("logs/jittered.csv"), jittered).unwrap();
    let summary = calibrate(dir, "logs/jittered.csv", "logs/gps.csv", "jittered");
    assert_eq!(summary["dt_mode"], "per_step");
    let (accel, gps) = logs(dir, "logs/jittered.csv");
    let reference = process(&accel, &gps, &prior);
    let (b, s) = (reference.x[n][2], reference.p[n][2][2].sqrt());
    let bias = summary["bias_m_s2"].as_f64().unwrap();
    let sigma = summary["bias_sigma_m_s2"].as_f64().unwrap();
    assert!(relative(bias, b) < 1e-9, "bias {bias} vs {b}");
    assert!(relative(sigma, s) < 1e-9, "σ {sigma} vs {s}");
    let (filtered, smoothed) = worst_differences(dir, "jittered", &reference);
    eprintln!(
        "jitter: bias rel. {:.1e}, σ rel. {:.1e}; worst |Δ|/σ filtered {filtered:.1e}, smoothed {smoothed:.1e}",
        relative(bias, b),
        relative(sigma, s)
    );
    assert!(filtered < 1e-9 && smoothed < 1e-6, "{filtered} {smoothed}");
    let steps = (
        summary["min_step_s"].as_f64().unwrap(),
        summary["max_step_s"].as_f64().unwrap(),
    );
    assert!(steps.0 < 0.0049 && steps.1 > 0.0051, "{steps:?}");
}
