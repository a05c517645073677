//! `intrinsics` proven on sessions drawn from its model: every parameter's 95 % interval covers
//! the truth in the binomial band at 1 % over 240 sessions (9 to 36 poses turned by hand, a
//! consumer MEMS with scale factors within ±3 %, non-orthogonality within ±2°), intervals half as
//! wide fail that band (the control); the goodness test rejects at its stated rate, and rejects a
//! session whose accelerometers drift as with temperature; poses too few or too alike leave
//! parameters named as undetermined.

use accelcal::intrinsics::accel::{MATRIX_ENTRIES, PARAMETER_NAMES, Params, derived};
use accelcal::intrinsics::simulate::{
    Session, TrueIntrinsics, draw_intrinsics, random_poses, simulate,
};
use accelcal::intrinsics::{Intrinsics, Settings, calibrate};
use accelcal::random::Stream;
use accelcal::stats::binomial_band;
use nalgebra::{UnitQuaternion, Vector3};
use rayon::prelude::*;

const SESSIONS: u64 = 240;
/// The binomial band's false-alarm rate, per count tested.
const BAND_ALPHA: f64 = 0.01;

/// Session `index`: its truth, and the calibration of its log.
fn session(index: u64, edit: impl Fn(&mut Session)) -> (TrueIntrinsics, Session, Intrinsics) {
    let mut rng = Stream::new(0x1a7c0, index);
    let truth = draw_intrinsics(&mut rng);
    let poses = 9 + (rng.next_u64() % 28) as usize;
    let mut s = Session::consumer(random_poses(poses, &mut rng));
    edit(&mut s);
    let log = simulate(&truth, &s, &mut rng);
    let mut settings = Settings::new(s.gravity_m_s2);
    settings.latitude_rad = Some(s.latitude_rad);
    let x = calibrate(&log, &settings).expect("a session of good poses");
    (truth, s, x)
}

/// The truth as the fit's θ.
fn true_params(t: &TrueIntrinsics) -> Params {
    let mut p = Params::zeros();
    for i in 0..3 {
        p[i] = t.accel_bias[i];
    }
    for (k, &(r, c)) in MATRIX_ENTRIES.iter().enumerate() {
        p[3 + k] = t.accel_matrix[(r, c)];
    }
    p
}

/// Each quantity's (error, σ) in one session where the poses determine it: the nine
/// parameters, the six derived, the three gyro biases.
fn errors(t: &TrueIntrinsics, x: &Intrinsics) -> Vec<Option<(f64, f64)>> {
    let a = &x.accel;
    let truth = true_params(t);
    let mut out: Vec<Option<(f64, f64)>> = (0..9)
        .map(|i| a.determined[i].then(|| (a.params[i] - truth[i], a.covariance[(i, i)].sqrt())))
        .collect();
    let d = derived(&truth);
    for (i, e) in a.scale_ppm.iter().chain(&a.misalignment_rad).enumerate() {
        out.push(e.determined.then(|| (e.value - d[i], e.sigma)));
    }
    for i in 0..3 {
        out.push(Some((
            x.gyro.bias[i].value - t.gyro_bias[i],
            x.gyro.bias[i].sigma,
        )));
    }
    let g = x.gyro_matrix.as_ref().expect("turns between the poses");
    for i in 0..9 {
        let truth = t.gyro_matrix[(i / 3, i % 3)];
        out.push(g.determined[i].then(|| (g.params[i] - truth, g.covariance[(i, i)].sqrt())));
    }
    for i in 0..3 {
        out.push(Some((g.bias[i].value - t.gyro_bias[i], g.bias[i].sigma)));
    }
    let mut tp = accelcal::intrinsics::gyro_matrix::GyroParams::zeros();
    for i in 0..9 {
        tp[i] = t.gyro_matrix[(i / 3, i % 3)];
    }
    let d = accelcal::intrinsics::gyro_matrix::derived(&tp);
    for (i, e) in g.scale_ppm.iter().chain(&g.misalignment_rad).enumerate() {
        out.push(e.determined.then(|| (e.value - d[i], e.sigma)));
    }
    out
}

fn names() -> Vec<String> {
    let mut n: Vec<String> = PARAMETER_NAMES.iter().map(|s| s.to_string()).collect();
    n.extend(
        [
            "scale_x",
            "scale_y",
            "scale_z",
            "nonorth_xy",
            "nonorth_xz",
            "nonorth_yz",
        ]
        .map(String::from),
    );
    n.extend(["gyro_bias_x", "gyro_bias_y", "gyro_bias_z"].map(String::from));
    n.extend((0..9).map(|i| format!("gyro_matrix_{}{}", i / 3, i % 3)));
    n.extend(
        [
            "turns_gyro_bias_x",
            "turns_gyro_bias_y",
            "turns_gyro_bias_z",
        ]
        .map(String::from),
    );
    n.extend(["gyro_scale_x", "gyro_scale_y", "gyro_scale_z"].map(String::from));
    n.extend(
        accelcal::intrinsics::gyro_matrix::MISALIGNMENT_NAMES.map(|m| format!("gyro_lean_{m}")),
    );
    n
}

