//! `calibrate --estimate-noise`: the estimates recover the statistics of simulated drives, the
//! profile-likelihood intervals cover the truth at their confidence over many drives (and
//! intervals of half the width do not), a statistic the drive cannot determine is reported as
//! such, the reduced likelihood is the per-sample filter's, and bad requests exit with 2.

mod common;

use std::path::Path;

use accelcal::config::Config;
use accelcal::likelihood::{Key, Request};
use accelcal::study::noise::{self, KeyCoverage, NOISE_DRIVES};

fn coverage_line(c: &KeyCoverage) -> String {
    format!(
        "{}: {} of {} covered, band [{}, {}]; half width {}; median ratio {:.4}",
        c.key.name(),
        c.covered,
        c.identifiable,
        c.band.0,
        c.band.1,
        c.half_width_covered,
        c.median_ratio
    )
}

#[test]
fn intervals_cover_the_truth_over_many_drives_and_half_intervals_do_not() {
    let study = noise::run(
        &Config::default(),
        NOISE_DRIVES,
        &mut accelcal::study::Silent,
    )
    .expect("the default filter is positive definite")
    .expect("the default rates fit a 120 s drive");
    assert_eq!(
        study.estimates.len() as u64,
        NOISE_DRIVES,
        "every drive calibrated"
    );
    for (j, c) in study.coverage.iter().enumerate() {
        let line = coverage_line(c);
        eprintln!("{line}");
        // Each statistic is measured on (nearly) every drive of this kind.
        assert!(c.identifiable >= NOISE_DRIVES * 9 / 10, "{line}");
        // The covered count in its binomial band at 1 % (95 % intervals).
        assert!(c.holds(), "{line}");
        // The negative control: half the interval (the wrong curvature) covers too rarely.
        assert!(!c.half_width_holds(), "{line}");
        // The estimates recover the truth: the median of estimate/truth within 4 standard
        // errors of 1, its standard error from the intervals' median width (a 95 % interval
        // spans 3.92 σ of the log-estimate; the median of n draws has 1.253 σ/√n).
        let mut widths: Vec<f64> = study
            .estimates
            .iter()
            .map(|e| &e.keys[j])
            .filter(|k| k.identifiable)
            .map(|k| (k.upper.unwrap() / k.lower).ln() / 3.92)
            .collect();
        widths.sort_by(f64::total_cmp);
        let sigma = widths[widths.len() / 2];
        let se = 1.253 * sigma / (c.identifiable as f64).sqrt();
        assert!(c.median_ratio.ln().abs() < 4.0 * se, "{line}; se {se}");
    }
}

/// One drive of `config` estimated with `keys`.
fn estimate_one(config: &Config, keys: &[Key], index: u64) -> accelcal::likelihood::NoiseEstimate {
    let (model, schedule) = common::model_of(config);
    let request = Request {
        keys: keys.to_vec(),
        confidence: 0.95,
    };
    noise::run_drive(&model, &schedule, index, &request).expect("a simulated drive calibrates")
}

#[test]
fn whether_the_white_noise_is_identifiable_depends_on_the_drive() {
    let keys = [Key::GpsPosition, Key::GpsVelocity, Key::AccelNoiseVar];
    // The default drive: W = 4e-4 (m/s²)², 5 Hz fixes, 120 s. The profile of W runs to the
    // search's lower bound: only an upper bound is known.
    let mut quiet = Config::default();
    quiet.profile.duration_s = 120.0;
    quiet.ensemble.truth = accelcal::config::TruthModel::Euler;
    for index in 0..3 {
        let e = estimate_one(&quiet, &keys, index);
        let w = &e.keys[2];
        assert_eq!(w.key, Key::AccelNoiseVar);
        assert!(!w.identifiable, "drive {index}: {w:?}");
        assert_eq!(w.lower, 0.0, "drive {index}: {w:?}");
        assert!(w.upper.is_some_and(|u| u > 4e-4), "drive {index}: {w:?}");
        assert!(e.keys[0].identifiable && e.keys[1].identifiable);
    }
    // A vibrating car: W = 0.4 (m/s²)², 10 Hz fixes, one minute. W is measured, and its
    // interval holds the truth on most drives (each covers with probability 0.95).
    let mut car = quiet.clone();
    car.profile.duration_s = 60.0;
    car.gps.sample_rate_hz = 10.0;
    car.accelerometer.noise_var_m2_s4 = 0.4;
    let mut covered = 0;
    for index in 0..5 {
        let e = estimate_one(&car, &keys, index);
        let w = &e.keys[2];
        assert!(w.identifiable, "drive {index}: {w:?}");
        covered += usize::from(w.lower < 0.4 && w.upper.unwrap() > 0.4);
    }
    // P(fewer than 3 of 5 cover) = 1.2e-3 at 0.95 each.
    assert!(covered >= 3, "{covered} of 5");
}

