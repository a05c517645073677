//! `calibrate --imu --gnss` with the six scale factors (`error_states = 21`) on simulated
//! recordings whose IMU has them: the biases and scale factors within their σ's over many
//! recordings (a binomial band) with a half-width control that fails; a level drive without
//! turns leaves the gyros' scale factors undetermined while the whole drive, which turns,
//! determines the vertical gyro's.

mod common;

use accelcal::calibrate::imu::Settings;
use accelcal::calibrate::imu::run::calibrate_of;
use accelcal::calibrate::imu::summary::{Summary, summary};
use accelcal::calibrate::imu::triad::Triad;
use accelcal::config::ins::InsConfig;
use accelcal::input::csv::read::LogText;
use accelcal::ins::error_state::STATES_WITH_SCALE;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;
use common::imu::{band, settings_of};
use rayon::prelude::*;

/// The recordings of the coverage study.
const RECORDINGS: u64 = 100;

/// The study-wide false-alarm rate, split over the twelve quantities and both tails.
const FALSE_ALARM: f64 = 0.01;

/// The scale factors' σ of the simulated IMU, ppm.
const SCALE_PPM: f64 = 3000.0;

fn scenario(duration_s: f64) -> Scenario {
    let mut c = InsConfig::default();
    c.drive.duration_s = duration_s;
    c.imu.gyro_scale_factor_sigma_ppm = SCALE_PPM;
    c.imu.accel_scale_factor_sigma_ppm = SCALE_PPM;
    Scenario::from_config(&c).expect("a valid scenario")
}

/// The assumptions of the simulated sensors with the scale factors estimated.
fn settings(scenario: &Scenario) -> Settings {
    Settings {
        error_states: STATES_WITH_SCALE,
        gyro_scale_factor_sigma_ppm: SCALE_PPM,
        accel_scale_factor_sigma_ppm: SCALE_PPM,
        ..settings_of(scenario)
    }
}

/// Recording `index` calibrated with 21 states, and the truth at its end: the six biases (gyro
/// rad/s, accelerometer m/s²), then the six scale factors (ppm).
fn calibrated(scenario: &Scenario, index: u64) -> (Summary, [f64; 12]) {
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(scenario, index, &mut imu, &mut gnss, &mut truth).expect("in memory");
    let truth = String::from_utf8(truth).expect("text");
    let header: Vec<&str> = truth.lines().next().expect("a header").split(',').collect();
    assert_eq!(header.len(), 22, "the truth has its scale factors");
    let last: Vec<f64> = truth
        .lines()
        .last()
        .expect("rows")
        .split(',')
        .map(|f| f.parse().expect("a number"))
        .collect();
    let s = settings(scenario);
    let c = calibrate_of::<STATES_WITH_SCALE>(
        &LogText::new("imu.csv", imu),
        &LogText::new("gnss.csv", gnss),
        &s,
    )
    .expect("a simulated recording calibrates");
    (
        summary(&c, &s, "imu.csv"),
        std::array::from_fn(|i| last[10 + i]),
    )
}

/// The twelve end estimates' triads in the truth's order, with their component.
fn triads(s: &Summary) -> [(&Triad, usize); 12] {
    let g = s.gyro_scale_factor_ppm.as_ref().expect("estimated");
    let a = s.accel_scale_factor_ppm.as_ref().expect("estimated");
    let all = [&s.gyro_bias_rad_s, &s.accel_bias_m_s2, g, a];
    std::array::from_fn(|k| (all[k / 3], k % 3))
}

#[test]
fn biases_and_scale_factors_are_within_their_sigmas_over_many_recordings() {
    let scenario = scenario(600.0);
    let z: Vec<[f64; 12]> = (0..RECORDINGS)
        .into_par_iter()
        .map(|index| {
            let (s, truth) = calibrated(&scenario, index);
            let t = triads(&s);
            std::array::from_fn(|k| {
                let (triad, i) = t[k];
                (triad.value[i] - truth[k]) / triad.sigma[i]
            })
        })
        .collect();
    let (lo, hi) = band(RECORDINGS, 0.95, FALSE_ALARM / 12.0);
    let count =
        |scale: f64, k: usize| z.iter().filter(|z| z[k].abs() * scale <= 1.959_964).count() as u64;
    let names = [
        "bgx", "bgy", "bgz", "bax", "bay", "baz", "sgx", "sgy", "sgz", "sax", "say", "saz",
    ];
    for (k, name) in names.iter().enumerate() {
        let n = count(1.0, k);
        eprintln!("{name}: {n} of {RECORDINGS} within 95 % (band [{lo}, {hi}])");
        assert!(
            (lo..=hi).contains(&n),
            "{name}: {n} of {RECORDINGS} within their 95 % intervals, band [{lo}, {hi}]"
        );
    }
    // Negative control: intervals of half the width cover too seldom, for every scale factor
    // the drive determines (the gyros', and the accelerometers' x and z).
    let failing = (6..12).filter(|&k| count(2.0, k) < lo).count();
    assert!(
        failing >= 4,
        "half-width intervals of the scale factors were not caught ({failing} of 6)"
    );
}

#[test]
fn a_level_drive_without_turns_leaves_the_gyros_scale_factors_undetermined() {
    // The drive's first minute: at rest, then a speed change, straight and level throughout.
    let (level, _) = calibrated(&scenario(60.0), 0);
    let gyro = level.gyro_scale_factor_ppm.as_ref().expect("estimated");
    assert_eq!(gyro.identifiable, [false; 3], "{gyro:?}");
    assert!(
        level
            .warnings
            .iter()
            .any(|w| w.contains("gyro scale factors of axes x, y, z are not determined")),
        "{:?}",
        level.warnings
    );
    // The whole drive turns by 90°, −180° and 135°: the vertical gyro's scale factor is then
    // determined (the flag can be true).
    let (whole, _) = calibrated(&scenario(600.0), 0);
    let gyro = whole.gyro_scale_factor_ppm.as_ref().expect("estimated");
    assert!(gyro.identifiable[2], "{gyro:?}");
    eprintln!(
        "vertical gyro scale factor σ: level {:.0} ppm, whole drive {:.0} ppm (prior {SCALE_PPM})",
        level
            .gyro_scale_factor_ppm
            .as_ref()
            .map_or(f64::NAN, |t| t.sigma[2]),
        gyro.sigma[2]
    );
}

#[test]
fn a_bad_error_state_is_refused_with_its_key_and_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scenario = scenario(60.0);
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(&scenario, 0, &mut imu, &mut gnss, &mut truth).expect("in memory");
    std::fs::write(dir.path().join("imu.csv"), imu).expect("written");
    std::fs::write(dir.path().join("gnss.csv"), gnss).expect("written");
    for (text, key) in [
        ("[filter]\nerror_states = 18\n", "filter.error_states"),
        (
            "[filter]\nerror_states = 21\ngyro_scale_factor_sigma_ppm = 0.0\n",
            "filter.gyro_scale_factor_sigma_ppm",
        ),
    ] {
        std::fs::write(dir.path().join("c.toml"), text).expect("written");
        let args = [
            "calibrate",
            "--imu",
            "imu.csv",
            "--gnss",
            "gnss.csv",
            "--config",
            "c.toml",
            "--out",
            "out",
        ];
        let out = common::run_in(dir.path(), &args, None);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(key) && err.contains("c.toml:"), "{err}");
        assert!(
            !dir.path().join("out").exists(),
            "a refused run wrote its outputs"
        );
    }
}
