//! The one-pass reader: per-fix estimates that are the per-sample file's rows at the fixes,
//! gzip and pipes read to the same bits, `--every-sample` refused on a pipe, a device without
//! line ends refused at once, and the same numbers on any thread count.

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::{column, common, read_csv, run, simulate_logs, stderr};

/// Calibrates in `dir` with `extra` arguments after the logs and the simulation's configuration
/// in full; expects success.
fn calibrate_with(dir: &Path, accel: &str, out: &str, extra: &[&str]) {
    let config = crate::default_config(dir);
    let args = [
        &["calibrate", "--config", config][..],
        &["--accel", accel, "--gps", "logs/gps.csv"],
        &["--out", out, "--quiet"],
        extra,
    ]
    .concat();
    let o = run(&args, dir);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Runs `script` with bash in `dir`, `$B` the binary (for process substitution).
fn bash(dir: &Path, script: &str) -> Output {
    Command::new("bash")
        .arg("-c")
        .arg(script)
        .env("B", common::bin())
        .current_dir(dir)
        .output()
        .expect("bash runs")
}

/// summary.json without the name of the accelerometer log.
fn summary(dir: &Path, out: &str) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap())
            .unwrap();
    v.as_object_mut().unwrap().remove("accelerometer_log");
    v
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

#[test]
fn per_fix_estimates_are_the_per_sample_rows_at_the_fixes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    calibrate_with(d, "logs/accelerometer.csv", "fix", &[]);
    calibrate_with(d, "logs/accelerometer.csv", "all", &["--every-sample"]);
    assert_eq!(summary(d, "fix"), summary(d, "all"));
    let (fix, all) = (
        read_csv(&d.join("fix/estimates.csv")),
        read_csv(&d.join("all/estimates.csv")),
    );
    let at_fix: Vec<usize> = column(&all, "gps_fix")
        .iter()
        .enumerate()
        .filter(|(_, f)| **f == 1.0)
        .map(|(j, _)| j)
        .collect();
    assert_eq!(fix.1.len(), at_fix.len());
    let gps = read_csv(&d.join("logs/gps.csv"));
    assert_eq!(fix.1.len(), gps.1.len());
    let shared: Vec<&String> = fix.0.iter().filter(|c| all.0.contains(c)).collect();
    assert!(shared.len() >= 19, "{shared:?}");
    for name in shared {
        let (a, b) = (column(&fix, name), column(&all, name));
        for (i, &j) in at_fix.iter().enumerate() {
            assert_eq!(a[i].to_bits(), b[j].to_bits(), "{name} at fix {i}");
        }
    }
    // The a priori σ is never below the a posteriori, and the fixes are the GPS log's.
    for (k, unit) in [("dp", "m"), ("dv", "m_s"), ("bias", "m_s2")] {
        let prior = column(&fix, &format!("sigma_{k}_prior_{unit}"));
        let post = column(&fix, &format!("sigma_{k}_filtered_{unit}"));
        assert!(prior.iter().zip(&post).all(|(a, b)| a >= b), "{k}");
    }
    assert_eq!(column(&fix, "gps_position_m"), column(&gps, "position_m"));
    // The per-fix NIS add up to the sum the NIS test judges.
    let nis_sum: f64 = column(&fix, "nis").iter().sum();
    let s = summary(d, "fix");
    assert!((nis_sum - s["nis"]["sum"].as_f64().unwrap()).abs() < 1e-9 * nis_sum);
}

