//! The diagnostics of a calibration: the whiteness test rejects white innovations at its stated
//! rate (synthetic sequences and simulated logs, each count inside its binomial band) and flags
//! correlated ones (negative controls: an AR(1) sequence, a GPS position error that is AR(1));
//! the other tests of a consistent filter reject no more often than their rates allow.

use accelcal::calibrate::diagnose::{Diagnostics, whiteness};
use accelcal::calibrate::summary::Calibration;
use accelcal::calibrate::{Settings, prepare};
use accelcal::config::{Config, TruthModel};
use accelcal::input::csv::read::LogText;
use accelcal::logs::write::LogWriter;
use accelcal::random::Stream;
use accelcal::simulation::run_realization;
use statrs::distribution::{Binomial, DiscreteCDF};

use crate::common;

/// The rate at which each binomial band below may fail a correct implementation: two-sided,
/// half in each tail.
const BAND_RATE: f64 = 1e-3;

/// The two-sided band [lo, hi] of K ~ Binomial(`trials`, `p`) at [`BAND_RATE`]: P(K < lo) and
/// P(K > hi) are each at most half of it.
fn binomial_band(trials: u64, p: f64) -> (u64, u64) {
    let b = Binomial::new(p, trials).unwrap();
    let lo = (0..=trials)
        .take_while(|&k| k == 0 || b.cdf(k - 1) <= BAND_RATE / 2.0)
        .last()
        .unwrap();
    let hi = (0..=trials).find(|&k| b.sf(k) <= BAND_RATE / 2.0).unwrap();
    (lo, hi)
}

/// `count` rejections of `trials` at rate `p` lie in their band.
fn assert_in_band(what: &str, count: u64, trials: u64, p: f64) {
    let (lo, hi) = binomial_band(trials, p);
    eprintln!("{what}: {count} of {trials} rejected, band [{lo}, {hi}] at rate {p}");
    assert!(
        (lo..=hi).contains(&count),
        "{what}: {count} of {trials} rejected at rate {p}: outside [{lo}, {hi}]"
    );
}

/// `n` values of an AR(1) sequence u_i = φ·u_{i−1} + √(1 − φ²)·w_i from stream `s`, stationary
/// N(0, 1) from its first value (φ = 0: white).
fn ar1(s: &mut Stream, n: usize, phi: f64) -> Vec<f64> {
    let mut u = s.normal();
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(u);
        u = phi * u + (1.0 - phi * phi).sqrt() * s.normal();
    }
    out
}

#[test]
fn whiteness_rejects_white_sequences_at_its_rate_and_flags_correlated_ones() {
    let rate = 0.01;
    let sequences = 4000;
    for (key, n) in [(1, 150), (2, 600)] {
        let mut white = 0;
        let mut correlated = 0;
        for l in 0..sequences {
            let mut s = Stream::new(key, l);
            if whiteness(&ar1(&mut s, n, 0.0), rate).verdict == "fail" {
                white += 1;
            }
            if l < 400 && whiteness(&ar1(&mut s, n, 0.5), rate).verdict == "fail" {
                correlated += 1;
            }
        }
        assert_in_band(&format!("white, n = {n}"), white, sequences, rate);
        // Negative control: ρ(1) = 0.5 is 6 σ of ρ̂(1) at n = 150.
        eprintln!("AR(1) φ = 0.5, n = {n}: {correlated} of 400 rejected");
        assert!(
            correlated >= 396,
            "{correlated} of 400 AR(1) sequences flagged"
        );
    }
}

/// The diagnostics of realization `l` of `config`'s simulation, its GPS position error
/// replaced by an AR(1) error of the same σ and correlation φ per fix when `phi` is given.
fn diagnose_simulated(config: &Config, l: u64, phi: Option<f64>) -> Diagnostics {
    calibrate_simulated(config, l, phi).summary.diagnostics
}

