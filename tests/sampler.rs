//! The exact sampler of an ensemble's fix-level sums: its draws have the moments the actual
//! covariance of the mistuned filter gives them, and the filter's own covariance is rejected by
//! the same test (the negative control).

mod common;

use accelcal::config::{Config, TruthModel};
use accelcal::ensemble::EnsembleStats;
use accelcal::filter::Stage;
use accelcal::random::Stream;
use accelcal::sensitivity::sampler::Sampler;
use accelcal::sensitivity::{AssumedStatistic, actual_covariance};
use statrs::distribution::{ContinuousCDF, Normal};

const N: u64 = 300;
const DRAWS: usize = 20_000;
/// Family-wise false-alarm rate of each test below.
const ALPHA: f64 = 1e-3;

/// Two-sided normal bound for one of `members` members at family-wise rate [`ALPHA`].
fn bound(members: usize) -> f64 {
    -Normal::standard().inverse_cdf(ALPHA / members as f64 / 2.0)
}

/// Variances of the three states a priori and a posteriori at one fix.
type Stages = [[f64; 3]; 2];

/// Draws of the ensemble statistics of the filter assuming half the GPS velocity σ, with the
/// variances against which to normalize them: the actual ones, or the filter's own.
fn draws() -> (Vec<EnsembleStats>, Vec<Stages>, Vec<Stages>, Vec<f64>) {
    let mut base = Config::default();
    base.profile.duration_s = 6.0;
    let c = AssumedStatistic::GpsVelocity.scaled(&base, 0.5);
    let (model, schedule) = common::model_of(&c);
    let model = model.with_truth(TruthModel::Euler);
    let sampler = Sampler::new(
        &model.timeline,
        &schedule,
        &model.truth_stats,
        N,
        model.residual_pair,
    );
    let mut rng = Stream::new(2024, 0);
    let stats = (0..DRAWS)
        .map(|_| EnsembleStats::from_sums(&sampler.draw(&mut rng), &schedule))
        .collect();
    let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
    let diag = |p: &accelcal::state::StateMatrix| std::array::from_fn(|k| p[(k, k)]);
    let actual_var = actual
        .iter()
        .map(|a| [diag(&a.prior), diag(&a.post)])
        .collect();
    let claimed_var = schedule
        .fixes
        .iter()
        .map(|f| [diag(&f.p_prior), diag(&f.p_post)])
        .collect();
    let expected_nees = actual
        .iter()
        .zip(&schedule.fixes)
        .map(|(a, f)| (f.p_post_inv * a.post).trace())
        .collect();
    (stats, actual_var, claimed_var, expected_nees)
}

/// For every fix, stage and state: the z-score of the mean over the draws of (ensemble variance / var),
/// whose expectation is 1 when `var` is the actual variance (the ensemble variance of N
/// realizations is var·χ²(N − 1)/(N − 1)), and the z-score of the mean of the squared normalized
/// mean error √N·ē/√var, which is 1 when var is right.
fn scores(stats: &[EnsembleStats], var: &[Stages]) -> Vec<f64> {
    let d = stats.len() as f64;
    let mut z = Vec::new();
    for (i, stages) in var.iter().enumerate() {
        for (stage, v) in Stage::ALL.into_iter().zip(stages) {
            for (k, &var_k) in v.iter().enumerate() {
                let ratio: f64 = stats
                    .iter()
                    .map(|s| s.fixes[i].stage(stage).ensemble_cov[k][k] / var_k)
                    .sum::<f64>()
                    / d;
                z.push((ratio - 1.0) / (2.0 / ((N - 1) as f64 * d)).sqrt());
                let mean_sq: f64 = stats
                    .iter()
                    .map(|s| N as f64 * s.fixes[i].stage(stage).mean_error[k].powi(2) / var_k)
                    .sum::<f64>()
                    / d;
                z.push((mean_sq - 1.0) / (2.0 / d).sqrt());
            }
        }
    }
    z
}

#[test]
fn draws_have_the_moments_of_the_actual_covariance_and_not_of_the_filters() {
    let (stats, actual_var, claimed_var, expected_nees) = draws();
    let z = scores(&stats, &actual_var);
    let b = bound(z.len());
    let worst = z.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(worst <= b, "worst |z| {worst} > {b}");

    // The average NEES: its mean over the draws is tr(P⁻¹·P_actual) at every fix.
    let b = bound(expected_nees.len());
    for (i, &expected) in expected_nees.iter().enumerate() {
        let x: Vec<f64> = stats.iter().map(|s| s.fixes[i].post.nees_avg).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (x.len() - 1) as f64).sqrt();
        let zi = (mean - expected) / (sd / (x.len() as f64).sqrt());
        assert!(zi.abs() <= b, "fix {i}: NEES {mean} vs {expected}, z {zi}");
    }

    // Negative control: the filter's own covariance, which the mistuned filter gets wrong.
    let z = scores(&stats, &claimed_var);
    let outside = z.iter().filter(|x| x.abs() > bound(z.len())).count();
    assert!(outside > z.len() / 4, "{outside} of {} outside", z.len());
}

#[test]
fn draws_do_not_depend_on_the_thread_count() {
    let mut base = Config::default();
    base.profile.duration_s = 2.0;
    let c = AssumedStatistic::AccelNoise.scaled(&base, 2.0);
    let (model, schedule) = common::model_of(&c);
    let model = model.with_truth(TruthModel::Euler);
    let sampler = Sampler::new(
        &model.timeline,
        &schedule,
        &model.truth_stats,
        N,
        model.residual_pair,
    );
    let budget = accelcal::checks::Budget::study(0.5);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| sampler.detection(&schedule, &budget, 300, 7))
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert!(one.iter().flatten().any(|&p| p > 0.0 && p < 1.0), "{one:?}");
}
