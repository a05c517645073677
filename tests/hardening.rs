//! Hostile inputs found by fuzzing the command line: each reproducer must end, within a time
//! limit, with exit code 0 or with exit code 2 and a message naming what is wrong; never a
//! panic, a hang or an exit 0 with non-finite numbers.

mod common;

use std::path::Path;

use accelcal::input::LogProblem;
use accelcal::input::csv::read::{AccelReader, LogText};
use common::{assert_refused, run_limited};
use std::time::{Duration, Instant};

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

/// Writes the two shard partials `a.bin` and `b.bin` of a 200-realization ensemble into `dir`.
fn two_partials(dir: &Path) {
    for (k, file) in [("1/2", "a.bin"), ("2/2", "b.bin")] {
        let args = ["ensemble", "--realizations", "200", "-q", "--shard", k];
        let args = [&args[..], &["--partial", file]].concat();
        let ended = run_limited(dir, &args, 60);
        assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    }
}

#[test]
fn merge_refuses_headers_that_contradict_themselves() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    // The untouched pair merges (the control).
    let merge = ["merge", "a.bin", "b.bin", "--json", "m.json", "-q"];
    let ended = run_limited(d, &merge, 60);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let cases: [(&str, &str, &[&str]); 3] = [
        // Zero shards divided the blocks by zero.
        (r#""shards":2"#, r#""shards":0"#, &["a.bin", "shard 1/0"]),
        // A configuration edited in every file alike: 75 fixes over sums of 150.
        (
            r#""duration_s":30.0"#,
            r#""duration_s":15.0"#,
            &["a.bin", "75 fixes", "150 fixes"],
        ),
        // More shards than blocks: shard 2/9 of 4 blocks.
        (
            r#""shards":2"#,
            r#""shards":9"#,
            &["a.bin", "shard 1/9", "≤ 4"],
        ),
    ];
    for (from, to, expect) in cases {
        for file in ["a.bin", "b.bin"] {
            std::fs::copy(d.join(file), d.join(format!("edited-{file}"))).unwrap();
            // With the header's digest written anew: the header's own consistency is checked
            // too, for a file whose digest was forged.
            common::partials::edit_header(&d.join(format!("edited-{file}")), from, to, true);
        }
        let args = ["merge", "edited-a.bin", "edited-b.bin", "--json", "e.json"];
        let ended = run_limited(d, &args, 60);
        assert_refused(&ended, expect, &format!("merge with {to}"));
        assert!(
            !d.join("e.json").exists(),
            "a refused merge wrote its output"
        );
    }
}

/// Replaces field `column` (from 0) of line `line` (the header is line 1) of the CSV `path`.
fn edit_csv(path: &Path, line: usize, column: usize, value: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 != line {
                return l.to_string();
            }
            let mut fields: Vec<&str> = l.split(',').collect();
            fields[column] = value;
            fields.join(",")
        })
        .collect();
    std::fs::write(path, edited.join("\n") + "\n").unwrap();
}

