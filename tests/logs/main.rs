//! Calibration from logs: `simulate --logs` then `calibrate` reproduces the in-memory filter bit
//! for bit and an independent processing to 1e-9, with and without jitter; the smoother is never
//! less certain than the filter and its errors match its σ over an ensemble; every bad log is
//! refused with its file and line, exit code 2, and nothing written.

#[path = "../common/mod.rs"]
mod common;

mod bad_logs;
mod between;
mod configuration;
mod diagnostics;
mod drift;
mod fast;
mod prior;
mod reader;
mod recordings;
mod reference;
mod round_trip;
mod smoother;

use std::path::Path;
use std::process::Output;

/// Runs the binary in `dir`.
pub fn run(args: &[&str], dir: &Path) -> Output {
    common::run_in(dir, args, None)
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A CSV file: its header and its rows of numbers.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|f| f.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

/// The column `name` of a CSV file.
pub fn column(csv: &(Vec<String>, Vec<Vec<f64>>), name: &str) -> Vec<f64> {
    let k = csv
        .0
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    csv.1.iter().map(|r| r[k]).collect()
}

/// Simulates realization 0 of the default configuration with the Euler truth into `dir/logs`.
pub fn simulate_logs(dir: &Path) {
    let o = run(&["simulate", "--truth", "euler", "--logs", "logs"], dir);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Writes the configuration `partial` (TOML text) into `dir/name` in full, every key written out:
/// the prior (`[initial]`) and the accelerometer rate of the simulation too, so that `calibrate`
/// takes them from the file and not from the log.
pub fn full_config(dir: &Path, name: &str, partial: &str) {
    let config = accelcal::config::Config::from_toml_str(partial).unwrap();
    std::fs::write(dir.join(name), config.to_toml_string()).unwrap();
}

/// The name of the default configuration in full, written into `dir`.
pub fn default_config(dir: &Path) -> &'static str {
    full_config(dir, "simulation.toml", "");
    "simulation.toml"
}

/// Calibrates `accel` and `gps` into `dir/out`, the estimates at every sample, with the
/// simulation's configuration in full; returns the summary.
pub fn calibrate(dir: &Path, accel: &str, gps: &str, out: &str) -> serde_json::Value {
    calibrate_with(dir, &[], (accel, gps), out).0
}

/// [`calibrate`] with more arguments (`--config FILE`, say; the default configuration in full
/// when none is given); returns the summary and the line the command printed.
pub fn calibrate_with(
    dir: &Path,
    more: &[&str],
    (accel, gps): (&str, &str),
    out: &str,
) -> (serde_json::Value, String) {
    let logs = ["--accel", accel, "--gps", gps, "--out", out];
    let config = if more.contains(&"--config") {
        vec![]
    } else {
        vec!["--config", default_config(dir)]
    };
    let args = [
        &["calibrate"][..],
        &config,
        more,
        &logs,
        &["--quiet", "--every-sample"],
    ]
    .concat();
    let o = run(&args, dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap();
    (
        serde_json::from_str(&text).unwrap(),
        String::from_utf8(o.stdout).unwrap(),
    )
}
