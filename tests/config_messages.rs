//! Configuration errors whose words once misled, each from its reproducer: the message must
//! name the right key at the right line, with numbers as they read back, and the commands must
//! agree on what they accept.

use std::path::Path;
use std::process::{Command, Output};

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .expect("the binary runs")
}

/// Runs `ensemble` on the configuration `text` (bytes, written as given) and returns its error
/// message, after checking that it refused with exit code 2 and no panic.
fn refusal(text: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("c.toml"), text).unwrap();
    let out = run(
        dir.path(),
        &[
            "ensemble",
            "-q",
            "--config",
            "c.toml",
            "--realizations",
            "4",
        ],
    );
    let msg = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(!msg.contains("panicked"), "{msg}");
    assert!(msg.contains("c.toml"), "the file is named: {msg}");
    msg
}

#[test]
fn carriage_returns_alone_are_named_and_comments_are_not_fields() {
    let msg = refusal(b"# the number of draws = many\r[ensemble]\rrealizations = 10\r");
    assert!(msg.contains("carriage return"), "{msg}");
    assert!(
        msg.contains("c.toml:1:29"),
        "line 1 ends at column 29: {msg}"
    );
    assert!(!msg.contains("field `"), "no field is named: {msg}");
    // The second line of a CR LF file ended by a lone CR is line 2, quoted without the rest.
    let msg = refusal(b"[ensemble]\r\nrealizations = 10 # x\r\r\n");
    assert!(msg.contains("c.toml:2:22"), "{msg}");
    assert!(!msg.contains('\r'), "the quoted line holds no CR: {msg:?}");
}

#[test]
fn a_date_is_called_a_date() {
    let msg = refusal(b"[ensemble]\nrealizations = 1979-05-27\n");
    assert!(msg.contains("date-time"), "{msg}");
    assert!(!msg.contains("map"), "{msg}");
    assert!(msg.contains("ensemble.realizations"), "{msg}");
}

#[test]
fn a_tiny_gps_rate_is_blamed_on_the_rate_in_short_numbers() {
    let msg = refusal(b"[gps]\nsample_rate_hz = 1e-300\n");
    assert!(msg.contains("`gps.sample_rate_hz` = 1e-300"), "{msg}");
    assert!(msg.contains("c.toml:2:18"), "{msg}");
    assert!(!msg.contains("`profile.duration_s`"), "{msg}");
    assert!(!msg.contains("00000000"), "no 300-digit decimal: {msg}");
    // One fix at 0.05 Hz in 30 s: the rate, with the least that gives two.
    let msg = refusal(b"[gps]\nsample_rate_hz = 0.05\n");
    assert!(msg.contains("`gps.sample_rate_hz` = 0.05"), "{msg}");
    assert!(msg.contains("0.0666"), "{msg}");
    // With a fix at the start, 1/30 Hz gives two fixes and is accepted by the rate check.
    let dir = tempfile::tempdir().unwrap();
    let text = "[gps]\nsample_rate_hz = 0.04\nfix_at_start = true\n";
    std::fs::write(dir.path().join("c.toml"), text).unwrap();
    let out = run(
        dir.path(),
        &[
            "ensemble",
            "-q",
            "--config",
            "c.toml",
            "--realizations",
            "4",
        ],
    );
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(!msg.contains("fewer than 2 fixes"), "{msg}");
}

#[test]
fn numbers_in_range_messages_read_back() {
    let msg = refusal(b"[sensitivity]\nfactors = [-1e-300]\n");
    assert!(msg.contains("= -1e-300"), "{msg}");
    let msg = refusal(b"[profile]\nduration_s = 1e-300\n");
    assert!(!msg.contains("00000000"), "{msg}");
}

#[test]
fn a_tiny_truth_variance_is_blamed_at_its_own_line() {
    let msg = refusal(
        b"[accelerometer]\nnoise_var_m2_s4 = 1e-300\n[filter]\ngps_position_sigma_m = 1.0\n",
    );
    assert!(
        msg.contains("`accelerometer.noise_var_m2_s4` = 1e-300"),
        "{msg}"
    );
    assert!(
        msg.contains("c.toml:2:19"),
        "at its line, not [filter]'s: {msg}"
    );
    assert!(msg.contains("filter.accel_noise_var_m2_s4"), "{msg}");
    assert!(!msg.contains("0.000000"), "{msg}");
}

