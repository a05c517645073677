use super::*;
use crate::config::Config;
use crate::ensemble::{Ensemble, EnsembleStats};
use crate::filter::{FilterSchedule, Stage};
use crate::model::Model;
use crate::state::ErrorState;

/// The statistics of a seeded ensemble of `n` realizations of a `duration_s` run (euler truth).
fn stats_of(duration_s: f64, n: u64) -> EnsembleStats {
    let mut c = Config::default();
    c.profile.duration_s = duration_s;
    let model = Model::new(&c)
        .unwrap()
        .with_truth(crate::config::TruthModel::Euler);
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats).unwrap();
    let acc = Ensemble::new(&model, &schedule)
        .with_seed(11)
        .with_realizations(n)
        .sums(|_| {});
    EnsembleStats::from_sums(&acc, &schedule)
}

/// Number of members of check `id` on `stats`.
fn count(id: CheckId, stats: &EnsembleStats) -> usize {
    id.definition().count(stats)
}

#[test]
fn copies_of_the_bias_are_counted_once() {
    let stats = stats_of(30.0, 2);
    // 150 fixes × 2 stages × 3 states, less the 149 a priori biases after the first fix.
    assert_eq!(count(CheckId::MEAN_ERROR, &stats), 900 - 149);
    assert_eq!(count(CheckId::COVARIANCE_MATCH, &stats), 900 - 149);
    assert_eq!(count(CheckId::COVARIANCE_CORRELATION, &stats), 900);
    assert_eq!(count(CheckId::NEES, &stats), 300);
    assert_eq!(count(CheckId::NIS, &stats), 150);
    assert_eq!(
        count(CheckId::RESIDUAL_WHITENESS, &stats),
        4 * 150 * 149 / 2
    );
    // The copies really are copies: same statistics.
    for i in 1..stats.fixes.len() {
        let (prior, post) = (&stats.fixes[i].prior, &stats.fixes[i - 1].post);
        let b = ErrorState::BIAS;
        assert_eq!(prior.mean_error[b], post.mean_error[b]);
        assert_eq!(prior.ensemble_cov[b][b], post.ensemble_cov[b][b]);
        assert_eq!(
            prior.orthogonality_corr[b][b],
            post.orthogonality_corr[b][b]
        );
    }
}

#[test]
fn bounded_correlation_scores_are_untestable_at_ten_realizations() {
    let stats = stats_of(30.0, 10);
    let v = evaluate(&stats, &Budget::study(0.01));
    for id in CheckId::ALL {
        let c = v.get(id);
        let expect_untestable = [CheckId::ORTHOGONALITY, CheckId::RESIDUAL_WHITENESS].contains(&id);
        assert_eq!(
            matches!(c.verdict, Verdict::Untestable(_)),
            expect_untestable,
            "{id:?}: {c:?}"
        );
        if expect_untestable {
            // Its bound is beyond √N: no member could have failed.
            assert!(c.upper >= 10f64.sqrt() && c.failures == 0);
            assert!(c.min_realizations > 10);
        }
    }
    assert!(!v.all_passed());
    // The single pair is a correlation score too: its bound 3.57 exceeds √10.
    assert_eq!(
        v.residual_pair.verdict,
        Verdict::Untestable(Untestable::TooFewRealizations { needs: 13 })
    );
}

#[test]
fn fisher_needs_more_than_three_realizations() {
    let stats = stats_of(2.0, 3);
    let v = evaluate(&stats, &Budget::study(0.01));
    assert_eq!(
        v.get(CheckId::COVARIANCE_CORRELATION).verdict,
        Verdict::Untestable(Untestable::TooFewRealizations { needs: 4 })
    );
}

#[test]
fn shares_add_up_to_the_study_wide_rate() {
    let b = Budget::study(0.01);
    approx::assert_relative_eq!(b.total(CATALOGUE.len()), 0.01, max_relative = 1e-12);
    approx::assert_relative_eq!(
        b.share(),
        0.01 / CATALOGUE.len() as f64,
        max_relative = 1e-12
    );
}

#[test]
fn a_non_finite_member_fails_and_is_the_worst() {
    let mut stats = stats_of(2.0, 50);
    stats.fixes[3].nis_avg = f64::NAN;
    let v = evaluate(&stats, &Budget::study(0.01));
    let nis = v.get(CheckId::NIS);
    assert_eq!(nis.verdict, Verdict::Fail);
    assert_eq!(nis.worst.unwrap().member, MemberId::Nis { fix: 3 });
}

#[test]
fn chi_squared_worst_takes_the_bound_of_its_side() {
    let mut stats = stats_of(2.0, 50);
    // One a posteriori NEES far below its band, one slightly above the median.
    stats.fixes[2].post.nees_avg = 0.5;
    stats.fixes[4].prior.nees_avg = 3.1;
    let v = evaluate(&stats, &Budget::study(0.01));
    let nees = v.get(CheckId::NEES);
    let worst = nees.worst.unwrap();
    assert_eq!(
        worst.member,
        MemberId::Nees {
            fix: 2,
            stage: Stage::Posterior
        }
    );
    assert_eq!(nees.bound(), nees.lower);
    assert_eq!(nees.worst_value(), 0.5);
    assert_eq!(nees.verdict, Verdict::Fail);
}
