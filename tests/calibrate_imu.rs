//! `calibrate --imu --gnss` on simulated recordings of the three-axis drive with a known truth:
//! the six biases within their σ's over many recordings (a binomial band), with a negative
//! control; the same numbers from the same recording in other forms (forward-left-up axes,
//! increments, gzip, fixes missing); and bad recordings refused with file, line and field.

mod common;

use accelcal::calibrate::imu::Settings;
use accelcal::calibrate::imu::run::{Calibrated, calibrate};
use accelcal::calibrate::imu::smoother::smooth;
use accelcal::calibrate::imu::summary::{Summary, summary};
use accelcal::config::ins::{Axes, InsConfig};
use accelcal::input::csv::read::LogText;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;
use common::imu::{band, settings_of};
use rayon::prelude::*;

/// The recordings of the coverage study.
const RECORDINGS: u64 = 100;

/// The study-wide false-alarm rate of the coverage checks, split over the six biases.
const FALSE_ALARM: f64 = 0.01;

/// One simulated recording: the IMU log, the GNSS log, and the true biases at the end
/// (gyro x, y, z rad/s, then accelerometer x, y, z m/s²).
struct Recording {
    imu: String,
    gnss: String,
    truth: [f64; 6],
    /// The biases at the middle of the drive, with its time, s.
    middle: (f64, [f64; 6]),
}

fn scenario() -> Scenario {
    Scenario::from_config(&InsConfig::default()).expect("the default scenario is valid")
}

fn recording(scenario: &Scenario, index: u64) -> Recording {
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(scenario, index, &mut imu, &mut gnss, &mut truth).expect("in memory");
    let truth = String::from_utf8(truth).expect("text");
    let row =
        |l: &str| -> Vec<f64> { l.split(',').map(|f| f.parse().expect("a number")).collect() };
    let last = row(truth.lines().last().expect("rows"));
    let rows = truth.lines().count() - 1;
    let mid = row(truth.lines().nth(rows / 2).expect("rows"));
    Recording {
        imu: String::from_utf8(imu).expect("text"),
        gnss: String::from_utf8(gnss).expect("text"),
        truth: std::array::from_fn(|i| last[10 + i]),
        middle: (mid[0], std::array::from_fn(|i| mid[10 + i])),
    }
}

fn run(imu: &str, gnss: &str, s: &Settings) -> Summary {
    summary(&calibrated(imu, gnss, s), s, "imu.csv")
}

fn calibrated(imu: &str, gnss: &str, s: &Settings) -> Calibrated {
    let (i, g) = (
        LogText::new("imu.csv", imu.as_bytes()),
        LogText::new("gnss.csv", gnss.as_bytes()),
    );
    calibrate(&i, &g, s).expect("a simulated recording calibrates")
}

/// |error| / σ of the six smoothed biases at the fix at `t_s` against `truth`; and whether
/// every smoothed σ is at most the filtered one (to 10⁻⁹) with the last fix's equal.
fn smoothed_z(c: &Calibrated, t_s: f64, truth: &[f64; 6]) -> ([f64; 6], bool) {
    let s = smooth(&c.records);
    let k = c
        .records
        .iter()
        .position(|r| (r.t_s - t_s).abs() < 1e-6)
        .expect("a fix at the middle");
    let p = &s[k].covariance;
    let z = std::array::from_fn(|i| {
        let v = if i < 3 {
            s[k].gyro_bias_rad_s[i]
        } else {
            s[k].accel_bias_m_s2[i - 3]
        };
        (v - truth[i]).abs() / p[(9 + i, 9 + i)].sqrt()
    });
    let tighter = c.records.iter().zip(&s).all(|(r, sm)| {
        (0..15).all(|i| sm.covariance[(i, i)] <= r.covariance[(i, i)] * (1.0 + 1e-9))
    });
    let last = s.last().expect("fixes").covariance == c.records.last().expect("fixes").covariance;
    (z, tighter && last)
}

/// |error| / σ of the six biases.
fn z_scores(s: &Summary, truth: &[f64; 6]) -> [f64; 6] {
    let (g, a) = (&s.gyro_bias_rad_s, &s.accel_bias_m_s2);
    std::array::from_fn(|i| {
        let (t, k) = if i < 3 { (g, i) } else { (a, i - 3) };
        (t.value[k] - truth[i]).abs() / t.sigma[k]
    })
}