/// The calibration of [`diagnose_simulated`].
fn calibrate_simulated(config: &Config, l: u64, phi: Option<f64>) -> Calibration {
    let (model, schedule) = common::model_of(config);
    let settings = Settings::from_model(&model);
    let (mut accel, mut gps, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    let mut writer = LogWriter::new(&model.timeline, &mut accel, &mut gps, &mut truth).unwrap();
    run_realization(&model, &schedule, config.ensemble.seed, l, &mut writer);
    writer.finish().unwrap();
    if let Some(phi) = phi {
        gps = correlated_position(&gps, &truth, phi, config.gps.position_sigma_m, l);
    }
    let (accel, gps) = (LogText::new("a.csv", accel), LogText::new("g.csv", gps));
    let prepared = prepare(&accel, &gps, &settings).unwrap();
    prepared.calibration()
}

/// The GPS log `gps` with each position the truth's (from `truth`, at the same time stamp)
/// plus an AR(1) error of σ `sigma_m` and correlation `phi` from fix to fix.
fn correlated_position(gps: &[u8], truth: &[u8], phi: f64, sigma_m: f64, l: u64) -> Vec<u8> {
    let rows = |bytes: &[u8]| -> Vec<Vec<String>> {
        std::str::from_utf8(bytes)
            .unwrap()
            .lines()
            .skip(1)
            .map(|r| r.split(',').map(String::from).collect())
            .collect()
    };
    let truth: std::collections::HashMap<String, String> = rows(truth)
        .into_iter()
        .map(|r| (r[0].clone(), r[1].clone()))
        .collect();
    let fixes = rows(gps);
    let error = ar1(&mut Stream::new(77, l), fixes.len(), phi);
    let mut out = String::from("t_s,position_m,velocity_m_s\n");
    for (r, e) in fixes.iter().zip(error) {
        let p: f64 = truth[&r[0]].parse().unwrap();
        out.push_str(&format!("{},{},{}\n", r[0], p + sigma_m * e, r[2]));
    }
    out.into_bytes()
}

#[test]
fn diagnostics_of_simulated_logs_reject_at_their_rates() {
    let mut config = Config::default();
    config.ensemble.truth = TruthModel::Euler;
    let logs = 1500u64;
    // Per measurement: whiteness and mean square at α/M each; per log: per-fix count, bias.
    let (mut white, mut square, mut per_fix, mut bias) = (0, 0, 0, 0);
    let mut alpha = 0.0;
    for l in 0..logs {
        let d = diagnose_simulated(&config, l, None);
        alpha = d.false_alarm_rate;
        for m in &d.measurements {
            white += u64::from(m.whiteness.verdict == "fail");
            square += u64::from(m.mean_square_place != "in");
        }
        per_fix += u64::from(d.nis_per_fix.verdict == "fail");
        bias += u64::from(d.bias.verdict == "fail");
    }
    let members = 2 * logs;
    assert_in_band("whiteness", white, members, alpha / 2.0);
    assert_in_band("mean square", square, members, alpha / 2.0);
    // The per-fix count's bound and the bias's Bonferroni bound hold at most α: one-sided.
    let (_, hi) = binomial_band(logs, alpha);
    eprintln!("per-fix NIS count: {per_fix}, bias: {bias} of {logs} rejected, at most {hi}");
    assert!(per_fix <= hi && bias <= hi, "{per_fix}, {bias} > {hi}");
}

#[test]
fn a_correlated_gps_position_error_is_flagged() {
    let mut config = Config::default();
    config.ensemble.truth = TruthModel::Euler;
    // A position error with a 2 s correlation time at 5 Hz: φ = e^(−0.2/2) per fix.
    let phi = (-0.1f64).exp();
    let logs = 50;
    let mut flagged = 0;
    let mut words = 0;
    for l in 0..logs {
        let d = diagnose_simulated(&config, l, Some(phi));
        let position = &d.measurements[0];
        assert_eq!(position.measurement, "position");
        flagged += u64::from(position.whiteness.verdict == "fail");
        words += u64::from(
            d.findings
                .iter()
                .any(|s| s.contains("the GPS position errors are not white at 5 Hz")),
        );
    }
    eprintln!("AR(1) GPS position error: {flagged} of {logs} logs flagged, {words} say so");
    assert!(flagged >= logs - 2, "{flagged} of {logs}");
    assert_eq!(words, flagged);
}

#[test]
fn the_page_and_the_summary_show_the_diagnosis() {
    let mut config = Config::default();
    config.ensemble.truth = TruthModel::Euler;
    let cal = calibrate_simulated(&config, 0, Some((-0.1f64).exp()));
    let html = accelcal::report::calibration::render(&cal, "accelcal calibrate", false).unwrap();
    for id in [
        "id=\"diagnosis\"",
        "id=\"fig-autocorrelation\"",
        "id=\"fig-bias-departure\"",
    ] {
        assert!(html.contains(id), "the page has no {id}");
    }
    let d = &cal.summary.diagnostics;
    let sentence = d
        .findings
        .iter()
        .find(|s| s.contains("position innovations are correlated"))
        .expect("the sentence on the position innovations");
    let escaped = sentence.replace('"', "&quot;").replace('\'', "&#x27;");
    assert!(
        html.contains(sentence.as_str()) || html.contains(&escaped),
        "the page does not say: {sentence}"
    );
    // summary.json: the existing fields in their order, then `diagnostics`.
    let json = cal.summary.to_json();
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    let keys: Vec<&String> = value.as_object().unwrap().keys().collect();
    let at = |k: &str| json.find(&format!("\n  \"{k}\"")).unwrap();
    assert!(at("nis") < at("filter") && at("filter") < at("warnings"));
    assert!(at("warnings") < at("diagnostics"), "{keys:?}");
    let m = &value["diagnostics"]["measurements"][0];
    for field in ["whiteness", "mean_square", "mean_square_band", "gps_share"] {
        assert!(
            !m[field].is_null(),
            "no diagnostics.measurements[0].{field}"
        );
    }
    let w = &m["whiteness"];
    assert_eq!(w["verdict"], "fail");
    assert_eq!(w["max_lag"], 15);
    assert_eq!(w["autocorrelation"].as_array().unwrap().len(), 15);
    assert!(!value["diagnostics"]["nis_per_fix"]["outside_t_s"].is_null());
    assert!(!value["diagnostics"]["bias"]["departure_bound_sigmas"].is_null());
}
