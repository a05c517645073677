//! The ensemble over the drive: its statistics do not depend on the thread count, a consistent
//! filter passes the check catalogue (each realization normalized by its own covariance), and a
//! filter without the lever arm does not; with scale factors in the sensors, the 21-state filter
//! passes and the 15-state one does not.

use crate::checks::{Budget, Verdict, Verdicts, evaluate};
use crate::config::ins::InsConfig;
use crate::ins::ensemble::{Track, run};
use crate::ins::error_state::{STATES, STATES_WITH_SCALE};
use crate::ins::setup::Scenario;

/// A scenario of the drive's first `duration_s` seconds.
fn scenario(duration_s: f64, edit: impl FnOnce(&mut InsConfig)) -> Scenario {
    let mut c = InsConfig::default();
    c.drive.duration_s = duration_s;
    edit(&mut c);
    Scenario::from_config(&c).unwrap()
}

/// The verdicts on `n` realizations of `s`, at the scenario's family-wise 1 %.
fn verdicts(s: &Scenario, n: u64) -> Verdicts {
    verdicts_of::<STATES>(s, n)
}

/// [`verdicts`] of a filter of `N` error states.
fn verdicts_of<const N: usize>(s: &Scenario, n: u64) -> Verdicts {
    let stats = run::<N>(s, &Track::of(s), n).unwrap().stats;
    let v = evaluate(&stats, &Budget::study(s.false_alarm_rate));
    for c in &v.checks {
        eprintln!(
            "{:<20} {:<10} members {:>7} outside {:>5} worst {:.3} band [{:.3}, {:.3}]",
            c.definition.title,
            c.verdict.name(),
            c.members,
            c.failures,
            c.worst_value(),
            c.lower,
            c.upper
        );
    }
    v
}

#[test]
fn the_same_statistics_on_one_and_two_threads() {
    let s = scenario(20.0, |_| {});
    let track = Track::of(&s);
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run::<STATES>(&s, &track, 20).unwrap().stats)
    };
    // Debug text compares every number to the last bit and NaN (an estimate that never moves)
    // with NaN.
    assert_eq!(format!("{:?}", on(1)), format!("{:?}", on(2)));
}

#[test]
fn a_consistent_filter_passes_and_one_without_its_lever_arm_fails() {
    let n = 64;
    let s = scenario(60.0, |_| {});
    let v = verdicts(&s, n);
    let testable = v
        .checks
        .iter()
        .filter(|c| !matches!(c.verdict, Verdict::Untestable(_)))
        .count();
    assert!(
        testable >= 6,
        "only {testable} checks could fail at N = {n}"
    );
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(failed.is_empty(), "a consistent filter failed {failed:?}");
    // The antenna is 1 m from the IMU; a filter that puts it at the IMU misreads every turn.
    let s = scenario(60.0, |c| c.filter.gnss_lever_arm_m = Some([0.0; 3]));
    let v = verdicts(&s, n);
    assert!(
        v.failed().count() > 0,
        "the lever arm's absence went unseen"
    );
}

#[test]
fn a_filter_that_leaves_the_earth_rate_out_fails() {
    // The missing ω_ie (12 °/h about the body axes as the car turns) and Coriolis term (about
    // 0.2 mg at 15 m/s) look like biases that change with heading: over the whole drive the
    // filter cannot absorb them.
    let mut s = scenario(600.0, |_| {});
    s.filter_earth_rotation_rad_s = 0.0;
    let v = verdicts(&s, 48);
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(
        failed.contains(&"NEES"),
        "the Earth's rate went unseen: {failed:?}"
    );
}

#[test]
fn with_scale_factors_the_21_state_filter_passes_and_the_15_state_one_fails() {
    // 1 000 ppm on every axis: 0.01 m/s² on gravity's axis, 0.03 °/s in a 30 °/s turn.
    let scaled = |c: &mut InsConfig| {
        c.imu.gyro_scale_factor_sigma_ppm = 1000.0;
        c.imu.accel_scale_factor_sigma_ppm = 1000.0;
    };
    let n = 64;
    let s = scenario(600.0, |c| {
        scaled(c);
        c.filter.error_states = Some(21);
    });
    assert_eq!(s.error_states, STATES_WITH_SCALE);
    let v = verdicts_of::<STATES_WITH_SCALE>(&s, n);
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(failed.is_empty(), "the 21-state filter failed {failed:?}");
    // The control: the same sensors, a filter that does not know their scale factors.
    let s = scenario(120.0, scaled);
    let v = verdicts(&s, n);
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(
        failed.contains(&"NEES"),
        "unmodelled scale factors went unseen: {failed:?}"
    );
}

#[test]
fn a_21_state_filter_needs_a_prior_for_its_scale_factors() {
    let mut c = InsConfig::default();
    c.filter.error_states = Some(21);
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(e.contains("filter.gyro_scale_factor_sigma_ppm"), "{e}");
    c.filter.error_states = Some(18);
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(e.contains("filter.error_states"), "{e}");
}
