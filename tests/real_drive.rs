//! The shipped minute of a real drive (examples/comma2k19), calibrated as the report shows it:
//! the gravity-compensated axis passes the NIS test once the white noise W is estimated with the
//! GPS σ's and fails it with the GPS σ's alone; its bias is negative; the raw axis needs a
//! drifting bias.

use accelcal::study::drive::{self, Axis, RUNS};

#[test]
fn the_real_drive_calibrates_as_the_report_says() {
    let runs = drive::run().expect("the shipped files calibrate");
    assert_eq!(runs.len(), RUNS.len());
    let nis = |i: usize| &runs[i].calibration.summary.nis;
    // GPS σ's alone: the NIS sum lies above its band (the vibration is not in the model).
    assert_eq!(runs[0].axis, Axis::GravityCompensated);
    assert_eq!(nis(0).verdict, "fail", "{:?}", nis(0));
    assert!(nis(0).sum > nis(0).upper);
    // With W: the NIS test passes, W is identified near 0.4 (m/s²)², and the bias is negative
    // with its interval below zero.
    assert_eq!(nis(1).verdict, "pass", "{:?}", nis(1));
    let w = &runs[1].noise.keys[2];
    assert!(w.identifiable, "{w:?}");
    assert!(w.lower > 0.1 && w.upper.unwrap() < 2.0, "{w:?}");
    let s = &runs[1].calibration.summary;
    assert!(
        s.bias_m_s2 + 1.96 * s.bias_sigma_m_s2 < 0.0,
        "{} ± {}",
        s.bias_m_s2,
        s.bias_sigma_m_s2
    );
    // The raw axis with a random walk: K is identified (gravity's share moves with the pitch).
    let k = &runs[3].noise.keys[3];
    assert!(k.identifiable, "{k:?}");
}
