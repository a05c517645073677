//! `calibrate --imu --gnss` on recordings whose IMU steps are irregular and whose fixes fall
//! between IMU samples, with an exact truth: the three-axis drive simulated at 600 Hz, its rows
//! aggregated into groups of 2, 3 or 4 fine steps drawn at random (a ~200 Hz log with ±33 %
//! jitter), the fixes left at their fine-grid times (two in three strictly between the
//! aggregated samples). Increments are additive over a group, Δv = Σ f·δt and Δθ = Σ ω·δt
//! (Savage, *Strapdown Analytics*, 2nd ed., §7.1: the integrated rates over an interval are
//! the sums of those over its sub-intervals), so a group's row is its exact mean rate
//! Σ(rate·δt)/Σδt and the aggregated log is what an IMU with jittered sampling reports.
//! A gap — a lost row, a step of twice the median — is refused as the one-axis log path
//! refuses it, through the binary.

mod common;

use accelcal::calibrate::imu::Settings;
use accelcal::calibrate::imu::run::calibrate;
use accelcal::calibrate::imu::summary::{Summary, summary};
use accelcal::config::ins::InsConfig;
use accelcal::input::csv::read::LogText;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;
use common::imu::{band, settings_of};
use rayon::prelude::*;

/// The recordings of the coverage study (about 1.3 core-seconds each in release: 40 s on 2 idle cores).
const RECORDINGS: u64 = 60;

/// The fine rate the drive is simulated at, Hz: groups of 3 make 200 Hz.
const FINE_RATE_HZ: f64 = 600.0;

/// The drive's length, s: the default drive's first four minutes hold three turns (90°, −180°,
/// 135°), two climbs and four speed changes, which excite every axis.
const DURATION_S: f64 = 240.0;

/// The study-wide false-alarm rate of the coverage checks, split over the six biases.
const FALSE_ALARM: f64 = 0.01;

/// One simulated recording at the fine rate: its IMU rows (time, three specific forces, three
/// rates), the GNSS log, and the true biases over each fine step (gyro x, y, z rad/s, then
/// accelerometer x, y, z m/s²).
struct Recording {
    rows: Vec<[f64; 7]>,
    gnss: String,
    truth: Vec<[f64; 6]>,
}

fn scenario() -> Scenario {
    let mut config = InsConfig::default();
    config.imu.imu_rate_hz = FINE_RATE_HZ;
    config.drive.duration_s = DURATION_S;
    Scenario::from_config(&config).expect("a valid scenario")
}

fn numbers(line: &str) -> Vec<f64> {
    line.split(',')
        .map(|f| f.parse().expect("a number"))
        .collect()
}

fn recording(scenario: &Scenario, index: u64) -> Recording {
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(scenario, index, &mut imu, &mut gnss, &mut truth).expect("in memory");
    let imu = String::from_utf8(imu).expect("text");
    let truth = String::from_utf8(truth).expect("text");
    Recording {
        rows: imu
            .lines()
            .skip(1)
            .map(|l| numbers(l).try_into().expect("seven columns"))
            .collect(),
        gnss: String::from_utf8(gnss).expect("text"),
        truth: truth
            .lines()
            .skip(1)
            .map(|l| {
                let t = numbers(l);
                std::array::from_fn(|i| t[10 + i])
            })
            .collect(),
    }
}

/// SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014): the group sizes' stream, independent of the library's.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The fine rows aggregated into groups whose sizes `size` gives: the third row as it is (the
/// first row of a log only starts the first step; starting at 3/600 s puts the ends of groups
/// of 3 on whole seconds, the fixes' times), then each group's last time and its mean rates (every fine
/// step is 1/600 s, so Σ(rate·δt)/Σδt is the plain mean). A last group cut short by the end
/// of the log keeps at least 2 fine steps (a single one is dropped). Returns the log and the
/// index of the last fine row it covers, where the truth at its end is read.
fn aggregate(rows: &[[f64; 7]], mut size: impl FnMut() -> usize) -> (String, usize) {
    let mut out = String::from("t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s\n");
    let line = |out: &mut String, r: &[f64; 7]| {
        let cells: Vec<String> = r.iter().map(|x| format!("{x}")).collect();
        *out += &cells.join(",");
        out.push('\n');
    };
    line(&mut out, &rows[2]);
    let mut k = 3;
    while rows.len() - k >= 2 {
        let group = &rows[k..(k + size()).min(rows.len())];
        let n = group.len() as f64;
        let mut r = [0.0; 7];
        r[0] = group[group.len() - 1][0];
        for c in 1..7 {
            r[c] = group.iter().map(|g| g[c]).sum::<f64>() / n;
        }
        line(&mut out, &r);
        k += group.len();
    }
    (out, k - 1)
}

