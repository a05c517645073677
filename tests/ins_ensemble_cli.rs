//! `ensemble --model ins`: the JSON keeps the linear summary's shape with `"model": "ins"`, is
//! the same on one and two threads, and bad requests are refused with exit code 2, the file
//! untouched.

mod common;

use std::path::Path;
use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ensemble(dir: &Path, threads: usize, json: &str) -> Output {
    common::run_in(
        dir,
        &[
            "ensemble",
            "--model",
            "ins",
            "--config",
            "short.toml",
            "--realizations",
            "8",
            "--json",
            json,
        ],
        Some(threads),
    )
}

/// The summary without its timing fields.
fn summary(dir: &Path, json: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join(json)).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let s = v["summary"].as_object_mut().unwrap();
    s.remove("realizations_per_s");
    s.remove("elapsed_s");
    v
}

#[test]
fn the_three_axis_ensemble_writes_its_checks_the_same_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("short.toml"),
        "[drive]\nduration_s = 10.0\n",
    )
    .unwrap();
    let o = ensemble(dir.path(), 1, "one.json");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("three axes, N = 8"));
    let o = ensemble(dir.path(), 2, "two.json");
    assert!(o.status.success(), "{}", stderr(&o));
    let (one, two) = (
        summary(dir.path(), "one.json"),
        summary(dir.path(), "two.json"),
    );
    assert_eq!(one, two);
    assert_eq!(one["model"], "ins");
    let checks = one["summary"]["checks"].as_array().unwrap();
    let ids: Vec<&str> = checks.iter().map(|c| c["id"].as_str().unwrap()).collect();
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
    for c in checks {
        assert!(
            c["verdict"].is_string() && c["members"].as_u64().unwrap() > 0,
            "{c}"
        );
    }
    // Members are named in the three-axis state's words.
    let nees = &checks[5];
    assert!(nees["worst_member"].as_str().unwrap().contains("NEES"));
    let states = one["summary"]["final_states"].as_array().unwrap();
    assert_eq!(states.len(), 15);
    assert_eq!(states[9]["state"], "gyro_bias_x");
    assert_eq!(one["fixes"].as_array().unwrap().len(), 10);
}

#[test]
fn bad_three_axis_requests_are_refused_and_nothing_is_clobbered() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("short.toml"),
        "[drive]\nduration_s = 10.0\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("bad.toml"),
        "[checks]\nfalse_alarm_rate = 0.9\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("fast.toml"),
        "[gnss]\ngnss_rate_hz = 100.0\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("old.json"), "kept").unwrap();
    let cases: [&[&str]; 5] = [
        &["--config", "fast.toml"],
        &["--config", "bad.toml"],
        &["--config", "short.toml", "--realizations", "1"],
        &["--config", "short.toml", "--truth", "euler"],
        // The three-axis ensemble shards (tests/ins_shards.rs); its engine is not the one-axis'.
        &["--config", "short.toml", "--engine", "epoch"],
    ];
    let expect = [
        "GiB",
        "bad.toml:2",
        "ensemble.realizations",
        "one-axis",
        "--engine",
    ];
    for (args, word) in cases.iter().zip(expect) {
        let mut all = vec!["ensemble", "--model", "ins", "--json", "old.json"];
        all.extend_from_slice(args);
        let o = common::run_in(dir.path(), &all, Some(2));
        let msg = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {msg}");
        assert!(msg.contains(word), "{args:?}: {msg}");
        assert!(!msg.contains("panicked"), "{msg}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join("old.json")).unwrap(),
            "kept"
        );
    }
}
