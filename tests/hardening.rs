//! Hostile inputs found by fuzzing the command line: each reproducer must end, within a time
//! limit, with exit code 0 or with exit code 2 and a message naming what is wrong; never a
//! panic, a hang or an exit 0 with non-finite numbers.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a run ended with: its exit code (None when killed at the limit) and its stderr.
struct Ended {
    code: Option<i32>,
    stderr: String,
}

/// Runs the binary with `args` in `dir`, killed when it has not ended within `limit_s` seconds.
fn run_limited(dir: &Path, args: &[&str], limit_s: u64) -> Ended {
    let mut child = Command::new(common::bin())
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > Duration::from_secs(limit_s) {
            child.kill().unwrap();
            child.wait().unwrap();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    Ended { code, stderr }
}

/// Expects `ended` to be a refusal: exit code 2, no panic, every word of `expect` in the message.
fn assert_refused(ended: &Ended, expect: &[&str], what: &str) {
    let msg = &ended.stderr;
    assert_eq!(
        ended.code,
        Some(2),
        "{what}: exit code (None = hung): {msg}"
    );
    assert!(!msg.contains("panicked"), "{what}: {msg}");
    for word in expect {
        assert!(msg.contains(word), "{what}: message lacks {word:?}: {msg}");
    }
}

#[test]
fn false_alarm_rates_below_the_accurate_range_are_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("accel.csv"), "t_s,accel_m_s2\n0,1\n0.01,1\n").unwrap();
    std::fs::write(d.join("gps.csv"), "t_s,position_m,velocity_m_s\n0.01,0,0\n").unwrap();
    for rate in ["5e-324", "1e-16", "1e-300", "9.9e-7"] {
        let toml = format!("[checks]\nfalse_alarm_rate = {rate}\n");
        std::fs::write(d.join("c.toml"), toml).unwrap();
        let commands: [&[&str]; 3] = [
            &["ensemble", "--config", "c.toml", "--realizations", "10"],
            &["report", "--config", "c.toml", "--realizations", "10"],
            &[
                "calibrate",
                "--config",
                "c.toml",
                "--accel",
                "accel.csv",
                "--gps",
                "gps.csv",
            ],
        ];
        for args in commands {
            let ended = run_limited(d, args, 30);
            let what = format!("{} at {rate}", args[0]);
            assert_refused(&ended, &["checks.false_alarm_rate", "[1e-6, 0.5]"], &what);
        }
    }
}

#[test]
fn the_smallest_accepted_false_alarm_rate_runs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("c.toml"),
        "[checks]\nfalse_alarm_rate = 1e-6\n",
    )
    .unwrap();
    let args = ["ensemble", "--config", "c.toml", "--realizations", "20"];
    let args = [&args[..], &["--json", "out.json"]].concat();
    let ended = run_limited(dir.path(), &args, 60);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let json = std::fs::read_to_string(dir.path().join("out.json")).unwrap();
    assert!(!json.contains("NaN") && !json.contains("inf"), "{json}");
}
