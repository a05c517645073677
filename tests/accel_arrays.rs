//! Calibrate from arrays (`input::csv::arrays::AccelArrays`, the Python package's entry) gives the
//! bytes that calibrate from the same log's text gives, on the shipped comma2k19 minute: the
//! summary, the per-fix estimates and (through the arrays' text form) the per-sample ones.

use accelcal::calibrate::{self, Settings};
use accelcal::config::Config;
use accelcal::input::csv::arrays::AccelArrays;
use accelcal::input::csv::read::{AccelReader, LogSource, LogText};

const ACCEL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/comma2k19/accel_gravcomp.csv"
);
const GPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/comma2k19/gps.csv");

fn settings() -> Settings {
    Settings::from_config(&Config::default(), false, false).unwrap()
}

/// summary.json, estimates.csv per fix and per sample of a calibration.
fn outputs(accel: &dyn LogSource) -> [String; 3] {
    let gps = LogText::new("gps", std::fs::read(GPS).unwrap());
    let mut prepared = calibrate::prepare(accel, &gps, &settings()).unwrap();
    let (mut fixes, mut samples) = (Vec::new(), Vec::new());
    prepared.write_fix_estimates(&mut fixes).unwrap();
    prepared.per_sample().unwrap();
    prepared.write_estimates(&mut samples).unwrap();
    [
        prepared.calibration().summary.to_json(),
        String::from_utf8(fixes).unwrap(),
        String::from_utf8(samples).unwrap(),
    ]
}

fn columns() -> (Vec<f64>, Vec<f64>) {
    let text = LogText::new("accel", std::fs::read(ACCEL).unwrap());
    let mut reader = AccelReader::open(&text).unwrap();
    let (mut t, mut a) = (Vec::new(), Vec::new());
    while let Some(s) = reader.next_sample().unwrap() {
        t.push(s.t_s);
        a.push(s.accel_m_s2);
    }
    (t, a)
}

#[test]
fn arrays_give_the_texts_bytes() {
    let text = LogText::new("accel", std::fs::read(ACCEL).unwrap());
    let (t, a) = columns();
    assert_eq!(t.len(), 6256);
    let expected = outputs(&text);
    let got = outputs(&AccelArrays::new("accel", &t, &a).unwrap());
    for (g, e) in got.iter().zip(&expected) {
        assert!(g == e, "arrays and text differ");
    }
    // Negative control: one sample moved by 10⁻⁶ m/s² changes the summary.
    let mut moved = a.clone();
    moved[3000] += 1e-6;
    let other = outputs(&AccelArrays::new("accel", &t, &moved).unwrap());
    assert_ne!(other[0], expected[0]);
}

#[test]
fn a_bad_sample_names_its_line_as_the_text_would() {
    let (t, mut a) = columns();
    a[40] = f64::NAN;
    let gps = LogText::new("gps", std::fs::read(GPS).unwrap());
    let arrays = AccelArrays::new("accel", &t, &a).unwrap();
    let err = calibrate::prepare(&arrays, &gps, &settings())
        .err()
        .unwrap();
    let message = err.to_string();
    assert!(
        message.contains("accel")
            && message.contains("42")
            && message.contains("not a finite number"),
        "{message}"
    );
    let (mut t, a) = columns();
    t.swap(10, 11);
    let arrays = AccelArrays::new("accel", &t, &a).unwrap();
    let err = calibrate::prepare(&arrays, &gps, &settings())
        .err()
        .unwrap();
    // Sample 11 is before sample 10: line 13, as in the text with those two rows swapped.
    assert!(
        err.to_string().starts_with("accel, line 13: time stamp"),
        "{err}"
    );
}
