//! `calibrate --imu --estimate-noise`'s profile-likelihood intervals cover the truth: over 200
//! simulated recordings of the three-axis drive, each key's 95 % interval holds its true value a
//! number of times inside the binomial band at α = 1 % (split over the keys); the same intervals
//! at half their width (the control) fall below it.

mod common;

use accelcal::calibrate::imu::noise::{ImuKey, estimate};
use accelcal::config::ins::InsConfig;
use accelcal::input::csv::read::LogText;
use accelcal::input::gnss_csv::read_gnss;
use accelcal::input::imu_csv::read_steps;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;
use common::imu::{band, settings_of};
use rayon::prelude::*;

/// The recordings.
const RECORDINGS: u64 = 200;
/// The study-wide false-alarm rate, split over the keys.
const FALSE_ALARM: f64 = 0.01;
/// The keys estimated.
const KEYS: [ImuKey; 3] = [
    ImuKey::GnssHorizontalSigma,
    ImuKey::GnssVelocitySigma,
    ImuKey::GnssTimeOffset,
];

/// Per key: whether the interval held the truth, and whether its half-width version did.
fn covered(scenario: &Scenario, index: u64) -> Vec<(bool, bool)> {
    let truth = settings_of(scenario);
    let (mut imu, mut gnss, mut t) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(scenario, index, &mut imu, &mut gnss, &mut t).expect("in memory");
    let rows = read_gnss(&LogText::new("gnss.csv", gnss)).expect("reads");
    let (steps, span, _) = read_steps(&LogText::new("imu.csv", imu), truth.axes).expect("reads");
    // The search starts away from the truth: the σ's doubled and halved, 50 ms of offset.
    let mut start = truth;
    start.gnss_position_sigma_m[0] *= 2.0;
    start.gnss_position_sigma_m[1] *= 2.0;
    start.gnss_velocity_sigma_m_s *= 0.5;
    start.gnss_time_offset_s = 0.05;
    let e = estimate(&rows, &steps, &span, &start, &KEYS, 0.95).expect("finite");
    KEYS.iter()
        .zip(&e.keys)
        .map(|(k, got)| {
            let value = k.get(&truth);
            let (lo, hi) = (
                got.lower.unwrap_or(f64::NEG_INFINITY),
                got.upper.unwrap_or(f64::INFINITY),
            );
            let half = (
                got.value - 0.5 * (got.value - lo),
                got.value + 0.5 * (hi - got.value),
            );
            (
                lo <= value && value <= hi,
                half.0 <= value && value <= half.1,
            )
        })
        .collect()
}

#[test]
fn noise_intervals_cover_the_truth_over_many_recordings() {
    let mut config = InsConfig::default();
    config.drive.duration_s = 240.0;
    config.imu.imu_rate_hz = 100.0;
    let scenario = Scenario::from_config(&config).expect("valid");
    let started = std::time::Instant::now();
    let all: Vec<Vec<(bool, bool)>> = (0..RECORDINGS)
        .into_par_iter()
        .map(|i| covered(&scenario, 1000 + i))
        .collect();
    let (lo, hi) = band(RECORDINGS, 0.95, FALSE_ALARM / KEYS.len() as f64);
    eprintln!(
        "{RECORDINGS} recordings in {:.1} s; band [{lo}, {hi}]",
        started.elapsed().as_secs_f64()
    );
    for (j, k) in KEYS.iter().enumerate() {
        let n = all.iter().filter(|c| c[j].0).count() as u64;
        let half = all.iter().filter(|c| c[j].1).count() as u64;
        eprintln!("{}: {n}/{RECORDINGS} covered, half-width {half}", k.name());
        assert!(
            (lo..=hi).contains(&n),
            "{}: {n} outside [{lo}, {hi}]",
            k.name()
        );
        assert!(
            half < lo,
            "{}: the half-width control {half} inside the band",
            k.name()
        );
    }
}
