//! The command line: bad input is refused with a message naming the field and exit code 2,
//! without touching files the user already has; results do not depend on the thread count.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&str], dir: &Path) -> Output {
    Command::new(common::bin())
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .expect("the binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `ensemble --config` on `toml` and expects exit code 2 and every word of `expect` in the
/// message, with the earlier output file untouched.
fn refuses(toml: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("c.toml"), toml).unwrap();
    std::fs::write(dir.path().join("out.json"), "earlier results").unwrap();
    let o = run(
        &["ensemble", "--config", "c.toml", "--json", "out.json"],
        dir.path(),
    );
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "exit code for {toml:?}: {msg}");
    for word in expect {
        assert!(
            msg.contains(word),
            "message for {toml:?} lacks {word:?}: {msg}"
        );
    }
    assert!(!msg.contains("panicked"), "{msg}");
    let kept = std::fs::read_to_string(dir.path().join("out.json")).unwrap();
    assert_eq!(kept, "earlier results", "a failed run clobbered the output");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .collect();
    assert_eq!(leftovers.len(), 2, "a failed run left files behind");
}

#[test]
fn negative_variance_is_refused() {
    refuses(
        "[accelerometer]\nnoise_var_m2_s4 = -0.0004\n",
        &["accelerometer.noise_var_m2_s4", "[0,"],
    );
}

#[test]
fn rates_that_do_not_divide_are_refused() {
    refuses(
        "[gps]\nsample_rate_hz = 7.0\n",
        &["gps.sample_rate_hz", "must divide"],
    );
}

#[test]
fn nan_is_refused() {
    refuses(
        "[gps]\nposition_sigma_m = nan\n",
        &["gps.position_sigma_m", "finite"],
    );
}

#[test]
fn non_positive_rate_and_duration_are_refused() {
    refuses(
        "[accelerometer]\nsample_rate_hz = 0.0\n",
        &["accelerometer.sample_rate_hz", "(0,"],
    );
    refuses(
        "[profile]\nduration_s = -30.0\n",
        &["profile.duration_s", "(0,"],
    );
}

#[test]
fn fewer_than_two_realizations_are_refused() {
    refuses(
        "[ensemble]\nrealizations = 1\n",
        &["ensemble.realizations", "[2,"],
    );
}

#[test]
fn unknown_field_is_refused() {
    refuses(
        "[gps]\nposition_sigma = 1.0\n",
        &["unknown field", "position_sigma"],
    );
}

#[test]
fn malformed_toml_is_refused() {
    refuses("[gps\nposition_sigma_m = 1.0\n", &["invalid configuration"]);
}

#[test]
fn wrong_type_is_refused() {
    refuses("[ensemble]\nrealizations = \"many\"\n", &["realizations"]);
}

#[test]
fn residual_pair_off_the_fix_grid_is_refused() {
    refuses(
        "[checks]\nresidual_pair_s = [10.1, 20.0]\n",
        &["checks.residual_pair_s", "t_m < t_i"],
    );
}

#[test]
fn missing_config_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &["ensemble", "--config", "nope.toml", "--realizations", "10"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("nope.toml"), "{}", stderr(&o));
}

#[test]
fn bad_realizations_flag_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&["ensemble", "--realizations", "1"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("ensemble.realizations"),
        "{}",
        stderr(&o)
    );
    let o = run(&["ensemble", "--truth", "exact"], dir.path());
    assert_eq!(o.status.code(), Some(2), "clap usage errors exit with 2");
}

#[test]
fn printed_default_config_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&["config"], dir.path());
    assert!(o.status.success());
    std::fs::write(dir.path().join("c.toml"), &o.stdout).unwrap();
    let o = run(
        &[
            "ensemble",
            "--config",
            "c.toml",
            "--realizations",
            "20",
            "--json",
            "e.json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The ensemble JSON without its timing fields.
fn without_timing(json: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
    let s = v["summary"].as_object_mut().expect("a summary object");
    assert!(s.remove("realizations_per_s").is_some());
    assert!(s.remove("elapsed_s").is_some());
    v
}

#[test]
fn same_seed_gives_the_same_json_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let name = format!("t{threads}.json");
        let o = Command::new(common::bin())
            .args([
                "ensemble",
                "--realizations",
                "1000",
                "--seed",
                "42",
                "--json",
                &name,
            ])
            .current_dir(dir.path())
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        outputs.push(std::fs::read_to_string(dir.path().join(&name)).unwrap());
    }
    let a = without_timing(&outputs[0]);
    assert_eq!(a, without_timing(&outputs[1]));
    let s = &a["summary"];
    assert_eq!(s["realizations"], 1000);
    assert_eq!(s["seed"], 42);
    assert_eq!(s["truth"], "analytic");
    for key in ["position_m", "velocity_m_s", "bias_m_s2"] {
        assert!(s["final_sigma"][key].as_f64().unwrap() > 0.0);
    }
    let ids: Vec<&str> = s["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["id"].as_str().unwrap())
        .collect();
    assert_eq!(
        ids,
        [
            "mean_error",
            "covariance_match",
            "covariance_correlation",
            "orthogonality",
            "residual_whiteness",
            "nees",
            "nis"
        ]
    );
    for c in s["checks"].as_array().unwrap() {
        assert!(c["passed"].is_boolean() && c["worst"].is_number() && c["bound"].is_number());
    }
}

#[test]
fn another_seed_gives_other_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for seed in ["1", "2"] {
        let o = run(
            &["ensemble", "--realizations", "100", "--seed", seed],
            dir.path(),
        );
        assert!(o.status.success());
        outputs.push(without_timing(&String::from_utf8(o.stdout).unwrap()));
    }
    assert_ne!(outputs[0]["fixes"], outputs[1]["fixes"]);
}

#[test]
fn simulate_writes_every_accelerometer_sample() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &["simulate", "--csv", "r.csv", "--truth", "euler"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.path().join("r.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 6001, "header and samples t = 0 … 30 s");
    assert!(lines[0].starts_with("t_s,"));
    let fixes = lines[1..].iter().filter(|l| l.ends_with(",1")).count();
    assert_eq!(fixes, 150);
}