#[test]
fn gzip_and_pipes_read_to_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    let text = bytes(&d.join("logs/accelerometer.csv"));
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&text).unwrap();
    let gz = gz.finish().unwrap();
    std::fs::write(d.join("logs/a.csv.gz"), &gz).unwrap();
    // Named like plain text: the magic bytes decide.
    std::fs::write(d.join("logs/misnamed.csv"), &gz).unwrap();
    calibrate_with(d, "logs/accelerometer.csv", "plain", &[]);
    for (name, accel) in [("gz", "logs/a.csv.gz"), ("misnamed", "logs/misnamed.csv")] {
        calibrate_with(d, accel, name, &[]);
        assert_eq!(summary(d, name), summary(d, "plain"), "{name}");
        let est = |o: &str| bytes(&d.join(o).join("estimates.csv"));
        assert_eq!(est(name), est("plain"), "{name}");
    }
    for (name, pipe) in [
        ("cat", "<(cat logs/accelerometer.csv)"),
        ("zcat", "<(cat logs/a.csv.gz | gzip -dc)"),
        ("gz-pipe", "<(cat logs/a.csv.gz)"),
    ] {
        let o = bash(
            d,
            &format!(
                "\"$B\" calibrate --config simulation.toml --accel {pipe} --gps logs/gps.csv \
                 --out {name} -q"
            ),
        );
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert_eq!(summary(d, name), summary(d, "plain"), "{name}");
    }
    // A damaged stream is refused, not read as text.
    let mut broken = gz.clone();
    broken.truncate(gz.len() / 2);
    std::fs::write(d.join("logs/broken.csv.gz"), &broken).unwrap();
    let o = run(
        &[
            "calibrate",
            "--accel",
            "logs/broken.csv.gz",
            "--gps",
            "logs/gps.csv",
            "--out",
            "broken",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("logs/broken.csv.gz"), "{}", stderr(&o));
    assert!(!d.join("broken").exists());
}

#[test]
fn every_sample_is_refused_on_a_pipe_and_a_device_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    let o = bash(
        d,
        "\"$B\" calibrate --accel <(cat logs/accelerometer.csv) --gps logs/gps.csv --out o \
         --every-sample",
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--every-sample"), "{}", stderr(&o));
    assert!(!d.join("o").exists());
    for (accel, gps) in [
        ("/dev/zero", "logs/gps.csv"),
        ("logs/accelerometer.csv", "/dev/zero"),
    ] {
        let started = Instant::now();
        let o = run(
            &["calibrate", "--accel", accel, "--gps", gps, "--out", "o"],
            d,
        );
        assert!(started.elapsed() < Duration::from_secs(10));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let msg = stderr(&o);
        assert!(
            msg.contains("/dev/zero, line 1") && msg.contains("longer than"),
            "{msg}"
        );
        assert!(!d.join("o").exists());
    }
}

/// A log of 300 s at 1 kHz (about 8.5 MB: several blocks of the reader), nominal or with every
/// time stamp moved by up to ±20 µs (per-step mode).
fn long_logs(d: &Path) {
    std::fs::write(
        d.join("long.toml"),
        "[profile]\nduration_s = 300.0\n\n[accelerometer]\nsample_rate_hz = 1000.0\n",
    )
    .unwrap();
    let o = run(&["simulate", "--config", "long.toml", "--logs", "logs"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("logs/accelerometer.csv")).unwrap();
    let mut jittered = String::with_capacity(text.len() + text.len() / 4);
    for (j, line) in text.lines().enumerate() {
        match (j, line.split_once(',')) {
            (0, _) | (_, None) => jittered.push_str(line),
            (_, Some((t, a))) => {
                let u = ((j as f64 * 12.9898).sin() * 43758.5453).fract();
                let t: f64 = t.parse().unwrap();
                jittered.push_str(&format!("{},{a}", t + 2e-5 * u));
            }
        }
        jittered.push('\n');
    }
    std::fs::write(d.join("logs/jittered.csv"), jittered).unwrap();
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    long_logs(d);
    for (accel, mode) in [
        ("logs/accelerometer.csv", "nominal"),
        ("logs/jittered.csv", "per_step"),
    ] {
        let mut outputs = Vec::new();
        for threads in [1, 2, 3] {
            let out = format!("{mode}-{threads}");
            let args = [
                "calibrate",
                "--config",
                "long.toml",
                "--accel",
                accel,
                "--gps",
                "logs/gps.csv",
                "--out",
                &out,
                "-q",
            ];
            let o = common::run_in(d, &args, Some(threads));
            assert!(o.status.success(), "{}", stderr(&o));
            let s = summary(d, &out);
            assert_eq!(s["dt_mode"], mode);
            outputs.push((s, bytes(&d.join(&out).join("estimates.csv"))));
        }
        assert!(outputs.windows(2).all(|w| w[0] == w[1]), "{mode}");
    }
}

/// The numbers of two summaries, flattened with their paths.
fn numbers(v: &serde_json::Value, path: &str, out: &mut Vec<(String, f64)>) {
    match v {
        serde_json::Value::Object(m) => m
            .iter()
            .for_each(|(k, v)| numbers(v, &format!("{path}.{k}"), out)),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, v)| numbers(v, &format!("{path}[{i}]"), out)),
        serde_json::Value::Number(n) => out.push((path.to_string(), n.as_f64().unwrap())),
        _ => {}
    }
}

