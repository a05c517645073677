//! The report's three cases: the world the filter's model assumes (A), the closed-form physics
//! with point samples (B) and with interval means, a delta-velocity output (C). Case C is
//! consistent; case B's mean error is deterministic, predicted by one noise-free pass, and its
//! achieved velocity accuracy is far worse than the filter claims.

use std::sync::OnceLock;

use accelcal::checks::{CheckId, Verdict};
use accelcal::config::{AccelerometerOutput, Case, Config, TruthModel};
use accelcal::model::Model;
use accelcal::study::{Silent, Study};

mod common;

/// The default study: N = 10 000 per case.
fn study() -> &'static Study {
    static STUDY: OnceLock<Study> = OnceLock::new();
    STUDY.get_or_init(|| Study::run(&Model::new(&Config::default()).unwrap(), &mut Silent).unwrap())
}

const MODEL_WORLD: Case = Case::REPORT[0];
const POINT_SAMPLES: Case = Case::REPORT[1];
const INTERVAL_MEANS: Case = Case::REPORT[2];

#[test]
fn the_report_runs_the_three_cases_in_order() {
    let cases: Vec<Case> = study().cases.iter().map(|o| o.case).collect();
    assert_eq!(cases, [MODEL_WORLD, POINT_SAMPLES, INTERVAL_MEANS]);
    assert_eq!(
        (POINT_SAMPLES.truth, POINT_SAMPLES.output),
        (TruthModel::Analytic, AccelerometerOutput::Sample)
    );
    // The recorded realization belongs to a consistent, physically real case.
    assert_eq!(study().realization_case, INTERVAL_MEANS);
}

#[test]
fn interval_means_make_the_closed_form_truth_consistent_at_20000_realizations() {
    let mut c = Config::default();
    c.ensemble.realizations = 20_000;
    c.ensemble.truth = TruthModel::Analytic;
    c.accelerometer.output = AccelerometerOutput::IntervalMean;
    let v = common::verdicts_of(&c, TruthModel::Analytic);
    let failed: Vec<&str> = v.failed().map(|c| c.id.name()).collect();
    assert!(v.all_passed(), "failed: {failed:?}");
}

#[test]
fn point_samples_under_the_closed_form_truth_fail_the_mean_error_as_before() {
    let o = study().case(POINT_SAMPLES);
    assert_eq!(o.verdicts.get(CheckId::MEAN_ERROR).verdict, Verdict::Fail);
    // The spread is unaffected.
    assert_eq!(
        o.verdicts.get(CheckId::COVARIANCE_MATCH).verdict,
        Verdict::Pass
    );
}

#[test]
fn the_prediction_explains_every_case_mean_error_within_the_check_bound() {
    for o in &study().cases {
        let bound = o.verdicts.get(CheckId::MEAN_ERROR).upper;
        assert!(
            o.prediction.worst_se <= bound,
            "{}: worst |e_ave − m| = {} standard errors, bound {bound}",
            o.case,
            o.prediction.worst_se
        );
    }
    // Without the prediction the point-sample mean error is hundreds of standard errors off.
    let b = study().case(POINT_SAMPLES);
    assert!(b.verdicts.get(CheckId::MEAN_ERROR).worst_value() > 100.0);
    // In the model world the noise-free pass has no error at all.
    let a = study().case(MODEL_WORLD);
    assert!(
        a.prediction
            .fixes
            .iter()
            .flatten()
            .flatten()
            .all(|m| *m == 0.0)
    );
    approx::assert_relative_eq!(a.prediction.predicted_nees_final, 3.0);
    // The deterministic error of point samples raises the predicted NEES, as measured.
    let rel = (b.prediction.predicted_nees_final - b.prediction.measured_nees_final).abs()
        / b.prediction.predicted_nees_final;
    assert!(
        b.prediction.predicted_nees_final > 4.0 && rel < 0.05,
        "{:?}",
        b.prediction
    );
}

#[test]
fn achieved_rms_matches_sigma_within_5_percent_in_the_consistent_cases() {
    let s = study();
    for case in [MODEL_WORLD, INTERVAL_MEANS] {
        let o = s.case(case);
        assert!(o.verdicts.all_passed(), "{case}");
        for (rms, fix) in o.achieved_rms.iter().zip(&s.schedule.fixes) {
            for (k, achieved) in rms.iter().enumerate() {
                let ratio = achieved / fix.p_post[(k, k)].sqrt();
                assert!(
                    (ratio - 1.0).abs() <= 0.05,
                    "{case}: state {k} at {} s: achieved/claimed = {ratio}",
                    fix.time_s
                );
            }
        }
    }
}

#[test]
fn point_samples_reach_far_less_velocity_accuracy_than_claimed() {
    let s = study();
    let o = s.case(POINT_SAMPLES);
    let last = s.schedule.fixes.last().unwrap();
    let ratio = o.achieved_rms_final()[1] / last.p_post[(1, 1)].sqrt();
    assert!(ratio >= 1.3, "velocity achieved/claimed = {ratio}");
}

#[test]
fn cases_draw_independent_random_numbers() {
    // The model world and the interval-mean case share no draws: their centred statistics
    // differ (with common streams they would be identical).
    let s = study();
    let a = &s.case(MODEL_WORLD).run.stats.fixes[75].post.ensemble_cov;
    let c = &s.case(INTERVAL_MEANS).run.stats.fixes[75].post.ensemble_cov;
    assert_ne!(a, c);
}
