//! `accelcal allan` end to end: a white-noise-only log leaves K unresolved (null with an upper
//! bound) in every file; a white-plus-random-walk log recovers N and K; bad input exits with 2.

use std::path::Path;
use std::process::Command;

use accelcal::allan::simulate::StaticLog;
use accelcal::input::csv::text::{header, push_row};

fn write_log(path: &Path, columns: &[&str], rows: impl Iterator<Item = Vec<f64>>) {
    let mut text = header(columns);
    for r in rows {
        push_row(&mut text, &r);
    }
    std::fs::write(path, text).unwrap();
}

fn allan(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .arg("allan")
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn white_noise_only_reports_k_unresolved_in_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let log = StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 0.0,
        offset_m_s2: 9.80665,
    };
    let y = log.samples(200_000, 5);
    let csv = dir.path().join("static.csv");
    // A second axis column, picked by --column.
    write_log(
        &csv,
        &["t_s", "ax_m_s2", "az_m_s2"],
        y.iter()
            .enumerate()
            .map(|(i, v)| vec![i as f64 * 0.01, 0.0, *v]),
    );
    let out = dir.path().join("out");
    let o = allan(&[
        "--accel",
        csv.to_str().unwrap(),
        "--column",
        "az_m_s2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("allan.json")).unwrap()).unwrap();
    let k = &json["fit"]["acceleration_random_walk_m_s2_per_sqrt_s"];
    assert!(k["value"].is_null() && k["lower"].is_null(), "{k}");
    assert!(k["upper"].as_f64().unwrap() > 0.0);
    let n = json["fit"]["velocity_random_walk_m_s_per_sqrt_s"]["value"]
        .as_f64()
        .unwrap();
    assert!((n / 2e-3 - 1.0).abs() < 0.05, "N = {n}");
    assert_eq!(json["samples"].as_u64(), Some(200_000));
    assert!((json["sample_period_s"].as_f64().unwrap() - 0.01).abs() < 1e-12);
    let toml = std::fs::read_to_string(out.join("noise.toml")).unwrap();
    assert!(toml.contains("upper bound"), "{toml}");
    let parsed: toml::Value = toml::from_str(&toml).unwrap();
    let var = parsed["filter"]["accel_noise_var_m2_s4"]
        .as_float()
        .unwrap();
    assert!((var / (n * n / 0.01) - 1.0).abs() < 1e-12);
    let yaml = std::fs::read_to_string(out.join("imu.yaml")).unwrap();
    assert!(yaml.contains("accelerometer_random_walk:") && yaml.contains("upper bound"));
    assert!(yaml.contains("update_rate: 100.0"), "{yaml}");
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(page.contains("<svg") && page.contains("unresolved"));
    assert!(!page.contains("http://") || !page.contains("src=\"http"));
}

#[test]
fn recovers_n_and_k_of_a_random_walk_log() {
    let dir = tempfile::tempdir().unwrap();
    let log = StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
        offset_m_s2: 9.80665,
    };
    let y = log.samples(1_000_000, 11);
    let csv = dir.path().join("static.csv");
    write_log(
        &csv,
        &["t_s", "accel_m_s2"],
        y.iter().enumerate().map(|(i, v)| vec![i as f64 * 0.01, *v]),
    );
    let out = dir.path().join("out");
    let o = allan(&[
        "--accel",
        csv.to_str().unwrap(),
        "--confidence",
        "0.95",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("allan.json")).unwrap()).unwrap();
    for (key, truth) in [
        ("velocity_random_walk_m_s_per_sqrt_s", 2e-3),
        ("acceleration_random_walk_m_s2_per_sqrt_s", 1e-4),
    ] {
        let t = &json["fit"][key];
        let (lo, hi) = (t["lower"].as_f64().unwrap(), t["upper"].as_f64().unwrap());
        assert!(
            lo <= truth && truth <= hi,
            "{key}: {truth} outside [{lo}, {hi}]"
        );
        assert!(t["value"].as_f64().is_some());
    }
    // The printed N shows its narrow interval's ends apart from each other and from N.
    let line = String::from_utf8_lossy(&o.stdout).into_owned();
    let n = line.split("N = ").nth(1).expect("N printed");
    let (value, rest) = n.split_once(" [").unwrap();
    let (lo, rest) = rest.split_once(", ").unwrap();
    let hi = rest.split_once(']').unwrap().0;
    let read = |x: &str| x.replace('−', "-").parse::<f64>().unwrap();
    let (v, lo, hi) = (read(value), read(lo), read(hi));
    assert!(lo < v && v < hi, "printed N {v} [{lo}, {hi}] in {line}");
    let toml = std::fs::read_to_string(out.join("noise.toml")).unwrap();
    assert!(toml.contains("bias_model = \"random_walk\""), "{toml}");
    noise_toml_drives_simulate_and_calibrate(&out.join("noise.toml"), dir.path());
}

/// The README's path: `noise.toml` given as it is to `--config` of `simulate --logs` and of
/// `calibrate` on those logs; the calibration's filter takes the measured white noise.
fn noise_toml_drives_simulate_and_calibrate(noise: &Path, dir: &Path) {
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_accelcal"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let (logs, cal) = (dir.join("drive"), dir.join("cal"));
    let config = noise.to_str().unwrap();
    run(&[
        "simulate",
        "--config",
        config,
        "--logs",
        logs.to_str().unwrap(),
    ]);
    run(&[
        "calibrate",
        "--config",
        config,
        "--accel",
        logs.join("accelerometer.csv").to_str().unwrap(),
        "--gps",
        logs.join("gps.csv").to_str().unwrap(),
        "--out",
        cal.to_str().unwrap(),
        "--quiet",
    ]);
    let parsed: toml::Value = toml::from_str(&std::fs::read_to_string(noise).unwrap()).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cal.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["filter"]["accel_noise_var_m2_s4"].as_f64(),
        parsed["filter"]["accel_noise_var_m2_s4"].as_float()
    );
}