/// Runs the binary in `dir`.
fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    common::run_in(dir, args, None)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_reduced_likelihood_is_the_per_sample_filter_s() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = "[profile]\nduration_s = 60.0\n\n[accelerometer]\nsample_rate_hz = 200.0\nbias_model = \"random_walk\"\n\
                  bias_random_walk_m_s2_per_sqrt_s = 0.002\n";
    std::fs::write(d.join("c.toml"), config).unwrap();
    let o = run(
        d,
        &[
            "simulate", "--config", "c.toml", "--truth", "euler", "--logs", "logs", "-q",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Nominal Δt (the recursion sample by sample), and per-step Δt: the same logs with every
    // time stamp stretched by a part in 10⁶.
    std::fs::create_dir(d.join("stretched")).unwrap();
    for name in ["accelerometer.csv", "gps.csv"] {
        let text = std::fs::read_to_string(d.join("logs").join(name)).unwrap();
        let mut lines = text.lines();
        let mut out = format!("{}\n", lines.next().unwrap());
        for line in lines {
            let (t, rest) = line.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            out.push_str(&format!("{},{rest}\n", t * (1.0 + 1e-6)));
        }
        std::fs::write(d.join("stretched").join(name), out).unwrap();
    }
    for (logs, mode) in [("logs", "nominal"), ("stretched", "per_step")] {
        let out = format!("out-{mode}");
        let o = run(
            d,
            &[
                "calibrate",
                "--config",
                "c.toml",
                "--accel",
                &format!("{logs}/accelerometer.csv"),
                "--gps",
                &format!("{logs}/gps.csv"),
                "--out",
                &out,
                "--every-sample",
                "--estimate-noise",
                "-q",
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let s = json(&d.join(&out).join("summary.json"));
        assert_eq!(s["dt_mode"], mode);
        let reduced = s["noise_estimate"]["log_likelihood"].as_f64().unwrap();
        let filter = s["log_likelihood"].as_f64().unwrap();
        let rel = (reduced - filter).abs() / filter.abs();
        assert!(rel < 1e-9, "{mode}: {reduced} against {filter} ({rel:e})");
        // The default keys of a random-walk filter: the two σ's and K.
        for key in [
            "gps_position_sigma_m",
            "gps_velocity_sigma_m_s",
            Key::BiasRandomWalk.name(),
        ] {
            assert!(
                s["noise_estimate"][key]["value"].as_f64().unwrap() > 0.0,
                "{key}"
            );
        }
        assert_eq!(s["filter"]["bias_model"], "random_walk");
        let k = s["filter"]["bias_random_walk_m_s2_per_sqrt_s"]
            .as_f64()
            .unwrap();
        assert_eq!(
            k,
            s["noise_estimate"][Key::BiasRandomWalk.name()]["value"]
                .as_f64()
                .unwrap()
        );
    }
}

#[test]
fn bad_requests_exit_with_2_and_name_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = run(d, &["simulate", "--logs", "logs", "-q"]);
    assert!(o.status.success());
    let logs = [
        "--accel",
        "logs/accelerometer.csv",
        "--gps",
        "logs/gps.csv",
        "--out",
        "out",
    ];
    std::fs::write(
        d.join("gm.toml"),
        "[filter]\nbias_model = \"gauss_markov\"\nbias_correlation_time_s = 50.0\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--estimate", "gps_position_sigma_m"], "--estimate-noise"),
        (
            &["--estimate-noise", "--estimate", "gps_sigma"],
            "gps_position_sigma_m",
        ),
        (&["--estimate-noise", "--confidence", "1.5"], "0 < P < 1"),
        (
            &[
                "--estimate-noise",
                "--config",
                "gm.toml",
                "--estimate",
                Key::BiasRandomWalk.name(),
            ],
            "gauss_markov",
        ),
    ];
    for (more, says) in cases {
        let args = [&["calibrate"][..], more, &logs].concat();
        let o = run(d, &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{more:?}: {err}");
        assert!(err.contains(says), "{more:?}: {err}");
        assert!(!d.join("out").exists(), "{more:?}");
    }
    // The constant-bias filter searching K becomes a random walk and says what it found.
    let args = [
        &["calibrate", "--estimate-noise", "--estimate"][..],
        &[Key::BiasRandomWalk.name()],
        &logs,
    ]
    .concat();
    let o = run(d, &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = json(&d.join("out/summary.json"));
    assert_eq!(s["filter"]["bias_model"], "random_walk");
    assert!(s["noise_estimate"][Key::BiasRandomWalk.name()]["identifiable"].is_boolean());
}