#[test]
fn per_step_fix_to_fix_filter_matches_the_per_sample_recursion() {
    // The per-step mode's interval noise Q = W·U_W + s_b·U_b and transition must hold every
    // process-noise term and the bias's decay of the state model: a term left out of the units
    // moves the numbers far beyond rounding. For each bias model the filter may assume.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    long_logs(d);
    let long = std::fs::read_to_string(d.join("long.toml")).unwrap();
    for (config, filter) in [
        ("long.toml", ""),
        (
            "long-rw.toml",
            "bias_model = \"random_walk\"\nbias_random_walk_m_s2_per_sqrt_s = 0.01\n",
        ),
        (
            "long-gm.toml",
            "bias_model = \"gauss_markov\"\nbias_correlation_time_s = 5.0\n",
        ),
    ] {
        if !filter.is_empty() {
            std::fs::write(d.join(config), format!("{long}\n[filter]\n{filter}")).unwrap();
        }
        fix_to_fix_against_per_sample(d, config);
    }
}

/// Calibrates the jittered log with `config`, fix to fix and sample by sample, and compares
/// every number of the summaries.
fn fix_to_fix_against_per_sample(d: &Path, config: &str) {
    let (fix, all) = (format!("{config}-fix"), format!("{config}-all"));
    for (out, extra) in [(&fix, None), (&all, Some("--every-sample"))] {
        let args = [
            "calibrate",
            "--config",
            config,
            "--accel",
            "logs/jittered.csv",
            "--gps",
            "logs/gps.csv",
            "--out",
            out,
            "-q",
        ];
        let args: Vec<&str> = args.into_iter().chain(extra).collect();
        let o = run(&args, d);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (mut fast, mut exact) = (Vec::new(), Vec::new());
    numbers(&summary(d, &fix), "", &mut fast);
    numbers(&summary(d, &all), "", &mut exact);
    assert_eq!(fast.len(), exact.len());
    // The smoothed σ at the start is P(0) less almost all of itself: the rounding at P(0)'s size
    // comes out multiplied by (σ(0)/σ^s)², 10⁴ to 10⁸ here, whichever recursion computes it.
    let tolerance = |path: &str| {
        if path.starts_with(".start_smoothed.sigma") {
            1e-6
        } else {
            1e-9
        }
    };
    let mut worst = (0.0f64, String::new());
    for ((path, a), (_, b)) in fast.iter().zip(&exact) {
        // An autocorrelation lies in [−1, 1] and near 0 at most lags: compared absolutely.
        let scale = if path.contains(".autocorrelation") {
            1.0
        } else {
            b.abs().max(f64::MIN_POSITIVE)
        };
        let relative = (a - b).abs() / scale / tolerance(path);
        if relative > worst.0 {
            worst = (relative, path.clone());
        }
    }
    eprintln!(
        "{config}: per-step, fix to fix against sample by sample: worst relative / tolerance \
         {worst:?}"
    );
    assert!(worst.0 < 1.0, "{config}: {worst:?}");
}
