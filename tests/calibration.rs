//! The bounds hold their false-alarm rate exactly, on both sides. Under a consistent filter
//! (euler truth, matching statistics) each member of a check lies outside its band with
//! probability α_c/M, so the number of members outside per ensemble has mean α_c exactly —
//! Bonferroni's sum of per-member rates, whatever the dependence between members. Over K
//! independent ensembles that mean is tested two-sided, with its standard error estimated from
//! the per-ensemble counts: bounds that are too wide fail it as surely as bounds too narrow.
//!
//! The share is α_c = 1 (one member outside per ensemble on average) so that every check sees
//! enough excursions to measure its rate to a few per cent. For the exact statistics (mean error,
//! variance, NEES, NIS) the mean is exact; for the correlation scores it holds to the accuracy of
//! their normal approximation at N = 400, well inside the tolerance.

mod common;

use accelcal::checks::{self, Budget, CheckId};
use accelcal::config::{Config, TruthModel};
use accelcal::ensemble::{self, Ensemble};

/// Independent ensembles.
const K: u64 = 1000;
/// Realizations per ensemble.
const N: u64 = 400;
/// Each check's share: its expected number of members outside their bands per ensemble.
const SHARE: f64 = 1.0;
/// Two-sided limit on |mean − share| / standard error: a false alarm of 6.3e-5 per check,
/// 4.4e-4 for the seven.
const Z_LIMIT: f64 = 4.0;

#[test]
fn members_outside_their_bands_average_exactly_the_false_alarm_share() {
    let mut c = Config::default();
    c.profile.duration_s = 2.0;
    let (model, schedule) = common::model_of(&c);
    let model = model.with_truth(TruthModel::Euler);
    let budget = Budget::per_check(SHARE);

    let mut counts = vec![Vec::with_capacity(K as usize); CheckId::ALL.len()];
    for k in 0..K {
        let acc = Ensemble::new(&model, &schedule)
            .with_seed(1_000 + k)
            .with_realizations(N)
            .sums(|_| {});
        let stats = ensemble::EnsembleStats::from_sums(&acc, &schedule);
        let v = checks::evaluate(&stats, &budget);
        for check in &v.checks {
            counts[check.id.index()].push(check.failures as f64);
        }
    }
    let mut report = String::new();
    let mut off = Vec::new();
    let mut blind = Vec::new();
    for id in CheckId::ALL {
        let x = &counts[id.index()];
        let k = x.len() as f64;
        let mean = x.iter().sum::<f64>() / k;
        let var = x.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (k - 1.0);
        let se = (var / k).sqrt();
        let z = (mean - SHARE) / se;
        report.push_str(&format!(
            "{:<24} mean {mean:.4} ± {se:.4} (z = {z:+.2})\n",
            id.name()
        ));
        if z.is_nan() || z.abs() > Z_LIMIT {
            off.push(id.name());
        }
        // Negative control: the same counts against a rate misstated by half must fail, or the
        // test could not tell a wrong bound from a right one.
        for wrong in [0.5 * SHARE, 1.5 * SHARE] {
            if ((mean - wrong) / se).abs() <= Z_LIMIT {
                blind.push((id.name(), wrong));
            }
        }
    }
    eprintln!("members outside per ensemble, {K} ensembles of N = {N}, share {SHARE}:\n{report}");
    assert!(
        off.is_empty(),
        "mean count off its share for {off:?}:\n{report}"
    );
    assert!(
        blind.is_empty(),
        "the test cannot tell these rates from the true one: {blind:?}\n{report}"
    );
}
