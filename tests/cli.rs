//! The command line: bad input is refused with a message naming the field and exit code 2,
//! without touching files the user already has; results do not depend on the thread count.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&str], dir: &Path) -> Output {
    common::run_in(dir, args, Some(2))
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
fn configuration_errors_name_file_line_column_field_and_quote_the_line() {
    refuses(
        "[ensemble]\nrealizations = \"many\"\n",
        &[
            "c.toml:2:16",
            "field `ensemble.realizations`",
            "expected u64",
            " 2 | realizations = \"many\"",
            "   |                ^^^^^^",
        ],
    );
    refuses(
        "[ensemble]\nrealizations = -1\n",
        &[
            "c.toml:2:16",
            "`ensemble.realizations`",
            "integer `-1`",
            "2 | realizations = -1",
        ],
    );
    refuses(
        "[gps]\nposition_sigma_m = 1.0\nposition_sigma_m = 2.0\n",
        &[
            "c.toml:3:1",
            "`gps.position_sigma_m`",
            "duplicate key",
            "3 | position_sigma_m = 2.0",
        ],
    );
    refuses(
        "\n[gps\nposition_sigma_m = 1.0\n",
        &["c.toml:2:5", "field `gps`", "2 | [gps"],
    );
    // A value out of range is found in the file too.
    refuses(
        "[profile]\nduration_s = 6.0\n[accelerometer]\nnoise_var_m2_s4 = -0.0004\n",
        &[
            "c.toml:4:19",
            "`accelerometer.noise_var_m2_s4` = -0.0004",
            "4 | noise_var_m2_s4 = -0.0004",
        ],
    );
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

#[test]
fn checks_that_cannot_fail_at_ten_realizations_are_untestable_not_passed() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &[
            "ensemble",
            "--truth",
            "euler",
            "--realizations",
            "10",
            "--json",
            "out.json",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("untestable at N = 10, needs N ≥"),
        "{stdout}"
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out.json")).unwrap())
            .unwrap();
    assert_eq!(doc["summary"]["all_passed"], false);
    for c in doc["summary"]["checks"].as_array().unwrap() {
        let untestable = c["verdict"] == "untestable";
        let bounded = c["id"] == "orthogonality" || c["id"] == "residual_whiteness";
        assert_eq!(untestable, bounded, "{c}");
        assert_eq!(c["passed"], c["verdict"] == "pass", "{c}");
        if bounded {
            assert!(c["min_realizations"].as_u64().unwrap() > 10, "{c}");
        }
    }
}

/// Runs `sensitivity` with `extra` arguments and expects exit code 2 naming `field`.
fn sensitivity_refuses(extra: &[&str], field: &str) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("out.json"), "earlier results").unwrap();
    let mut args = vec!["sensitivity", "--json", "out.json", "--quiet"];
    args.extend_from_slice(extra);
    let o = run(&args, dir.path());
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{extra:?}: {msg}");
    assert!(msg.contains(field), "{extra:?}: {msg}");
    assert!(!msg.contains("panicked"), "{msg}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("out.json")).unwrap(),
        "earlier results"
    );
}

#[test]
fn sensitivity_refuses_bad_parameters_and_factors() {
    sensitivity_refuses(&["--parameters", "gps_sigma"], "--parameters");
    sensitivity_refuses(&["--factors", "0.5,0"], "--factors");
    sensitivity_refuses(&["--factors", "-2"], "--factors");
    sensitivity_refuses(&["--factors", "inf"], "--factors");
    sensitivity_refuses(&["--factors", "nan"], "--factors");
    sensitivity_refuses(&["--factors", ""], "--factors");
    sensitivity_refuses(&["--ensembles", "10001"], "--ensembles");
    sensitivity_refuses(&["--draws", "1000001"], "--draws");
}

