//! A one-axis calibration's time grows linearly with the number of GPS fixes: a fix at every
//! 200 Hz sample, all at one position, as a day of 10 Hz fixes (864 000) would be. The
//! bias's robust interval once summed its Bartlett kernel lag by lag over a fifth of the fixes,
//! which made the run quadratic (50 000 fixes 0.8 s, 200 000 8.7 s, a million beyond 120 s).

mod common;

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// Writes `n` accelerometer samples at 200 Hz and a fix at every one, all at rest at 0.
fn write_logs(dir: &Path, n: usize) {
    let (mut accel, mut gps) = (
        String::from("t_s,accel_m_s2\n"),
        String::from("t_s,position_m,velocity_m_s\n"),
    );
    for i in 0..n {
        let t = i as f64 * 0.005;
        writeln!(accel, "{t},0").unwrap();
        writeln!(gps, "{t},0,0").unwrap();
    }
    std::fs::write(dir.join("accel.csv"), accel).unwrap();
    std::fs::write(dir.join("gps.csv"), gps).unwrap();
}

/// One calibration of the logs in `dir`: its wall time, s, and its peak resident memory (the
/// child's maximum resident set, from `wait4`), bytes. It must end within `limit_s` with exit
/// code 0.
fn calibrate(dir: &Path, limit_s: u64) -> (f64, f64) {
    let start = Instant::now();
    let child = Command::new(common::bin())
        .args(["calibrate", "--accel", "accel.csv", "--gps", "gps.csv"])
        .args(["--out", "out", "-q"])
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let ended = common::wait_measured(child, limit_s);
    let elapsed = start.elapsed().as_secs_f64();
    match ended.code {
        Some(0) => (elapsed, ended.peak_bytes),
        Some(code) => panic!("{}: exit {code}: {}", dir.display(), ended.stderr),
        None => panic!("{}: not done within {limit_s} s", dir.display()),
    }
}

#[test]
fn calibrate_time_is_linear_in_the_fixes() {
    // 80 000 and 320 000 fixes (both above the fixes the figures draw whole): linear is a ratio near 4 (the old code's was 10, quadratic
    // 16); the bound 8 leaves room for a loaded machine. The fastest of three runs each,
    // interleaved, so that a busy moment does not fall on one size only.
    let n = 80_000;
    let (small, large) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    write_logs(small.path(), n);
    write_logs(large.path(), 4 * n);
    let (mut t_small, mut t_large) = (f64::INFINITY, f64::INFINITY);
    let (mut m_small, mut m_large) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        let (t, m) = calibrate(small.path(), 60);
        (t_small, m_small) = (t_small.min(t), m_small.min(m));
        let (t, m) = calibrate(large.path(), 120);
        (t_large, m_large) = (t_large.min(t), m_large.min(m));
    }
    let ratio = t_large / t_small;
    assert!(
        ratio < 8.0,
        "{n} fixes {t_small:.2} s, {} fixes {t_large:.2} s: ratio {ratio:.1}, not linear",
        4 * n
    );
    // Memory: a million fixes within 512 MB is at most 512 bytes a fix over what the run holds
    // without them. Measured: 80 000 fixes 55 MB, 320 000 163 MB, 452 bytes a fix, a million
    // 470 MB (projected 471); the calibration that held every record whole took 958 MB for a
    // million, over 900 bytes a fix, which this fails.
    let per_fix = (m_large - m_small) / (3 * n) as f64;
    let million = m_large + per_fix * (1e6 - (4 * n) as f64);
    assert!(
        per_fix < 512.0 && million < 512e6,
        "{n} fixes {:.0} MB, {} fixes {:.0} MB: {per_fix:.0} bytes a fix, a million fixes \
         {:.0} MB",
        m_small / 1e6,
        4 * n,
        m_large / 1e6,
        million / 1e6
    );
    // Every fix has its row.
    let rows = std::fs::read_to_string(large.path().join("out/estimates.csv"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(rows, 4 * n + 1);
}
