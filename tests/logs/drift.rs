//! Calibration with a drifting bias: the filter and the smoother of `calibrate` against the
//! independent per-sample processing (the bias's φ and q_b at every step, Rauch–Tung–Striebel
//! over every sample) for a random walk and a Gauss–Markov bias, nominal and jittered; the NIS
//! test of a simulated random-walk log passes with the matching filter and fails with a
//! constant-bias one.

use std::path::Path;

use crate::reference::{AccelLog, Drift, GpsLog, Prior, Processed, process};
use crate::{column, read_csv, run, stderr};

/// K of the simulated random walk, m/s² per √s: over the 60 s run the drift's σ is
/// K·√60 = 0.31 m/s², 3.1 times the prior bias σ (0.1 m/s²).
const K_M_S2_PER_SQRT_S: f64 = 0.04;

/// The truth of every log here: 60 s, a random-walk bias.
const TRUTH: &str = "[profile]\nduration_s = 60.0\n\n[accelerometer]\nbias_model = \
                     \"random_walk\"\nbias_random_walk_m_s2_per_sqrt_s = 0.04\n";

/// Writes `name` = the truth with the `[filter]` section `filter`.
fn config(dir: &Path, name: &str, filter: &str) {
    crate::full_config(dir, name, &format!("{TRUTH}\n[filter]\n{filter}"));
}

/// Simulates realization `l` of the random-walk truth into `dir/logs-l`.
fn simulate(dir: &Path, l: u64) -> String {
    config(dir, "truth.toml", "");
    let logs = format!("logs-{l}");
    let l = l.to_string();
    let args = [
        "simulate",
        "--config",
        "truth.toml",
        "--truth",
        "euler",
        "--realization",
        &l,
        "--logs",
        &logs,
        "-q",
    ];
    let o = run(&args, dir);
    assert!(o.status.success(), "{}", stderr(&o));
    logs
}

/// Calibrates `accel` and `logs/gps.csv` with `config` into `out`; returns the summary.
fn calibrate(dir: &Path, config: &str, logs: (&str, &str), out: &str) -> serde_json::Value {
    calibrate_printed(dir, config, logs, out).0
}

/// [`calibrate`], with the line the command printed.
fn calibrate_printed(
    dir: &Path,
    config: &str,
    logs: (&str, &str),
    out: &str,
) -> (serde_json::Value, String) {
    super::calibrate_with(dir, &["--config", config], logs, out)
}

/// The printed line places the NIS sum against its band in words that agree with the verdict:
/// "pass (sum … in [" or "fail (sum … below [" / "above [" (it said "in" for a failing sum).
fn assert_nis_words(summary: &serde_json::Value, printed: &str) {
    let n = &summary["nis"];
    let sum = n["sum"].as_f64().unwrap();
    let place = if n["verdict"] == "pass" {
        "in"
    } else if sum < n["lower"].as_f64().unwrap() {
        "below"
    } else {
        "above"
    };
    let verdict = n["verdict"].as_str().unwrap();
    let words = format!("NIS test {verdict} (sum ");
    let at = printed.find(&words).unwrap_or_else(|| panic!("{printed}"));
    let rest = &printed[at + words.len()..];
    let after_sum = &rest[rest.find(' ').unwrap() + 1..];
    assert!(after_sum.starts_with(&format!("{place} [")), "{printed}");
}