/// Groups of 2, 3 or 4 fine steps with equal probability, from seed `seed`.
fn jittered(rows: &[[f64; 7]], seed: u64) -> (String, usize) {
    let mut state = seed;
    aggregate(rows, || 2 + (splitmix(&mut state) % 3) as usize)
}

fn run(imu: &str, gnss: &str, s: &Settings) -> Summary {
    let (i, g) = (
        LogText::new("imu.csv", imu.as_bytes()),
        LogText::new("gnss.csv", gnss.as_bytes()),
    );
    let c = calibrate(&i, &g, s).expect("a simulated recording calibrates");
    summary(&c, s, "imu.csv")
}

/// (value, σ) of the six biases.
fn biases(s: &Summary) -> [(f64, f64); 6] {
    let (g, a) = (&s.gyro_bias_rad_s, &s.accel_bias_m_s2);
    std::array::from_fn(|i| {
        let (t, k) = if i < 3 { (g, i) } else { (a, i - 3) };
        (t.value[k], t.sigma[k])
    })
}

/// |error| / σ of the six biases.
fn z_scores(s: &Summary, truth: &[f64; 6]) -> [f64; 6] {
    let b = biases(s);
    std::array::from_fn(|i| (b[i].0 - truth[i]).abs() / b[i].1)
}

/// How many fixes of `gnss` fall strictly between two rows of `imu`.
fn fixes_between(imu: &str, gnss: &str) -> (usize, usize) {
    let times: Vec<f64> = imu.lines().skip(1).map(|l| numbers(l)[0]).collect();
    let fixes: Vec<f64> = gnss.lines().skip(1).map(|l| numbers(l)[0]).collect();
    let between = fixes
        .iter()
        .filter(|t| times.binary_search_by(|x| x.total_cmp(t)).is_err())
        .count();
    (between, fixes.len())
}

/// The six biases recovered against the truth over 60 jittered recordings, each axis inside
/// the binomial band of a 95 % interval at α = 1 % split over the six. The control: the same
/// estimates judged with their σ's halved — a 68.3 % interval claimed as 95 % — fall below the
/// band's floor on every axis.
#[test]
fn jittered_recordings_cover_the_truth() {
    let scenario = scenario();
    let settings = settings_of(&scenario);
    let z: Vec<[f64; 6]> = (0..RECORDINGS)
        .into_par_iter()
        .map(|i| {
            let r = recording(&scenario, i);
            let (imu, end) = jittered(&r.rows, 1000 + i);
            if i == 0 {
                let (between, fixes) = fixes_between(&imu, &r.gnss);
                eprintln!("{between} of {fixes} fixes strictly between IMU samples");
                assert!(3 * between > fixes, "{between} of {fixes} between samples");
            }
            z_scores(&run(&imu, &r.gnss, &settings), &r.truth[end])
        })
        .collect();
    let (lo, hi) = band(RECORDINGS, 0.95, FALSE_ALARM / 6.0);
    let names = ["bgx", "bgy", "bgz", "bax", "bay", "baz"];
    for (k, name) in names.iter().enumerate() {
        let inside = z.iter().filter(|z| z[k] <= 1.959_964).count() as u64;
        let halved = z.iter().filter(|z| z[k] <= 1.959_964 / 2.0).count() as u64;
        eprintln!("{name}: {inside} within 1.96σ, {halved} within 0.98σ, band [{lo}, {hi}]");
        assert!(
            (lo..=hi).contains(&inside),
            "{name}: {inside} of {RECORDINGS} within 1.96σ, band [{lo}, {hi}]"
        );
        // Within 0.98σ is a 67.3 % event when the σ's are right: it reaches the 95 % band's
        // floor (51 of 60) with probability P(Bin(60, 0.673) ≥ 51) = 1.6·10⁻³ per axis, under
        // 1 % over the six — the control's own false-alarm rate.
        assert!(
            halved < lo,
            "{name}: the half-width control passes ({halved} of {RECORDINGS} within 0.98σ)"
        );
    }
}