#[test]
fn intervals_cover_the_truth_and_the_goodness_test_keeps_its_rate() {
    // Each session: its errors, and whether each goodness test rejected (None: untestable,
    // nine poses for nine parameters).
    type Run = (
        Vec<Option<(f64, f64)>>,
        Option<bool>,
        Option<bool>,
        Option<bool>,
    );
    let runs: Vec<Run> = (0..SESSIONS)
        .into_par_iter()
        .map(|i| {
            let (t, _, x) = session(i, |_| {});
            let alpha = x.settings.alpha;
            (
                errors(&t, &x),
                x.accel.p_value.map(|p| p < alpha),
                x.gyro.p_value.map(|p| p < alpha),
                x.gyro_matrix
                    .as_ref()
                    .and_then(|g| g.p_value)
                    .map(|p| p < alpha),
            )
        })
        .collect();
    let z = accelcal::stats::normal_bound(0.05);
    let names = names();
    let mut half_width_misses = 0;
    for (q, name) in names.iter().enumerate() {
        let known: Vec<(f64, f64)> = runs.iter().filter_map(|r| r.0[q]).collect();
        let n = known.len() as u64;
        // Few poses may leave a quantity free (named, not given): at most 5 % of sessions.
        assert!(
            n * 20 >= SESSIONS * 19,
            "{name}: determined in only {n} sessions"
        );
        let (lo, hi) = binomial_band(n, 0.95, BAND_ALPHA);
        let covered = known.iter().filter(|(e, s)| e.abs() <= z * s).count() as u64;
        let half = known.iter().filter(|(e, s)| e.abs() <= 0.5 * z * s).count() as u64;
        eprintln!("{name}: {covered}/{n} covered, band [{lo}, {hi}] (half width {half})");
        assert!(
            (lo..=hi).contains(&covered),
            "{name}: {covered} of {n} outside [{lo}, {hi}]"
        );
        if !(lo..=hi).contains(&half) {
            half_width_misses += 1;
        }
    }
    assert_eq!(
        half_width_misses,
        names.len(),
        "the half-width control must fail everywhere"
    );
    for (which, k) in [("accel", 1), ("gyro", 2), ("turns", 3)] {
        let tested: Vec<bool> = runs
            .iter()
            .filter_map(|r| match k {
                1 => r.1,
                2 => r.2,
                _ => r.3,
            })
            .collect();
        let n = tested.len() as u64;
        let rejected = tested.iter().filter(|r| **r).count() as u64;
        let (lo, hi) = binomial_band(n, 0.01, BAND_ALPHA);
        eprintln!("{which} goodness: {rejected}/{n} rejected, band [{lo}, {hi}]");
        assert!(
            n * 10 >= SESSIONS * 9,
            "{which}: testable in {n} sessions only"
        );
        assert!(
            (lo..=hi).contains(&rejected),
            "{which}: {rejected} rejections"
        );
    }
}

#[test]
fn a_drift_the_model_lacks_is_rejected() {
    // 2·10⁻⁴ m/s² per second on each axis: 0.02 m/s² over a session of 12 poses, as a consumer
    // MEMS warming up.
    let drifting: Vec<bool> = (0..20)
        .into_par_iter()
        .map(|i| {
            let (_, _, x) = session(1000 + i, |s| {
                s.poses = random_poses(12, &mut Stream::new(0x1a7c2, i));
                s.accel_drift = Vector3::repeat(2e-4);
            });
            x.accel.p_value.expect("dof") < x.settings.alpha
        })
        .collect();
    let rejected = drifting.iter().filter(|r| **r).count();
    assert!(
        rejected >= 18,
        "{rejected} of 20 drifting sessions rejected"
    );
}

#[test]
fn three_poses_near_one_axis_name_what_is_missing() {
    let mut rng = Stream::new(0x1a7c1, 0);
    let truth = draw_intrinsics(&mut rng);
    let tilt =
        |r: f64, p: f64| UnitQuaternion::from_euler_angles(r.to_radians(), p.to_radians(), 0.0);
    let s = Session::consumer(vec![tilt(0.0, 0.0), tilt(5.0, 0.0), tilt(0.0, 5.0)]);
    let log = simulate(&truth, &s, &mut rng);
    let x = calibrate(&log, &Settings::new(s.gravity_m_s2)).expect("three poses");
    assert_eq!(x.detection.intervals.len(), 3);
    let free: Vec<&str> = PARAMETER_NAMES
        .iter()
        .zip(x.accel.determined)
        .filter(|(_, d)| !d)
        .map(|(n, _)| *n)
        .collect();
    assert!(free.len() >= 6, "{free:?}");
    assert!(
        x.accel.p_value.is_none(),
        "three poses leave no degree of freedom"
    );
    assert!(x.accel.scale_ppm.iter().any(|e| !e.determined));
    // The three share the sensor's −z axis up (within 5°): the pose asked for is another.
    let up = x.accel.suggested_up.expect("a pose to add");
    assert!(up.z > -0.7, "{up:?}");
    eprintln!("free {free:?}, add {up:?}");
    let json = accelcal::intrinsics::export::intrinsics_json(&x, "three.csv");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(v["accel"]["matrix"]["value"][1][0].is_null(), "{json}");
    assert_eq!(
        v["accel"]["undetermined"].as_array().unwrap().len(),
        free.len()
    );
}
