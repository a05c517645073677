//! The shipped minute in three axes (examples/comma2k19_3d) as the report's section "A real
//! drive in three axes" shows it: what the calibration with no configuration determines, the
//! attitude compared with comma's pose at the fixes' own times, and the section's sentences
//! following the numbers (each flipped number flips its words).

use std::sync::OnceLock;

use accelcal::calibrate::imu::run::euler_sigmas;
use accelcal::report::real_drive_3d_words as words;
use accelcal::study::drive3d::{self, Pose, RealDrive3d, reference_at};

/// The section's calibrations, run once.
fn drive() -> &'static RealDrive3d {
    static DRIVE: OnceLock<RealDrive3d> = OnceLock::new();
    DRIVE.get_or_init(|| drive3d::run().expect("the shipped minute calibrates"))
}

#[test]
fn the_reference_is_read_between_its_samples_and_across_the_yaw_seam() {
    let r = [
        Pose {
            t_s: 0.0,
            euler_deg: [1.0, -2.0, 179.0],
        },
        Pose {
            t_s: 1.0,
            euler_deg: [3.0, -4.0, -179.0],
        },
    ];
    let mid = reference_at(&r, 0.5).unwrap();
    assert!((mid[0] - 2.0).abs() < 1e-12 && (mid[1] + 3.0).abs() < 1e-12);
    // 179° → −179° is a turn of 2°: half-way is ±180°, not 0°.
    assert!((mid[2].abs() - 180.0).abs() < 1e-9, "{mid:?}");
    assert_eq!(reference_at(&r, 1.0).unwrap(), r[1].euler_deg);
    // Outside the span there is nothing to compare with.
    assert!(reference_at(&r, -0.1).is_none() && reference_at(&r, 1.1).is_none());
    let shipped = drive3d::reference().unwrap();
    assert!(shipped.windows(2).all(|w| w[1].t_s > w[0].t_s));
}

/// What the page says of the minute with no configuration holds in its numbers, and the
/// comparison at the last fix is the summary's attitude minus comma's pose there.
#[test]
fn the_minute_calibrates_as_the_section_says() {
    let d = drive();
    let p = &d.plain.summary;
    assert!(p.gyro_bias_rad_s.identifiable.iter().all(|x| *x));
    assert_eq!(p.accel_bias_m_s2.identifiable[..2], [false, false]);
    assert!(!p.attitude_deg.yaw_identifiable);
    // The receiver's smoothed fixes: the NIS sum below its band, the position innovations
    // correlated, the intervals conditional.
    assert!(p.nis.sum < p.nis.lower, "{:?}", p.nis);
    assert!(p.intervals_conditional);
    assert!(
        p.rejected_by
            .iter()
            .any(|r| r == "whiteness_position_north")
    );
    // The comparison at the last fix, against the summary's attitude and comma's pose there.
    let a = &d.plain.attitude;
    let last = d.plain.calibrated.records.last().unwrap();
    assert_eq!(*a.t_s.last().unwrap(), last.t_s);
    let r = reference_at(&d.reference, last.t_s).unwrap();
    let end = [
        p.attitude_deg.roll,
        p.attitude_deg.pitch,
        p.attitude_deg.yaw,
    ];
    for k in 0..3 {
        assert!((a.filtered.last().unwrap()[k] - (end[k] - r[k])).abs() < 1e-9);
    }
    let sigma = euler_sigmas(&last.pva, &last.covariance).map(f64::to_degrees);
    assert_eq!(*a.filtered_sigma.last().unwrap(), sigma);
    // The estimate was made and used.
    let e = d.estimated.summary.noise_estimate.as_ref().unwrap();
    assert_eq!(e.keys.len(), drive3d::REPORT_KEYS.len());
    assert_eq!(d.estimated.summary.assumptions, e.settings);
}

#[test]
fn the_bias_sentences_follow_the_numbers() {
    let d = drive();
    let said = words::bias_findings(d);
    assert!(
        said[0]
            .contains("does not determine the accelerometer bias x and the accelerometer bias y"),
        "{}",
        said[0]
    );
    let mut all = d.clone();
    all.plain.summary.accel_bias_m_s2.identifiable = [true; 3];
    assert!(words::bias_findings(&all)[0].contains("determines all six"));
    // Android's estimate at the calibration's values: inside every interval; 5σ off on z:
    // outside on z alone.
    let g = &d.plain.summary.gyro_bias_rad_s;
    let mut near = d.clone();
    near.android_gyro_bias_rad_s = g.value;
    assert!(words::bias_findings(&near)[1].contains("inside every axis"));
    near.android_gyro_bias_rad_s[2] += 5.0 * g.sigma[2];
    let said = words::bias_findings(&near)[1].clone();
    assert!(
        said.contains("outside") && said.contains("on z (5.0 σ)"),
        "{said}"
    );
}

