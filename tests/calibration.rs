//! The checks hold their stated false-alarm rate: over many independent ensembles of a correct
//! filter (euler truth, matching statistics), each check fails in at most a fraction α of them.
//! A mis-derived bound (wrong degrees of freedom, a one-sided quantile, a missing Bonferroni
//! factor) makes a family fail far more often than that.

mod common;

use accelcal::checks;
use accelcal::config::{Config, TruthModel};
use accelcal::ensemble;

#[test]
fn each_check_fails_at_most_at_its_false_alarm_rate() {
    // α = 0.1 so that false alarms are frequent enough to count.
    let alpha = 0.1;
    let ensembles = 300u64;
    let mut c = Config::default();
    c.profile.duration_s = 2.0;
    c.checks.false_alarm_rate = alpha;
    let (model, schedule) = common::model_of(&c);
    let model = model.with_truth(TruthModel::Euler);

    let mut failures = std::collections::BTreeMap::<&str, u64>::new();
    for seed in 0..ensembles {
        let acc = ensemble::run(&model, &schedule, 1_000 + seed, 400, |_| {});
        let stats = ensemble::EnsembleStats::from_sums(&acc, &schedule);
        let v = checks::evaluate(&stats, &model.timeline, alpha, model.residual_pair_s);
        for check in &v.checks {
            *failures.entry(check.id).or_default() += u64::from(!check.passed);
        }
    }
    // Under the null hypothesis each count is at most Binomial(300, α) (Bonferroni is
    // conservative). Its mean is 30 and its standard deviation 5.2; 3.1 standard deviations above
    // the mean (≈ 1e-3 one-sided) is 46.
    eprintln!("failures out of {ensembles} ensembles at α = {alpha}: {failures:?}");
    let n = ensembles as f64;
    let limit = n * alpha + 3.1 * (n * alpha * (1.0 - alpha)).sqrt();
    for (id, count) in &failures {
        assert!(
            (*count as f64) <= limit,
            "{id} failed {count} of {ensembles} ensembles; at most {limit:.0} expected"
        );
    }
    assert_eq!(failures.len(), 7);
}