#[test]
fn an_invisible_character_in_a_value_is_named() {
    let msg = refusal("[gps]\nposition_sigma_m = \u{feff}2.0\n".as_bytes());
    assert!(msg.contains("U+FEFF"), "{msg}");
    assert!(msg.contains("byte order mark"), "{msg}");
    let msg = refusal("[gps]\nposition_sigma_m = 2.0\u{a0}\n".as_bytes());
    assert!(msg.contains("U+00A0"), "{msg}");
    // A byte order mark that starts the file is allowed.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("c.toml"),
        "\u{feff}[ensemble]\nrealizations = 4\n",
    )
    .unwrap();
    let out = run(dir.path(), &["ensemble", "-q", "--config", "c.toml"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
}

#[test]
fn report_accepts_the_filter_values_ensemble_accepts() {
    let dir = tempfile::tempdir().unwrap();
    // The reproducer: 1e6 at the top of the [filter] range, which the sensitivity study's factor
    // 2 on σ takes to 4e6; small sizes keep the report quick.
    let text = "[profile]\nduration_s = 4.0\n[accelerometer]\nsample_rate_hz = 20.0\n\
                [ensemble]\nrealizations = 8\n[filter]\naccel_noise_var_m2_s4 = 1e6\n\
                [sensitivity]\nfactors = [0.5, 2.0]\ndraws = 10\n";
    std::fs::write(dir.path().join("c.toml"), text).unwrap();
    let ensemble = run(dir.path(), &["ensemble", "-q", "--config", "c.toml"]);
    assert_eq!(ensemble.status.code(), Some(0), "{ensemble:?}");
    for args in [
        &["report", "-q", "--config", "c.toml", "--out", "r"][..],
        &["sensitivity", "-q", "--config", "c.toml"][..],
    ] {
        let out = run(dir.path(), args);
        let msg = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {msg}");
    }
}

#[test]
fn configurations_are_read_within_a_bound() {
    let dir = tempfile::tempdir().unwrap();
    let start = std::time::Instant::now();
    let out = run(dir.path(), &["ensemble", "--config", "/dev/zero"]);
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(msg.contains("/dev/zero") && msg.contains("1 MiB"), "{msg}");
    assert!(start.elapsed().as_secs() < 10, "refused at once");
    // A comment longer than the limit in an otherwise valid file.
    let mut text = b"[ensemble]\nrealizations = 4\n#".to_vec();
    text.resize(accelcal::config::MAX_CONFIG_BYTES + 1, b'x');
    std::fs::write(dir.path().join("big.toml"), &text).unwrap();
    let out = run(dir.path(), &["ensemble", "--config", "big.toml"]);
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(msg.contains("big.toml") && msg.contains("1 MiB"), "{msg}");
    // At the limit exactly, it is read.
    text.truncate(accelcal::config::MAX_CONFIG_BYTES);
    std::fs::write(dir.path().join("big.toml"), &text).unwrap();
    let out = run(dir.path(), &["ensemble", "-q", "--config", "big.toml"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    // Not UTF-8.
    std::fs::write(dir.path().join("bin.toml"), [0xff, 0xfe, 0x00]).unwrap();
    let out = run(dir.path(), &["ensemble", "--config", "bin.toml"]);
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(msg.contains("UTF-8"), "{msg}");
}

#[test]
fn a_full_standard_output_is_an_error_not_a_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("skipped: no /dev/full here");
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .args(["ensemble", "-q", "--realizations", "4"])
        .stdout(full)
        .output()
        .unwrap();
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(
        msg.contains("standard output") && !msg.contains("panicked"),
        "{msg}"
    );
}

#[test]
fn small_ensembles_are_not_sampled_beyond_the_samplers_reach() {
    // N = 7, 8 and 9 passed the old guard (N > 6) and panicked in the Wishart draws, which need
    // N ≥ 3·DIM + 1.
    let dir = tempfile::tempdir().unwrap();
    for n in [7, 9, 10] {
        let text = format!(
            "[profile]\nduration_s = 4.0\n[accelerometer]\nsample_rate_hz = 20.0\n\
             [ensemble]\nrealizations = {n}\n[sensitivity]\nfactors = [2.0]\ndraws = 5\n"
        );
        std::fs::write(dir.path().join("c.toml"), text).unwrap();
        let out = run(dir.path(), &["sensitivity", "-q", "--config", "c.toml"]);
        let msg = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "N = {n}: {msg}");
    }
}
