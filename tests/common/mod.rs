//! Shared helpers of the integration tests.
#![allow(dead_code)]

pub mod imu;
pub mod partials;
pub mod plain;

use std::path::Path;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

use accelcal::checks::Verdicts;
use accelcal::config::{Config, TruthModel};
use accelcal::filter::FilterSchedule;
use accelcal::model::Model;

/// Model and schedule of `config`.
pub fn model_of(config: &Config) -> (Model, FilterSchedule) {
    let model = Model::new(config).expect("valid configuration");
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
    (model, schedule)
}

/// Runs the ensemble of `config` with `truth` and evaluates its checks.
pub fn verdicts_of(config: &Config, truth: TruthModel) -> Verdicts {
    let (model, schedule) = model_of(config);
    let ensemble = accelcal::ensemble::Ensemble::new(&model, &schedule).with_truth(truth);
    accelcal::study::run_case(&ensemble, &mut accelcal::study::Silent).verdicts
}

/// Path of the built binary.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_accelcal")
}

/// Runs the binary with `args` in `dir`; `threads` sets its thread count when given.
pub fn run_in(dir: &Path, args: &[&str], threads: Option<usize>) -> Output {
    let mut c = Command::new(bin());
    c.args(args).current_dir(dir);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t.to_string());
    }
    c.output().expect("the binary runs")
}

/// The JSON of `path` without its timing fields (`elapsed_s`, `realizations_per_s`).
pub fn summary_without_timing(path: &Path) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("elapsed_s");
                m.remove("realizations_per_s");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    strip(&mut v);
    v
}

/// What a child ended with, measured by [`wait_measured`].
pub struct Measured {
    /// Its exit code: `None` when it was killed at the limit (or ended by a signal).
    pub code: Option<i32>,
    /// Its peak resident memory (the maximum resident set, from `wait4`), bytes.
    pub peak_bytes: f64,
    /// Its stderr, when the caller piped it (empty otherwise).
    pub stderr: String,
}

/// Waits for `child` at most `limit_s` seconds (then kills it), reaping it with `wait4` for
/// its maximum resident set.
pub fn wait_measured(mut child: Child, limit_s: u64) -> Measured {
    let start = Instant::now();
    let pid = child.id() as i32;
    let mut status = 0;
    // SAFETY: rusage is plain data that wait4 fills.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let killed = loop {
        // SAFETY: the pid is our own unwaited child; status and usage are ours to fill.
        let done = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if done == pid {
            // Already reaped by wait4: std's wait finds no child.
            assert!(child.wait().is_err());
            break false;
        }
        assert_eq!(done, 0, "wait4 failed");
        if start.elapsed() > Duration::from_secs(limit_s) {
            child.kill().unwrap();
            child.wait().unwrap();
            break true;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        std::io::Read::read_to_string(&mut e, &mut stderr).unwrap();
    }
    let exited = !killed && libc::WIFEXITED(status);
    Measured {
        code: exited.then(|| libc::WEXITSTATUS(status)),
        // ru_maxrss is in kilobytes on Linux.
        peak_bytes: usage.ru_maxrss as f64 * 1024.0,
        stderr,
    }
}

/// Waits for `child` at most `limit_s` seconds (then kills it: `None`); its status and stderr
/// (piped by the caller).
pub fn wait_limited(mut child: Child, limit_s: u64) -> (Option<ExitStatus>, String) {
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
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
    (status, stderr)
}

/// An observer that keeps every fix of a realization.
pub struct Keep(pub Vec<accelcal::simulation::FixState>);

impl accelcal::simulation::Observer for Keep {
    fn fix(&mut self, f: &accelcal::simulation::FixState) {
        self.0.push(*f);
    }
}

/// What a run ended with: its exit code (None when killed at the limit) and its stderr.
pub struct Ended {
    pub code: Option<i32>,
    pub stderr: String,
}

/// Runs the binary with `args` in `dir` on two threads, killed when it has not ended within
/// `limit_s` seconds.
pub fn run_limited(dir: &Path, args: &[&str], limit_s: u64) -> Ended {
    let child = Command::new(bin())
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let (status, stderr) = wait_limited(child, limit_s);
    Ended {
        code: status.and_then(|s| s.code()),
        stderr,
    }
}

/// Expects `ended` to be a refusal: exit code 2, no panic, every word of `expect` in the message.
pub fn assert_refused(ended: &Ended, expect: &[&str], what: &str) {
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