/// The largest |library − reference| / σ_reference over every sample and state of the filtered
/// and smoothed estimates and of their σ.
fn worst(dir: &Path, out: &str, reference: &Processed) -> [f64; 4] {
    let est = read_csv(&dir.join(out).join("estimates.csv"));
    let mut worst = [0.0f64; 4];
    for (k, (name, unit)) in [("dp", "m"), ("dv", "m_s"), ("bias", "m_s2")]
        .into_iter()
        .enumerate()
    {
        let col = |what: &str| column(&est, &format!("{what}_{unit}"));
        let (x, s) = (
            col(&format!("{name}_filtered")),
            col(&format!("sigma_{name}_filtered")),
        );
        let (xs, ss) = (
            col(&format!("{name}_smoothed")),
            col(&format!("sigma_{name}_smoothed")),
        );
        assert_eq!(x.len(), reference.x.len());
        for j in 0..x.len() {
            let (sf, sm) = (reference.p[j][k][k].sqrt(), reference.ps[j][k][k].sqrt());
            let d = [
                (x[j] - reference.x[j][k]).abs() / sf,
                (s[j] - sf).abs() / sf,
                (xs[j] - reference.xs[j][k]).abs() / sm,
                (ss[j] - sm).abs() / sm,
            ];
            for (w, d) in worst.iter_mut().zip(d) {
                *w = w.max(d);
            }
        }
    }
    worst
}

/// Every time stamp of `accel` moved by up to ±0.2 ms (per-step mode); the fixes keep theirs.
fn jitter(dir: &Path, logs: &str) -> String {
    let (accel, _) = logs_of(dir, logs, "accelerometer.csv");
    let mut text = String::from("t_s,accel_m_s2\n");
    for (j, (t, a)) in accel.iter().enumerate() {
        let u = ((j as f64 * 12.9898).sin() * 43758.5453).fract();
        text.push_str(&format!("{},{a}\n", t + 2e-4 * u));
    }
    let name = format!("{logs}/jittered.csv");
    std::fs::write(dir.join(&name), text).unwrap();
    name
}

/// The accelerometer log `accel` and the GPS log of the directory `logs` as plain rows.
fn logs_of(dir: &Path, logs: &str, accel: &str) -> (AccelLog, GpsLog) {
    let a = read_csv(&dir.join(logs).join(accel));
    let g = read_csv(&dir.join(logs).join("gps.csv"));
    (
        a.1.iter().map(|r| (r[0], r[1])).collect(),
        g.1.iter().map(|r| (r[0], r[1], r[2])).collect(),
    )
}

/// The filter and the smoother against the per-sample processing written plainly, for both
/// drifting models, nominal and jittered: every sample's filtered and smoothed estimate within
/// 10⁻⁹ of its σ, and every σ within a relative 10⁻⁹. Negative control: the same processing
/// with a constant bias is far from the library's drifting filter.
#[test]
fn drifting_filter_and_smoother_agree_with_the_per_sample_processing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let logs = simulate(d, 0);
    let jittered = jitter(d, &logs);
    let cases = [
        (
            "rw.toml",
            "bias_random_walk_m_s2_per_sqrt_s = 0.04\n",
            Drift::RandomWalk(K_M_S2_PER_SQRT_S),
        ),
        (
            "gm.toml",
            "bias_model = \"gauss_markov\"\nbias_correlation_time_s = 30.0\n",
            Drift::GaussMarkov(30.0),
        ),
    ];
    let gps = format!("{logs}/gps.csv");
    for (name, filter, drift) in cases {
        config(d, name, filter);
        for (accel, mode) in [
            (format!("{logs}/accelerometer.csv"), "nominal"),
            (jittered.clone(), "per_step"),
        ] {
            let out = format!("{name}-{mode}");
            let summary = calibrate(d, name, (&accel, &gps), &out);
            assert_eq!(summary["dt_mode"], mode);
            let file = accel.rsplit('/').next().unwrap();
            let (a, g) = logs_of(d, &logs, file);
            let prior = Prior {
                drift,
                ..Prior::default_config()
            };
            let w = worst(d, &out, &process(&a, &g, &prior));
            eprintln!("{name} {mode}: worst |Δ|/σ filtered, σ, smoothed, σ^s: {w:?}");
            assert!(w.iter().all(|&w| w < 1e-9), "{name} {mode}: {w:?}");
            let constant = worst(d, &out, &process(&a, &g, &Prior::default_config()));
            assert!(constant[2] > 1e-3, "{name} {mode}: control {constant:?}");
            // The end of the log: smoothed = filtered, the summary's and the last row's.
            assert_eq!(summary["end_smoothed"], summary["end_estimate"]);
            assert_eq!(summary["filter"]["bias_model"], drift_name(drift));
        }
    }
}

