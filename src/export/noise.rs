//! The `noise_statistics` record of `data.json`: `calibrate --estimate-noise` on simulated drives
//! (every drive's estimates, the coverage of each statistic) and the white noise's
//! identifiability on two drives.

use serde::Serialize;

use crate::likelihood::KeyEstimate;
use crate::study::identify::{WhiteNoiseDrive, WhiteNoiseDrives};
use crate::study::noise::{KeyCoverage, NOISE_FALSE_ALARM_RATE, NOISE_START_FACTOR, NoiseStudy};

/// One statistic over the drives.
#[derive(Serialize)]
pub struct KeyRecord<'a> {
    /// The `[filter]` key.
    key: &'static str,
    /// Its true value.
    truth: f64,
    /// Drives on which it was identifiable.
    identifiable_drives: u64,
    /// Of those, intervals that covered the truth.
    covered: u64,
    /// The binomial band of `covered` at the false-alarm rate, both ends accepted.
    band: [u64; 2],
    /// Whether `covered` lies in the band.
    coverage_holds: bool,
    /// Intervals of half the width that covered: the negative control.
    half_width_covered: u64,
    /// Whether the negative control's count lies in the band (it should not).
    half_width_holds: bool,
    /// The median of estimate / truth over the identifiable drives.
    median_ratio: f64,
    /// Every drive's estimate, by index: value, lower (0 = open), upper (null = open),
    /// identifiable, search bounds.
    estimates: Vec<&'a KeyEstimate>,
}

/// One drive with the white-noise variance W estimated.
#[derive(Serialize)]
pub struct WhiteNoiseRecord<'a> {
    /// Length, s.
    duration_s: f64,
    /// GPS rate, Hz.
    gps_rate_hz: f64,
    /// The true W, (m/s²)².
    accel_noise_var_m2_s4: f64,
    /// The estimate of W.
    estimate: &'a KeyEstimate,
}

/// The record.
#[derive(Serialize)]
pub struct NoiseRecord<'a> {
    /// Drives simulated.
    drives: u64,
    /// Length of each, s.
    duration_s: f64,
    /// The intervals' confidence.
    confidence: f64,
    /// The false-alarm rate of the coverage bands.
    false_alarm_rate: f64,
    /// Every searched statistic starts at this multiple of the truth's.
    start_factor: f64,
    /// One record per statistic.
    statistics: Vec<KeyRecord<'a>>,
    /// W on the configured drive and on a vibrating car, when they were run.
    #[serde(skip_serializing_if = "Option::is_none")]
    white_noise: Option<[WhiteNoiseRecord<'a>; 2]>,
}

fn key_record<'a>(n: &'a NoiseStudy, j: usize, c: &KeyCoverage) -> KeyRecord<'a> {
    KeyRecord {
        key: c.key.name(),
        truth: c.truth,
        identifiable_drives: c.identifiable,
        covered: c.covered,
        band: [c.band.0, c.band.1],
        coverage_holds: c.holds(),
        half_width_covered: c.half_width_covered,
        half_width_holds: c.half_width_holds(),
        median_ratio: c.median_ratio,
        estimates: n.estimates.iter().map(|e| &e.keys[j]).collect(),
    }
}

fn white_noise_record(d: &WhiteNoiseDrive) -> WhiteNoiseRecord<'_> {
    WhiteNoiseRecord {
        duration_s: d.duration_s,
        gps_rate_hz: d.gps_rate_hz,
        accel_noise_var_m2_s4: d.truth_w_m2_s4,
        estimate: d.w(),
    }
}

/// The record of `n` and `white`.
pub fn record<'a>(n: &'a NoiseStudy, white: Option<&'a WhiteNoiseDrives>) -> NoiseRecord<'a> {
    NoiseRecord {
        drives: n.drives,
        duration_s: n.duration_s,
        confidence: crate::study::noise::NOISE_CONFIDENCE,
        false_alarm_rate: NOISE_FALSE_ALARM_RATE,
        start_factor: NOISE_START_FACTOR,
        statistics: n
            .coverage
            .iter()
            .enumerate()
            .map(|(j, c)| key_record(n, j, c))
            .collect(),
        white_noise: white.map(|d| {
            [
                white_noise_record(&d.quiet),
                white_noise_record(&d.vibrating),
            ]
        }),
    }
}