/// One recording aggregated with every group of 3 (a regular 200 Hz log, every fix on a
/// sample) and with jittered groups gives the same six biases within 0.1σ: jitter and fixes
/// between samples are handled, not approximated. The control: another recording's biases
/// differ from this one's by more than 0.1σ on some axis, so the check can fail.
#[test]
fn jitter_leaves_the_biases_of_one_recording() {
    let scenario = scenario();
    let settings = settings_of(&scenario);
    let r = recording(&scenario, 77);
    let (regular, _) = aggregate(&r.rows, || 3);
    let (between, _) = fixes_between(&regular, &r.gnss);
    assert_eq!(between, 0, "groups of 3 put every fix on a sample");
    let (a, b) = rayon::join(
        || biases(&run(&regular, &r.gnss, &settings)),
        || biases(&run(&jittered(&r.rows, 5).0, &r.gnss, &settings)),
    );
    let worst = (0..6)
        .map(|k| (a[k].0 - b[k].0).abs() / a[k].1)
        .fold(0.0, f64::max);
    eprintln!("regular against jittered: largest difference {worst:.4}σ");
    assert!(worst <= 0.1, "jitter moves a bias by {worst}σ");
    let other = recording(&scenario, 78);
    let c = biases(&run(
        &aggregate(&other.rows, || 3).0,
        &other.gnss,
        &settings,
    ));
    let apart = (0..6)
        .map(|k| (a[k].0 - c[k].0).abs() / a[k].1)
        .fold(0.0, f64::max);
    assert!(apart > 0.1, "another recording within {apart}σ");
}

/// A recording with one IMU row dropped (a step of 2× the median) is refused by the binary
/// with exit code 2, the file and the line of the step after the gap, and no output written,
/// as the one-axis log path refuses it (tests/allan_cli.rs); the same recording whole is
/// calibrated (exit 0), so the refusal is the gap's.
#[test]
fn a_dropped_imu_row_is_refused_with_its_line() {
    let mut config = InsConfig::default();
    config.drive.duration_s = 90.0;
    let scenario = Scenario::from_config(&config).expect("a valid scenario");
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(&scenario, 3, &mut imu, &mut gnss, &mut truth).expect("in memory");
    let imu = String::from_utf8(imu).expect("text");
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("gnss.csv"), gnss).expect("written");
    let calibrate = |imu_text: &str, out: &str| {
        std::fs::write(dir.path().join("imu.csv"), imu_text).expect("written");
        let args = [
            "calibrate",
            "--imu",
            "imu.csv",
            "--gnss",
            "gnss.csv",
            "--out",
            out,
        ];
        common::run_in(dir.path(), &args, None)
    };
    let whole = calibrate(&imu, "whole");
    assert!(
        whole.status.success(),
        "{}",
        String::from_utf8_lossy(&whole.stderr)
    );
    // Line 1001 holds data row 1000 (t = 5.0 s); without it, the step into the row at
    // 5.005 s, now on line 1001, is 10 ms against a median of 5 ms.
    let dropped: String = imu
        .lines()
        .enumerate()
        .filter(|(k, _)| *k + 1 != 1001)
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let out = calibrate(&dropped, "gap");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("imu.csv, line 1001"), "{err}");
    assert!(err.contains("2.000 times the median step"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        !dir.path().join("gap").exists(),
        "output written for a refused log"
    );
}