fn drift_name(drift: Drift) -> &'static str {
    match drift {
        Drift::None => "constant",
        Drift::RandomWalk(_) => "random_walk",
        Drift::GaussMarkov(_) => "gauss_markov",
    }
}

/// Realizations of the NIS test below.
const SEEDS: u64 = 5;

/// The NIS test (two-sided, α = `checks.false_alarm_rate` = 0.01) of a simulated random-walk
/// log: with the matching filter a consistent filter fails it with probability α per log, so
/// of 5 independent realizations 2 or more fail with probability
/// 1 − 0.99⁵ − 5·0.01·0.99⁴ < 10⁻³: at most one may fail, whichever 5 realizations are taken.
/// With a constant-bias filter (negative control) every one must fail. The truth's bias path in
/// `truth.csv` is a random walk of K: Σ(Δb)²/(K²·T) over 12 000 steps is 1 within 5 of its σ
/// √(2/12 000) per log.
#[test]
fn a_random_walk_log_passes_the_nis_test_with_the_matching_filter_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    config(d, "constant.toml", "bias_model = \"constant\"\n");
    let (mut failed, mut control_failed) = (0, 0);
    for l in 0..SEEDS {
        let logs = simulate(d, l);
        let truth = read_csv(&d.join(&logs).join("truth.csv"));
        let (t, b) = (column(&truth, "t_s"), column(&truth, "bias_m_s2"));
        let squares: f64 = b.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
        let ratio = squares / (K_M_S2_PER_SQRT_S.powi(2) * (t[t.len() - 1] - t[0]));
        let steps = (b.len() - 1) as f64;
        assert!(
            (ratio - 1.0).abs() < 5.0 * (2.0 / steps).sqrt(),
            "{logs}: {ratio}"
        );
        let accel = format!("{logs}/accelerometer.csv");
        let gps = format!("{logs}/gps.csv");
        let (matching, printed) =
            calibrate_printed(d, "truth.toml", (&accel, &gps), &format!("rw-{l}"));
        assert_nis_words(&matching, &printed);
        let (constant, printed) =
            calibrate_printed(d, "constant.toml", (&accel, &gps), &format!("const-{l}"));
        assert_nis_words(&constant, &printed);
        assert_eq!(matching["filter"]["bias_model"], "random_walk");
        assert_eq!(
            matching["filter"]["bias_random_walk_m_s2_per_sqrt_s"],
            K_M_S2_PER_SQRT_S
        );
        assert_eq!(constant["filter"]["bias_model"], "constant");
        let nis = |s: &serde_json::Value| {
            let n = &s["nis"];
            (n["sum"].as_f64().unwrap(), n["verdict"].clone())
        };
        eprintln!(
            "{logs}: NIS random walk {:?}, constant {:?}",
            nis(&matching),
            nis(&constant)
        );
        failed += usize::from(matching["nis"]["verdict"] != "pass");
        control_failed += usize::from(constant["nis"]["verdict"] != "pass");
        // The smoothed bias at the start against the truth's b(0), within 4.5σ (a false alarm
        // has probability below 10⁻⁵ a log).
        let start = &matching["start_smoothed"];
        let z = (start["bias_m_s2"].as_f64().unwrap() - b[0])
            / start["sigma_bias_m_s2"].as_f64().unwrap();
        assert!(z.abs() < 4.5, "{logs}: start bias z = {z}");
    }
    assert!(
        failed <= 1,
        "{failed} of {SEEDS} matching filters failed the NIS test"
    );
    assert_eq!(
        control_failed, SEEDS as usize,
        "the constant-bias filter passed"
    );
}
