//! The Monte Carlo checks on a seeded ensemble: a filter that matches the truth passes every
//! check, and filters that assume the wrong noise fail the checks their error touches
//! (negative controls). Each check holds a 1 % family-wise false-alarm rate.

mod common;

use accelcal::config::{Config, TruthModel};

/// A filter whose noise statistics are wrong has the wrong gain and the wrong covariance: every
/// check that looks at spread or correlation must fail.
fn assert_mistuning_detected(v: &accelcal::checks::Verdicts) {
    let f = failed(v);
    for id in [
        "covariance_match",
        "covariance_correlation",
        "nees",
        "nis",
        "orthogonality",
        "residual_whiteness",
    ] {
        assert!(f.contains(&id), "{id} should fail, failed: {f:?}");
    }
}

fn failed(v: &accelcal::checks::Verdicts) -> Vec<&'static str> {
    v.checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| c.id)
        .collect()
}

#[test]
fn euler_truth_passes_every_check() {
    let v = common::verdicts_of(&Config::default(), TruthModel::Euler);
    assert!(v.all_passed(), "failed: {:?}\n{:#?}", failed(&v), v.checks);
    assert!(v.residual_pair.passed, "{:?}", v.residual_pair);
}

#[test]
fn filter_assuming_twice_the_gps_position_noise_fails() {
    let mut c = Config::default();
    c.filter.gps_position_sigma_m = Some(2.0);
    let v = common::verdicts_of(&c, TruthModel::Euler);
    assert_mistuning_detected(&v);
    // The filter stays unbiased: its mean error is still zero.
    assert!(v.get("mean_error").unwrap().passed);
}

#[test]
fn filter_assuming_100_times_the_accelerometer_noise_fails() {
    let mut c = Config::default();
    c.filter.accel_noise_var_m2_s4 = Some(100.0 * c.accelerometer.noise_var_m2_s4);
    let v = common::verdicts_of(&c, TruthModel::Euler);
    assert_mistuning_detected(&v);
}

#[test]
fn analytic_truth_biases_the_mean_error_but_not_the_spread() {
    // The filter's model (eq. 5) assumes the truth is Euler-integrated; the closed-form truth
    // differs from it by a deterministic drift that shows as a mean error, not as extra variance.
    let v = common::verdicts_of(&Config::default(), TruthModel::Analytic);
    let f = failed(&v);
    assert!(
        f.contains(&"mean_error") && f.contains(&"nees"),
        "failed: {f:?}"
    );
    assert!(v.get("covariance_match").unwrap().passed);
    assert!(v.get("orthogonality").unwrap().passed);
}