#[test]
fn calibrate_refuses_values_that_overflow_and_names_their_row() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The fuzzing reproducer: time stamps ±1e308 hung in the page's axis ticks.
    std::fs::write(d.join("a.csv"), "t_s,accel_m_s2\n-1e308,1\n1e308,1\n").unwrap();
    std::fs::write(d.join("g.csv"), "t_s,position_m,velocity_m_s\n0.01,0,100\n").unwrap();
    let args = [
        "calibrate",
        "--accel",
        "a.csv",
        "--gps",
        "g.csv",
        "--out",
        "o",
    ];
    let ended = run_limited(d, &args, 30);
    assert_refused(
        &ended,
        &["a.csv, line 2", "overflows"],
        "±1e308 time stamps",
    );
    assert!(!d.join("o").exists());
    let ended = run_limited(d, &["simulate", "--logs", "sim", "-q"], 60);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let (accel, gps) = (d.join("sim/accelerometer.csv"), d.join("sim/gps.csv"));
    // (file, line, column, value, the words of the message).
    let cases: [(&Path, usize, usize, &str, &[&str]); 3] = [
        // One GPS position of 1e308 gave exit 0 with a bias of −9.8e303 and NaN in summary.json.
        (
            &gps,
            11,
            1,
            "1e308",
            &["gps.csv, line 11", "position or velocity"],
        ),
        (
            &gps,
            151,
            2,
            "1e308",
            &["gps.csv, line 151", "position or velocity"],
        ),
        // An acceleration of 1e308 overflows at the next fix: the accelerometer is named.
        (
            &accel,
            500,
            1,
            "1e308",
            &["accelerometer.csv, line 482", "gps.csv line 14"],
        ),
    ];
    for (file, line, column, value, expect) in cases {
        let kept = std::fs::read(file).unwrap();
        edit_csv(file, line, column, value);
        let args = [
            "calibrate",
            "--accel",
            "sim/accelerometer.csv",
            "--gps",
            "sim/gps.csv",
        ];
        let args = [&args[..], &["--out", "o"]].concat();
        let ended = run_limited(d, &args, 60);
        assert_refused(&ended, expect, &format!("{value} at line {line}"));
        assert!(
            !d.join("o").exists(),
            "a refused calibration wrote its outputs"
        );
        std::fs::write(file, kept).unwrap();
    }
    // The control: the untouched logs calibrate, every number finite.
    let args = [
        "calibrate",
        "--accel",
        "sim/accelerometer.csv",
        "--gps",
        "sim/gps.csv",
    ];
    let ended = run_limited(d, &[&args[..], &["--out", "o", "-q"]].concat(), 60);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let summary = std::fs::read_to_string(d.join("o/summary.json")).unwrap();
    assert!(
        !summary.contains("null") && !summary.contains("NaN"),
        "{summary}"
    );
}

#[test]
fn a_log_header_of_a_million_columns_is_refused_at_once_in_a_short_message() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let header: Vec<String> = (0..1_000_000).map(|i| format!("c{i}")).collect();
    std::fs::write(d.join("wide.csv"), header.join(",") + "\n0\n").unwrap();
    std::fs::write(d.join("g.csv"), "t_s,position_m,velocity_m_s\n0.01,0,100\n").unwrap();
    let started = Instant::now();
    let args = [
        "calibrate",
        "--accel",
        "wide.csv",
        "--gps",
        "g.csv",
        "--out",
        "o",
    ];
    let ended = run_limited(d, &args, 30);
    assert_refused(&ended, &["wide.csv, line 1", "has no column `t_s`"], "wide");
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "{:?}",
        started.elapsed()
    );
    // It echoed all 6.9 MB of the header.
    assert!(ended.stderr.len() < 1000, "{} bytes", ended.stderr.len());
}

/// A header of `n` columns `c0,c1,…` followed by `last`, and one row.
fn wide(n: usize, last: &str) -> LogText {
    let mut header: Vec<String> = (0..n).map(|i| format!("c{i}")).collect();
    header.push(last.to_string());
    LogText::new("wide.csv", header.join(",") + "\n0\n")
}

/// The problem of opening `src` as an accelerometer log, found within 10 s.
fn problem_within_10_s(src: LogText) -> LogProblem {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(AccelReader::open(&src).err().unwrap().problem));
    rx.recv_timeout(std::time::Duration::from_secs(10))
        .expect("the header checked within 10 s")
}

#[test]
fn a_header_of_a_million_columns_is_checked_at_once_and_quoted_in_short() {
    // A repeated column at the end: every column is compared (it took minutes).
    let problem = problem_within_10_s(wide(1_000_000, "c5"));
    assert_eq!(
        problem,
        LogProblem::DuplicateColumn {
            column: "c5".to_string()
        }
    );
    // No wanted column: the message quotes the header's first characters only.
    let LogProblem::MissingColumn { found, .. } = problem_within_10_s(wide(1_000_000, "x")) else {
        panic!("a missing column")
    };
    assert!(
        found.chars().count() < accelcal::input::MAX_ECHO_CHARS + 40,
        "{found}"
    );
    assert!(found.starts_with("c0,c1,c2,") && found.contains("7888891 characters"));
    // A short header is quoted whole.
    let short = LogText::new("a.csv", "t_s,accel\n0,1\n");
    let Err(e) = AccelReader::open(&short) else {
        panic!("a missing column")
    };
    assert!(matches!(e.problem, LogProblem::MissingColumn { found, .. } if found == "t_s,accel"));
}