#[test]
fn the_attitude_sentences_follow_the_numbers() {
    let d = drive();
    let said = words::attitude_findings(&d.plain);
    assert!(
        said[1].starts_with("The yaw is not determined"),
        "{}",
        said[1]
    );
    let mut flipped = d.plain.clone();
    flipped.summary.attitude_deg.yaw_identifiable = true;
    assert!(words::attitude_findings(&flipped)[1].starts_with("The yaw is determined"));
    // σ's a hundredth as large: the differences are larger than them.
    for s in &mut flipped.attitude.filtered_sigma {
        *s = s.map(|x| 0.01 * x);
    }
    let said = words::attitude_findings(&flipped)[0].clone();
    assert!(said.contains("larger than the σ's"), "{said}");
}

#[test]
fn the_test_sentences_follow_the_numbers() {
    let d = drive();
    let p = &d.plain.summary;
    let said = words::test_findings(p).join(" ");
    assert!(said.contains("is below its band") && said.contains("smooths its fixes"));
    assert!(said.contains("assumes a model the data reject"));
    // The sum above its band: an error the model lacks, not smoothing.
    let mut above = p.clone();
    above.nis.sum = 2.0 * above.nis.upper;
    let said = words::test_findings(&above).join(" ");
    assert!(said.contains("an error the model lacks") && !said.contains("smooths"));
    // Every test passing: no diagnosis, the intervals stand.
    let mut clean = p.clone();
    clean.nis.sum = 0.5 * (clean.nis.lower + clean.nis.upper);
    clean.nis.verdict = "pass";
    for w in &mut clean.whiteness {
        w.test.verdict = "pass";
    }
    clean.rejected_by.clear();
    clean.intervals_conditional = false;
    let said = words::test_findings(&clean).join(" ");
    assert!(
        said.contains("No test rejects") && !said.contains("Together"),
        "{said}"
    );
}

#[test]
fn the_noise_sentences_follow_the_numbers() {
    let d = drive();
    // Every key determined (both interval ends inside the search's box), then the first one
    // open above: the first sentence says which.
    let mut all = d.clone();
    let est = all.estimated.summary.noise_estimate.as_mut().unwrap();
    for k in &mut est.keys {
        k.identifiable = true;
        k.lower = Some(k.lower.unwrap_or(0.5 * k.value));
        k.upper = Some(k.upper.unwrap_or(2.0 * k.value));
    }
    let said = words::noise_findings(&all);
    assert!(said[0].starts_with("The drive determines"), "{}", said[0]);
    let mut open = all.clone();
    let est = open.estimated.summary.noise_estimate.as_mut().unwrap();
    est.keys[0].identifiable = false;
    est.keys[0].upper = None;
    let name = est.keys[0].key;
    let said = words::noise_findings(&open);
    assert!(
        said[0].contains(&format!("does not determine {name}")),
        "{}",
        said[0]
    );
    // With more than one key, the others are still said to be determined.
    assert_eq!(
        said[0].starts_with("The drive determines"),
        open.estimated
            .summary
            .noise_estimate
            .as_ref()
            .unwrap()
            .keys
            .len()
            > 1,
        "{}",
        said[0]
    );
    let first = &open.estimated.summary.noise_estimate.as_ref().unwrap().keys[0];
    assert!(words::key_words(first).contains("only a lower bound"));
    // The same whiteness verdicts in both runs, then one flipped.
    let mut same = d.clone();
    same.estimated.summary.whiteness = same.plain.summary.whiteness.clone();
    assert!(words::noise_findings(&same)[1].contains("every whiteness verdict as it was"));
    let w = &mut same.estimated.summary.whiteness[0];
    w.test.verdict = if w.test.verdict == "pass" {
        "fail"
    } else {
        "pass"
    };
    assert!(words::noise_findings(&same)[1].contains("whiteness turns from"));
}

/// The section's view with numbers for exactly its own labels: a bias or yaw the drive does not
/// determine reads "not determined" (no value), one it determines reads value ± σ.
#[test]
fn the_view_prints_no_value_for_what_the_drive_leaves_open() {
    use accelcal::report::kind::SectionKind;
    use accelcal::report::labels::Numbers;
    use accelcal::report::real_drive_3d::{RealDrive3dSection, view};
    let labels = RealDrive3dSection.labels(0);
    let numbers = Numbers::from_map(
        labels
            .iter()
            .enumerate()
            .map(|(i, l)| (*l, i + 1))
            .collect(),
    );
    let d = drive();
    let v = view(d, &numbers).unwrap();
    assert_eq!(v.biases.len(), 6);
    let accel_x = &v.biases[3];
    assert!(!accel_x.plain_determined && accel_x.plain == "not determined");
    assert!(accel_x.plain_interval.starts_with('['));
    assert!(v.biases[0].plain.contains('±') && !v.biases[0].android.is_empty());
    assert_eq!(v.attitude[2].determined, Some(false));
    let mut flipped = d.clone();
    flipped.plain.summary.accel_bias_m_s2.identifiable[0] = true;
    flipped.plain.summary.attitude_deg.yaw_identifiable = true;
    let v = view(&flipped, &numbers).unwrap();
    assert!(v.biases[3].plain.contains('±'), "{}", v.biases[3].plain);
    assert_eq!(v.attitude[2].determined, Some(true));
    assert!(v.attitude_html[1].starts_with("The yaw is determined"));
}
