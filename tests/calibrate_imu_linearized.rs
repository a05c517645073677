//! The likelihood linearized about one run of the three-axis filter (`calibrate::imu::linearized`)
//! against the likelihood of rerunning the filter: equal at the run's own statistics, close
//! near them (within a tenth of the χ²₁ threshold an interval's end rests on), on the shipped
//! comma2k19 minute and on a simulated drive.

use accelcal::calibrate::imu::linearized::Linearized;
use accelcal::calibrate::imu::noise::log_likelihood;
use accelcal::calibrate::imu::{CONSUMER, Settings};
use accelcal::config::ins::InsConfig;
use accelcal::input::csv::read::LogText;
use accelcal::input::gnss_csv::read_gnss;
use accelcal::input::imu_csv::{ImuSpan, read_steps};
use accelcal::input::records::{GnssRow, ImuStep};
use accelcal::ins::error_state::STATES_WITH_SCALE;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;

/// The shipped minute, held.
fn comma() -> (Vec<GnssRow>, Vec<ImuStep>) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/comma2k19_3d");
    let gnss = std::fs::read(format!("{dir}/gnss.csv")).expect("shipped");
    let imu = std::fs::read(format!("{dir}/imu.csv")).expect("shipped");
    let rows = read_gnss(&LogText::new("gnss.csv", gnss)).expect("reads");
    let (steps, _, _) = read_steps(&LogText::new("imu.csv", imu), CONSUMER.axes).expect("reads");
    (rows, steps)
}

/// The first 240 s of the simulated drive, held.
fn simulated() -> (Vec<GnssRow>, Vec<ImuStep>) {
    let (rows, steps, _) = simulated_with_span();
    (rows, steps)
}

/// [`simulated`] with the IMU log's span.
fn simulated_with_span() -> (Vec<GnssRow>, Vec<ImuStep>, ImuSpan) {
    let mut config = InsConfig::default();
    config.drive.duration_s = 240.0;
    let scenario = Scenario::from_config(&config).expect("valid");
    let (mut imu, mut gnss, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    write_realization(&scenario, 3, &mut imu, &mut gnss, &mut truth).expect("in memory");
    let rows = read_gnss(&LogText::new("gnss.csv", gnss)).expect("reads");
    let (steps, span, _) = read_steps(&LogText::new("imu.csv", imu), CONSUMER.axes).expect("reads");
    (rows, steps, span)
}

/// Assumptions moved from `s`: each key the search takes changed by a factor or a shift.
fn moves(s: &Settings) -> Vec<(&'static str, Settings)> {
    let mut out = Vec::new();
    let mut push = |name, f: &dyn Fn(&mut Settings)| {
        let mut t = *s;
        f(&mut t);
        out.push((name, t));
    };
    push("horizontal sigma x1.5", &|t| {
        t.gnss_position_sigma_m[0] *= 1.5;
        t.gnss_position_sigma_m[1] *= 1.5;
    });
    push("vertical sigma x0.7", &|t| {
        t.gnss_position_sigma_m[2] *= 0.7
    });
    push("velocity sigma x0.6", &|t| t.gnss_velocity_sigma_m_s *= 0.6);
    push("vrw x2", &|t| t.accel_vrw_m_s_per_sqrt_s *= 2.0);
    push("arw x0.5", &|t| t.gyro_arw_rad_per_sqrt_s *= 0.5);
    push("gyro bias rw x3", &|t| {
        t.gyro_bias_random_walk_rad_s_per_sqrt_s *= 3.0
    });
    push("offset +0.03 s", &|t| t.gnss_time_offset_s += 0.03);
    push("offset -0.05 s", &|t| t.gnss_time_offset_s -= 0.05);
    out
}

/// The χ²₁ quantile at 95 % over two: the fall in ℓ at a 95 % profile interval's end.
const END_FALL: f64 = 1.92;

/// The linearized ℓ against the rerun's: equal at the run's statistics (to 10⁻⁹ relative), and
/// within `tolerance` at each move of [`moves`], each of which moves the rerun's ℓ by more than
/// `tolerance` (the control: a model that ignored the statistics would fail).
fn check((rows, steps): &(Vec<GnssRow>, Vec<ImuStep>), s: &Settings, tolerance: f64) {
    accelcal::with_layout!(s.layout(), N => check_of::<N>((rows, steps), s, tolerance));
}

/// [`check`] with the filter of `N` error states.
fn check_of<const N: usize>((rows, steps): (&[GnssRow], &[ImuStep]), s: &Settings, tolerance: f64) {
    let model = Linearized::<N>::new(rows, steps, s).expect("runs");
    let fixes = model.len() - 2;
    let exact = log_likelihood(rows, steps, s, fixes);
    let linear = model.log_likelihood(s, fixes);
    assert!(
        (exact - linear).abs() <= 1e-9 * exact.abs(),
        "at the run's own statistics: {exact} against {linear}"
    );
    for (what, t) in moves(s) {
        let e = log_likelihood(rows, steps, &t, fixes);
        let l = model.log_likelihood(&t, fixes);
        eprintln!(
            "{what}: rerun {e:.3}, linearized {l:.3}, rerun moved {:.3}",
            e - exact
        );
        assert!((l - e).abs() <= tolerance, "{what}: {l} against {e}");
        assert!(
            (e - exact).abs() > tolerance,
            "{what} does not move ℓ: {e} {exact}"
        );
    }
}

/// On the simulated drive, whose model the filter holds, the linearized ℓ stays within an
/// eighth of an interval end's fall of the rerun's at every move.
#[test]
fn linear_likelihood_is_the_runs_on_a_simulated_drive() {
    check(&simulated(), &CONSUMER, END_FALL / 8.0);
}

/// The same with the six scale factors as states (21): the linearized model carries them.
#[test]
fn linear_likelihood_is_the_runs_with_the_scale_factors() {
    let s = Settings {
        error_states: STATES_WITH_SCALE,
        ..CONSUMER
    };
    check(&simulated(), &s, END_FALL / 8.0);
}

/// On the comma2k19 minute (a vibrating phone, smoothed fixes) within half an end's fall.
#[test]
fn linear_likelihood_is_the_runs_on_the_comma_minute() {
    check(&comma(), &CONSUMER, END_FALL / 2.0);
}

/// A raised flag stops the search: the estimate is `Cancelled` without a full search's work;
/// the control, the same call with the flag down, gives an estimate.
#[test]
fn a_raised_flag_stops_the_noise_search() {
    use accelcal::calibrate::imu::noise::{ImuKey, estimate_cancellable};
    use accelcal::progress::Cancel;
    let (rows, steps, span) = simulated_with_span();
    let keys = [ImuKey::GnssHorizontalSigma, ImuKey::GnssTimeOffset];
    let down = Cancel::new();
    let started = std::time::Instant::now();
    let found = estimate_cancellable(&rows, &steps, &span, (&CONSUMER, &keys, 0.95), &down);
    let full = started.elapsed();
    assert!(matches!(found, Ok(Some(_))));
    let raised = Cancel::new();
    raised.cancel();
    let started = std::time::Instant::now();
    let stopped = estimate_cancellable(&rows, &steps, &span, (&CONSUMER, &keys, 0.95), &raised);
    assert!(stopped.is_err());
    assert!(
        started.elapsed() < full / 2,
        "{:?} against {full:?}",
        started.elapsed()
    );
}
