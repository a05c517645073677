//! The Monte Carlo checks on a seeded ensemble: a filter that matches the truth passes every
//! check, and filters that assume the wrong noise fail the checks their error touches
//! (negative controls). The study-wide false-alarm rate is 1 %.

mod common;

use accelcal::checks::{CheckId, Verdict, Verdicts};
use accelcal::config::{Config, TruthModel};

fn failed(v: &Verdicts) -> Vec<&'static str> {
    v.failed().map(|c| c.id.name()).collect()
}

/// A filter whose noise statistics are wrong has the wrong gain and the wrong covariance: every
/// check that looks at spread or correlation must fail; the mean error stays zero, because the
/// filter stays unbiased.
fn assert_mistuning_detected(v: &Verdicts) {
    for id in CheckId::ALL {
        let expected = if id == CheckId::MEAN_ERROR {
            Verdict::Pass
        } else {
            Verdict::Fail
        };
        assert_eq!(
            v.get(id).verdict,
            expected,
            "{}: failed {:?}",
            id.name(),
            failed(v)
        );
    }
}

#[test]
fn euler_truth_passes_every_check() {
    let v = common::verdicts_of(&Config::default(), TruthModel::Euler);
    assert!(v.all_passed(), "failed: {:?}\n{:#?}", failed(&v), v.checks);
    assert_eq!(
        v.residual_pair.verdict,
        Verdict::Pass,
        "{:?}",
        v.residual_pair
    );
}

#[test]
fn filter_assuming_twice_the_gps_position_noise_fails() {
    let mut c = Config::default();
    c.filter.gps_position_sigma_m = Some(2.0);
    assert_mistuning_detected(&common::verdicts_of(&c, TruthModel::Euler));
}

#[test]
fn filter_assuming_100_times_the_accelerometer_noise_fails() {
    let mut c = Config::default();
    c.filter.accel_noise_var_m2_s4 = Some(100.0 * c.accelerometer.noise_var_m2_s4);
    assert_mistuning_detected(&common::verdicts_of(&c, TruthModel::Euler));
}

#[test]
fn the_same_mistuning_is_untestable_not_passed_at_twenty_realizations() {
    // At N = 20 the correlation scores cannot reach their bounds: a filter assuming 100× the
    // accelerometer noise must not be told that its errors are orthogonal and its residuals white.
    let mut c = Config::default();
    c.filter.accel_noise_var_m2_s4 = Some(100.0 * c.accelerometer.noise_var_m2_s4);
    c.ensemble.realizations = 20;
    let v = common::verdicts_of(&c, TruthModel::Euler);
    for id in [CheckId::ORTHOGONALITY, CheckId::RESIDUAL_WHITENESS] {
        assert!(
            matches!(v.get(id).verdict, Verdict::Untestable(_)),
            "{}: {:?}",
            id.name(),
            v.get(id)
        );
    }
    assert!(!v.all_passed());
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
    assert!(v.get(CheckId::COVARIANCE_MATCH).passed());
    assert!(v.get(CheckId::ORTHOGONALITY).passed());
}