/// The six biases recovered against the truth over 100 recordings of the default 10-minute
/// drive — filtered at the end, and smoothed at the middle — each axis inside the binomial band
/// of a 95 % interval at α = 1 % split over the twelve; the same recordings with the σ's halved
/// (the half-width control) fall below it; every smoothed σ at most the filtered one.
#[test]
fn biases_are_within_their_sigmas_over_many_recordings() {
    let scenario = scenario();
    let settings = settings_of(&scenario);
    let runs: Vec<([f64; 6], [f64; 6], bool)> = (0..RECORDINGS)
        .into_par_iter()
        .map(|i| {
            let r = recording(&scenario, i);
            let c = calibrated(&r.imu, &r.gnss, &settings);
            let (zs, tighter) = smoothed_z(&c, r.middle.0, &r.middle.1);
            (
                z_scores(&summary(&c, &settings, "imu.csv"), &r.truth),
                zs,
                tighter,
            )
        })
        .collect();
    assert!(
        runs.iter().all(|r| r.2),
        "a smoothed σ above the filtered one"
    );
    let (lo, hi) = band(RECORDINGS, 0.95, FALSE_ALARM / 12.0);
    let names = ["bgx", "bgy", "bgz", "bax", "bay", "baz"];
    for (k, name) in names.iter().enumerate() {
        let smoothed = runs.iter().filter(|r| r.1[k] <= 1.959_964).count() as u64;
        eprintln!("{name}: smoothed at the middle, {smoothed} within 1.96σ");
        assert!(
            (lo..=hi).contains(&smoothed),
            "{name} smoothed: {smoothed} of {RECORDINGS} within 1.96σ, band [{lo}, {hi}]"
        );
    }
    let z: Vec<[f64; 6]> = runs.iter().map(|r| r.0).collect();
    for (k, name) in names.iter().enumerate() {
        let inside = z.iter().filter(|z| z[k] <= 1.959_964).count() as u64;
        let halved = z.iter().filter(|z| z[k] <= 1.959_964 / 2.0).count() as u64;
        eprintln!("{name}: {inside} within 1.96σ, {halved} within 0.98σ, band [{lo}, {hi}]");
        assert!(
            (lo..=hi).contains(&inside),
            "{name}: {inside} of {RECORDINGS} within 1.96σ, band [{lo}, {hi}]"
        );
        assert!(
            halved < lo,
            "{name}: the half-width control passes ({halved} of {RECORDINGS} within 0.98σ)"
        );
    }
}

/// The same recording with its y and z columns negated and `axes = flu`, or gzipped, gives the
/// same summary bit for bit; written as increments, the same biases to 10⁻⁹ relative.
#[test]
fn other_forms_of_one_recording_give_its_numbers() {
    let scenario = scenario();
    let settings = settings_of(&scenario);
    let r = recording(&scenario, 7);
    let base = run(&r.imu, &r.gnss, &settings);
    let json = |s: &Summary| {
        let mut v = serde_json::to_value(s).expect("json");
        v["assumptions"] = serde_json::Value::Null;
        v.to_string()
    };
    // Forward-left-up.
    let flu: String = r
        .imu
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 0 {
                return format!("{l}\n");
            }
            let f: Vec<&str> = l.split(',').collect();
            let neg = |s: &str| match s.strip_prefix('-') {
                Some(p) => p.to_string(),
                None if s == "0" => s.to_string(),
                None => format!("-{s}"),
            };
            format!(
                "{},{},{},{},{},{},{}\n",
                f[0],
                f[1],
                neg(f[2]),
                neg(f[3]),
                f[4],
                neg(f[5]),
                neg(f[6])
            )
        })
        .collect();
    let s_flu = Settings {
        axes: Axes::Flu,
        ..settings
    };
    assert_eq!(json(&base), json(&run(&flu, &r.gnss, &s_flu)));
    // gzip.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut gz, r.imu.as_bytes()).expect("memory");
    let gz = gz.finish().expect("memory");
    let (i, g) = (
        LogText::new("imu.csv.gz", gz),
        LogText::new("gnss.csv", r.gnss.as_bytes()),
    );
    let c = calibrate(&i, &g, &settings).expect("gzip reads");
    assert_eq!(json(&base), json(&summary(&c, &settings, "imu.csv")));
    // Increments: Δv = f·Δt, Δθ = ω·Δt over each row's step.
    let mut previous = None;
    let mut inc = String::from("t_s,dvx_m_s,dvy_m_s,dvz_m_s,dthx_rad,dthy_rad,dthz_rad\n");
    for l in r.imu.lines().skip(1) {
        let f: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
        let dt = previous.map_or(1.0 / scenario.imu_rate_hz, |p| f[0] - p);
        previous = Some(f[0]);
        inc += &format!("{}", f[0]);
        for x in &f[1..] {
            inc += &format!(",{}", x * dt);
        }
        inc += "\n";
    }
    let s_inc = run(&inc, &r.gnss, &settings);
    for k in 0..3 {
        for (a, b) in [
            (&base.gyro_bias_rad_s, &s_inc.gyro_bias_rad_s),
            (&base.accel_bias_m_s2, &s_inc.accel_bias_m_s2),
        ] {
            let d = (a.value[k] - b.value[k]).abs();
            assert!(
                d <= 1e-6 * a.sigma[k],
                "axis {k}: {} vs {}",
                a.value[k],
                b.value[k]
            );
        }
    }
    // The negative control: the columns negated without `axes = flu` give other biases.
    let wrong = run(&flu, &r.gnss, &settings);
    assert!((wrong.gyro_bias_rad_s.value[1] - base.gyro_bias_rad_s.value[1]).abs() > 0.0);
}

