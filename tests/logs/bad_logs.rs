//! Every bad log is refused with exit code 2 and a message naming the file, the line and what
//! was expected; no panic, and the output directory is left as it was.

use std::path::Path;

use crate::{run, stderr};

/// A good accelerometer log: 0 to 2 s at 200 Hz.
fn accel_rows() -> Vec<String> {
    (0..=400)
        .map(|j| format!("{},{}", j as f64 * 0.005, 0.1 + 1e-3 * (j % 7) as f64))
        .collect()
}

/// A good GPS log: fixes at 0.2 s, 0.4 s, … 2 s.
fn gps_rows() -> Vec<String> {
    (1..=10)
        .map(|i| format!("{},{},{}", i as f64 * 0.2, 20.0 * i as f64, 100.0))
        .collect()
}

fn text(header: &str, rows: &[String]) -> String {
    let mut s = format!("{header}\n");
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

/// Calibrates `accel` and `gps` (file contents; `None` leaves the file out) and expects exit code
/// 2, every word of `expect` in the message, and the output directory untouched.
fn refused(accel: Option<&str>, gps: Option<&str>, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    if let Some(a) = accel {
        std::fs::write(d.join("a.csv"), a).unwrap();
    }
    if let Some(g) = gps {
        std::fs::write(d.join("g.csv"), g).unwrap();
    }
    std::fs::create_dir(d.join("out")).unwrap();
    std::fs::write(d.join("out/estimates.csv"), "earlier").unwrap();
    let o = run(
        &[
            "calibrate",
            "--accel",
            "a.csv",
            "--gps",
            "g.csv",
            "--out",
            "out",
        ],
        d,
    );
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{msg}");
    for word in expect {
        assert!(msg.contains(word), "message lacks {word:?}: {msg}");
    }
    assert!(!msg.contains("panicked"), "{msg}");
    untouched(&d.join("out"));
    // Into a directory that does not exist yet: nothing is created.
    let o = run(
        &[
            "calibrate",
            "--accel",
            "a.csv",
            "--gps",
            "g.csv",
            "--out",
            "new",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        !d.join("new").exists(),
        "a failed run created its output directory"
    );
}

fn untouched(out: &Path) {
    let names: Vec<_> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["estimates.csv"], "a failed run left files behind");
    assert_eq!(
        std::fs::read_to_string(out.join("estimates.csv")).unwrap(),
        "earlier"
    );
}

fn accel_with(edit: impl FnOnce(&mut Vec<String>)) -> String {
    let mut rows = accel_rows();
    edit(&mut rows);
    text("t_s,accel_m_s2", &rows)
}

fn gps_with(edit: impl FnOnce(&mut Vec<String>)) -> String {
    let mut rows = gps_rows();
    edit(&mut rows);
    text("t_s,position_m,velocity_m_s", &rows)
}

#[test]
fn good_synthetic_logs_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.csv"), accel_with(|_| {})).unwrap();
    std::fs::write(d.join("g.csv"), gps_with(|_| {})).unwrap();
    let o = run(&["calibrate", "--accel", "a.csv", "--gps", "g.csv"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("bias") && stdout.contains("±"), "{stdout}");
    for f in ["estimates.csv", "summary.json", "index.html"] {
        assert!(d.join("calibration").join(f).exists(), "{f}");
    }
}

#[test]
fn missing_and_empty_files_are_refused() {
    let good_gps = gps_with(|_| {});
    refused(None, Some(&good_gps), &["a.csv", "cannot read"]);
    refused(
        Some(""),
        Some(&good_gps),
        &["a.csv", "empty", "t_s,accel_m_s2"],
    );
    let header_only = text("t_s,accel_m_s2", &accel_rows()[..1]);
    refused(
        Some(&header_only),
        Some(&good_gps),
        &["a.csv", "at least 2"],
    );
    let no_fix = text("t_s,position_m,velocity_m_s", &[]);
    refused(
        Some(&accel_with(|_| {})),
        Some(&no_fix),
        &["g.csv", "at least 1"],
    );
}

#[test]
fn missing_or_misnamed_columns_are_refused() {
    let good_gps = gps_with(|_| {});
    let misnamed = text("t_s,accel", &accel_rows());
    refused(
        Some(&misnamed),
        Some(&good_gps),
        &["a.csv, line 1", "`accel_m_s2`", "t_s,accel"],
    );
    let gps = text("time,position_m,velocity_m_s", &gps_rows());
    refused(
        Some(&accel_with(|_| {})),
        Some(&gps),
        &["g.csv, line 1", "`t_s`"],
    );
    let short = accel_with(|r| r[5] = "0.025".into());
    refused(
        Some(&short),
        Some(&good_gps),
        &["a.csv, line 7", "1 comma-separated", "expected 2"],
    );
}

#[test]
fn non_numbers_and_non_finite_values_are_refused() {
    let good_gps = gps_with(|_| {});
    let word = accel_with(|r| r[3] = "0.015,fast".into());
    refused(
        Some(&word),
        Some(&good_gps),
        &["a.csv, line 5", "`accel_m_s2` = `fast`", "not a number"],
    );
    let nan = accel_with(|r| r[9] = "0.045,NaN".into());
    refused(
        Some(&nan),
        Some(&good_gps),
        &["a.csv, line 11", "not a finite number"],
    );
    let inf = gps_with(|r| r[2] = "0.6,inf,100".into());
    refused(
        Some(&accel_with(|_| {})),
        Some(&inf),
        &["g.csv, line 4", "`position_m` = `inf`"],
    );
}

#[test]
fn time_stamps_must_increase_without_gaps() {
    let good_gps = gps_with(|_| {});
    let repeated = accel_with(|r| r[20] = r[19].clone());
    refused(
        Some(&repeated),
        Some(&good_gps),
        &["a.csv, line 22", "strictly increasing"],
    );
    let backwards = gps_with(|r| r.swap(3, 4));
    refused(
        Some(&accel_with(|_| {})),
        Some(&backwards),
        &["g.csv, line 6", "strictly increasing"],
    );
    // A lost sample: a step of twice the median.
    let gap = accel_with(|r| {
        r.remove(100);
    });
    refused(
        Some(&gap),
        Some(&good_gps),
        &[
            "a.csv, line 102",
            "from 0.495 s to 0.505 s is 0.01 s",
            "2.000 times the median",
            "between 0.5 and 1.5",
        ],
    );
}

#[test]
fn fixes_outside_the_log_are_refused_and_between_samples_taken() {
    let accel = accel_with(|_| {});
    let late = gps_with(|r| r.push("2.5,200,100".into()));
    refused(
        Some(&accel),
        Some(&late),
        &["g.csv, line 12", "2.5 s", "outside", "0 s to 2 s"],
    );
    let early = gps_with(|r| r.insert(0, "-0.1,0,100".into()));
    refused(Some(&accel), Some(&early), &["g.csv, line 2", "outside"]);
    // A fix on the last sample and one after it (within half a step) are both applied at it.
    let twice = gps_with(|r| r.push("2.001,200,100".into()));
    refused(
        Some(&accel),
        Some(&twice),
        &["g.csv, line 12", "line 11 already takes"],
    );
    // A fix in the middle of a step of 1.4 median steps, and two fixes in one step, are
    // applied at their own times.
    let stretched = accel_with(|r| {
        for (j, row) in r.iter_mut().enumerate().skip(201) {
            *row = format!("{:.3},0.1", j as f64 * 0.005 + 0.002);
        }
    });
    let between = gps_with(|r| r[4] = "1.0035,100,100".into());
    let two = gps_with(|r| r.insert(5, "1.001,100,100".into()));
    for (a, g) in [(&stretched, &between), (&accel, &two)] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.csv"), a).unwrap();
        std::fs::write(d.join("g.csv"), g).unwrap();
        let args = ["calibrate", "--accel", "a.csv", "--gps", "g.csv", "-q"];
        let o = run(&args, d);
        assert!(o.status.success(), "{}", stderr(&o));
    }
}