#[test]
fn bad_input_exits_2_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("gap.csv");
    let mut rows: Vec<Vec<f64>> = (0..1000).map(|i| vec![i as f64 * 0.01, 1.0]).collect();
    rows.remove(500); // t = 5.00 s: the step into 5.01 s (data row 501, line 502) is a gap
    write_log(&csv, &["t_s", "accel_m_s2"], rows.into_iter());
    let out = dir.path().join("out");
    let o = allan(&[
        "--accel",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("gap.csv, line 502"), "{err}");
    assert!(!out.exists());
    let o = allan(&["--accel", csv.to_str().unwrap(), "--column", "ay_m_s2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("ay_m_s2"));
    let o = allan(&["--accel", csv.to_str().unwrap(), "--confidence", "1.5"]);
    assert_eq!(o.status.code(), Some(2));
    let short = dir.path().join("short.csv");
    write_log(
        &short,
        &["t_s", "accel_m_s2"],
        (0..50).map(|i| vec![i as f64, 1.0 + i as f64]),
    );
    let o = allan(&[
        "--accel",
        short.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("at least"));
}

#[test]
fn the_same_numbers_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let log = StaticLog {
        sample_period_s: 0.005,
        velocity_random_walk_m_s_per_sqrt_s: 1e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-3,
        offset_m_s2: -9.80665,
    };
    // Long enough for several stretches of the phase (65 536 samples) and of the text (8 MiB).
    let y = log.samples(600_000, 2);
    let csv = dir.path().join("static.csv");
    write_log(
        &csv,
        &["t_s", "accel_m_s2"],
        y.iter()
            .enumerate()
            .map(|(i, v)| vec![i as f64 * 0.005, *v]),
    );
    let run = |threads: &str| {
        let out = dir.path().join(format!("out{threads}"));
        let o = Command::new(env!("CARGO_BIN_EXE_accelcal"))
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "allan",
                "--quiet",
                "--accel",
                csv.to_str().unwrap(),
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(out.join("allan.json")).unwrap()
    };
    assert_eq!(run("1"), run("3"));
}

/// A log with a sinusoid the model lacks: the fit is rejected in `allan.json` (`fit.goodness`,
/// `fit.reading`, the sinusoid named near its frequency, the per-τ fitted curve), in the files
/// another tool reads, on the page and in the printed line; a log drawn from the model is not.
#[test]
fn a_sinusoid_log_is_rejected_everywhere_and_a_model_log_is_not() {
    use accelcal::allan::simulate::FeatureLog;
    let dir = tempfile::tempdir().unwrap();
    let base = StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 1e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
        offset_m_s2: 9.80665,
    };
    let sinusoid = FeatureLog {
        base,
        bias_instability_m_s2: 0.0,
        sinusoid_amplitude_m_s2: 4e-3,
        sinusoid_frequency_hz: 0.5,
        rate_ramp_m_s3: 0.0,
    };
    for (name, y, rejected) in [
        ("sinusoid", sinusoid.samples(1 << 16, 2), true),
        ("model", base.samples(1 << 16, 2), false),
    ] {
        let csv = dir.path().join(format!("{name}.csv"));
        write_log(
            &csv,
            &["t_s", "accel_m_s2"],
            y.iter().enumerate().map(|(i, v)| vec![i as f64 * 0.01, *v]),
        );
        let out = dir.path().join(name);
        let o = allan(&[
            "--accel",
            csv.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let line = String::from_utf8_lossy(&o.stdout).to_string();
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("allan.json")).unwrap())
                .unwrap();
        let fit = &json["fit"];
        let g = &fit["goodness"];
        assert_eq!(g["alpha"].as_f64(), Some(0.01), "{g}");
        for key in ["statistic", "dof", "p_value", "worst_tau_s"] {
            assert!(g[key].as_f64().is_some_and(f64::is_finite), "{key}: {g}");
        }
        let taus = json["tau_s"].as_array().unwrap().len();
        assert_eq!(json["fit_adev_m_s2"].as_array().unwrap().len(), taus);
        assert!(fit["rate_ramp_m_s3"]["upper"].as_f64().unwrap() > 0.0);
        let toml = std::fs::read_to_string(out.join("noise.toml")).unwrap();
        let yaml = std::fs::read_to_string(out.join("imu.yaml")).unwrap();
        let page = std::fs::read_to_string(out.join("index.html")).unwrap();
        if rejected {
            assert_eq!(g["verdict"], "fail", "{g}");
            assert_eq!(fit["reading"], "ieee952");
            let f = &fit["features"][0];
            assert_eq!(f["kind"], "sinusoid", "{fit}");
            let hz = f["frequency_hz"].as_f64().unwrap();
            assert!((0.25..=1.0).contains(&hz), "{hz}");
            assert!(toml.contains("IEEE Std 952") && yaml.contains("IEEE Std 952"));
            assert!(line.contains("the model is rejected") && line.contains("sinusoid near"));
            assert!(page.contains("the model is rejected") && page.contains("departs"));
        } else {
            assert_eq!(g["verdict"], "pass", "{g}");
            assert_eq!(fit["reading"], "fit");
            assert!(toml.contains("model fit (goodness of fit"), "{toml}");
            assert!(line.contains("the model fits"), "{line}");
        }
    }
}