/// Every fifth fix dropped: the biases still within their σ's (|z| ≤ 3.5, a 5·10⁻⁴ two-sided
/// normal tail on each of six per recording, over 8 recordings: a false alarm at most 2.4 %),
/// their σ's no smaller than with every fix.
#[test]
fn missing_fixes_leave_the_biases_within_their_sigmas() {
    let scenario = scenario();
    let settings = settings_of(&scenario);
    for i in 0..8 {
        let r = recording(&scenario, 100 + i);
        let base = run(&r.imu, &r.gnss, &settings);
        let thinned: String = r
            .gnss
            .lines()
            .enumerate()
            .filter(|(k, _)| *k == 0 || k % 5 != 0)
            .map(|(_, l)| format!("{l}\n"))
            .collect();
        let s = run(&r.imu, &thinned, &settings);
        assert!(s.fixes < base.fixes);
        let z = z_scores(&s, &r.truth);
        assert!(z.iter().all(|z| *z <= 3.5), "recording {i}: {z:?}");
        for k in 0..3 {
            assert!(s.accel_bias_m_s2.sigma[k] >= base.accel_bias_m_s2.sigma[k] * 0.999);
        }
    }
}

/// `--estimate-noise` on one simulated recording, started from a horizontal σ three times the
/// truth's: the maximum-likelihood horizontal σ's interval holds the true 1 m and the time
/// offset's holds 0 (one recording: a check of the machinery, not of the coverage).
#[test]
fn noise_estimate_finds_the_receivers_sigma_and_no_offset() {
    use accelcal::calibrate::imu::noise::{ImuKey, estimate};
    use accelcal::input::gnss_csv::read_gnss;
    use accelcal::input::imu_csv::read_steps;
    // The drive's first 240 s (three turns, two climbs, four speed changes) keep it quick.
    let mut config = InsConfig::default();
    config.drive.duration_s = 240.0;
    let scenario = Scenario::from_config(&config).expect("valid");
    let truth = settings_of(&scenario);
    let r = recording(&scenario, 11);
    let start = Settings {
        gnss_position_sigma_m: [3.0, 3.0, 2.0],
        ..truth
    };
    let rows = read_gnss(&LogText::new("gnss.csv", r.gnss.as_bytes())).expect("reads");
    let imu = LogText::new("imu.csv", r.imu.as_bytes());
    let (steps, span, _) = read_steps(&imu, start.axes).expect("reads");
    let keys = [ImuKey::GnssHorizontalSigma, ImuKey::GnssTimeOffset];
    let e = estimate(&rows, &steps, &span, &start, &keys, 0.95).expect("finite");
    let (sigma, offset) = (&e.keys[0], &e.keys[1]);
    eprintln!("{sigma:?}\n{offset:?}\n{} evaluations", e.evaluations);
    assert!(sigma.identifiable && offset.identifiable);
    assert!(
        sigma.lower.unwrap() < 1.0 && 1.0 < sigma.upper.unwrap(),
        "{sigma:?}"
    );
    assert!(
        offset.lower.unwrap() < 0.0 && 0.0 < offset.upper.unwrap(),
        "{offset:?}"
    );
    // The negative control: the configured 3 m lies outside the interval.
    assert!(sigma.upper.unwrap() < 3.0);
}