/// Runs `sensitivity` on a 2 s run of 200 realizations with `extra` arguments and returns its JSON.
fn sensitivity_doc(extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("c.toml"),
        "[profile]\nduration_s = 2.0\n[ensemble]\nrealizations = 200\n",
    )
    .unwrap();
    let mut args = vec![
        "sensitivity",
        "--config",
        "c.toml",
        "--json",
        "s.json",
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let o = run(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap()
}

#[test]
fn sensitivity_writes_the_cases_of_the_data_contract() {
    let doc = sensitivity_doc(&[
        "--parameters",
        "accel_noise_var_m2_s4,bias_var_m2_s4",
        "--factors",
        "0.5,2",
        "--ensembles",
        "2",
    ]);
    let cases = doc["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 4);
    for c in cases {
        for key in [
            "parameter",
            "factor",
            "claimed_sigma_final",
            "actual_sigma_final",
            "expected_nees_final",
            "detection",
            "monte_carlo",
        ] {
            assert!(!c[key].is_null(), "{key} missing: {c}");
        }
        assert_eq!(c["detection"].as_object().unwrap().len(), 7);
        assert_eq!(c["monte_carlo"]["ensembles"], 2);
        assert_eq!(c["monte_carlo"]["realizations"], 200);
        assert_eq!(c["monte_carlo"]["detected"].as_object().unwrap().len(), 7);
        assert_eq!(
            c["detection_method"]["nees"],
            "sampled_sufficient_statistics"
        );
        assert_eq!(c["detection_method"]["residual_whiteness"], "monte_carlo");
    }
}

#[test]
fn sensitivity_without_ensembles_writes_null_measurements() {
    let doc = sensitivity_doc(&[
        "--parameters",
        "gps_position_sigma_m",
        "--factors",
        "0.5",
        "--ensembles",
        "0",
        "--draws",
        "50",
    ]);
    let c = &doc["cases"][0];
    assert!(c["monte_carlo"]["detected"].is_null(), "{c}");
    assert_eq!(c["monte_carlo"]["ensembles"], 0);
    // Nothing measures the residual whiteness; the other checks are sampled.
    assert!(c["detection"]["residual_whiteness"].is_null(), "{c}");
    assert!(c["detection_method"]["residual_whiteness"].is_null(), "{c}");
    assert!(c["detection"]["nees"].is_number(), "{c}");
    assert_eq!(c["detection_draws"], 50);
}

/// `config --model ins` prints the three-axis file, which reads back to its defaults and whose
/// values a bad edit leaves refused with the field named.
#[test]
fn the_three_axis_configuration_is_printed_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let o = common::run_in(dir.path(), &["config", "--model", "ins"], Some(1));
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let parsed = accelcal::config::ins::InsConfig::from_toml_str(&text).unwrap();
    parsed.validate().unwrap();
    assert_eq!(parsed.imu, accelcal::config::ins::ImuConfig::default());
    assert_eq!(parsed.gnss, accelcal::config::ins::GnssConfig::default());
    // The one-axis file is another file.
    let o = common::run_in(dir.path(), &["config"], Some(1));
    assert_ne!(String::from_utf8(o.stdout).unwrap(), text);
    let broken = text.replace("gnss_rate_hz = 1.0", "gnss_rate_hz = 400.0");
    let err = accelcal::config::ins::InsConfig::from_toml_str(&broken)
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(err.to_string().contains("gnss.gnss_rate_hz"), "{err}");
}

/// `simulate --model ins --logs DIR` writes the three-axis logs in the recorded formats; what
/// belongs to the one-axis model, or a GNSS faster than the IMU, is refused with exit code 2 and
/// nothing written.
#[test]
fn three_axis_logs_are_written_and_bad_requests_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("short.toml"), "[drive]\nduration_s = 5.0\n").unwrap();
    let o = common::run_in(
        dir.path(),
        &[
            "simulate",
            "--model",
            "ins",
            "--config",
            "short.toml",
            "--logs",
            "logs",
        ],
        Some(1),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |f: &str| std::fs::read_to_string(dir.path().join("logs").join(f)).unwrap();
    let imu = read("imu.csv");
    assert!(imu.starts_with("t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s\n"));
    assert_eq!(imu.lines().count(), 1 + 1000);
    let gnss = read("gnss.csv");
    assert!(gnss.starts_with("t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s\n"));
    assert_eq!(gnss.lines().count(), 1 + 5);
    assert!(
        read("truth.csv").starts_with("t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s,roll_deg")
    );
    std::fs::write(
        dir.path().join("bad.toml"),
        "[gnss]\ngnss_rate_hz = 400.0\n",
    )
    .unwrap();
    for args in [
        &["simulate", "--model", "ins", "--csv", "x.csv"][..],
        &[
            "simulate", "--model", "ins", "--logs", "new", "--truth", "euler",
        ],
        &[
            "simulate", "--model", "ins", "--logs", "new", "--config", "bad.toml",
        ],
    ] {
        let o = run(args, dir.path());
        let msg = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {msg}");
        assert!(!msg.contains("panicked"), "{msg}");
        assert!(!dir.path().join("new").exists() && !dir.path().join("x.csv").exists());
    }
    let msg = stderr(&run(
        &[
            "simulate", "--model", "ins", "--logs", "new", "--config", "bad.toml",
        ],
        dir.path(),
    ));
    assert!(
        msg.contains("bad.toml:2") && msg.contains("gnss.gnss_rate_hz"),
        "{msg}"
    );
}
