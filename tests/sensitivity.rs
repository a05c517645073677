//! The sensitivity study: the exact actual covariance of a mistuned filter against an independent
//! recursion and against Monte Carlo, and the predicted detection against the measured one.

mod common;

use accelcal::checks::CheckId;
use accelcal::config::{Config, TruthModel};
use accelcal::ensemble::{self, EnsembleStats};
use accelcal::model::Model;
use accelcal::sensitivity::{self, AssumedStatistic, Plan, actual_covariance};
use accelcal::study::Silent;
use statrs::distribution::{ChiSquared, ContinuousCDF};

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn t(a: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

fn add(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
}

/// The textbook recursion, in plain arrays: the filter's P and K from the assumed statistics, the
/// actual covariance from the filter's K and the truth's statistics. Returns the actual a
/// posteriori covariance at the last fix. `stats` are (W, M_b, σ_p, σ_v, σ_p0, σ_v0).
fn textbook(dt: f64, fix_every: usize, fixes: usize, assumed: [f64; 6], truth: [f64; 6]) -> M3 {
    let phi: M3 = [[1.0, dt, -dt * dt / 2.0], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]];
    let gamma = [-dt * dt / 2.0, -dt, 0.0];
    let q = |w: f64| -> M3 {
        std::array::from_fn(|i| std::array::from_fn(|j| gamma[i] * gamma[j] * w))
    };
    let p0 = |s: [f64; 6]| -> M3 {
        [
            [s[4] * s[4], 0.0, 0.0],
            [0.0, s[5] * s[5], 0.0],
            [0.0, 0.0, s[1]],
        ]
    };
    let (qf, qt) = (q(assumed[0]), q(truth[0]));
    let (mut p, mut pa) = (p0(assumed), p0(truth));
    for _ in 0..fixes {
        for _ in 0..fix_every {
            p = add(&mul(&mul(&phi, &p), &t(&phi)), &qf);
            pa = add(&mul(&mul(&phi, &pa), &t(&phi)), &qt);
        }
        // S = H P Hᵀ + R with H = [I₂ 0]: the upper-left 2×2 block.
        let s = [
            [p[0][0] + assumed[2] * assumed[2], p[0][1]],
            [p[1][0], p[1][1] + assumed[3] * assumed[3]],
        ];
        let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        let s_inv = [
            [s[1][1] / det, -s[0][1] / det],
            [-s[1][0] / det, s[0][0] / det],
        ];
        // K = P Hᵀ S⁻¹ (3×2).
        let k: [[f64; 2]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| p[i][0] * s_inv[0][j] + p[i][1] * s_inv[1][j])
        });
        let i_kh: M3 = std::array::from_fn(|i| {
            std::array::from_fn(|j| f64::from(u8::from(i == j)) - if j < 2 { k[i][j] } else { 0.0 })
        });
        let krk = |r: [f64; 2]| -> M3 {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| k[i][0] * r[0] * k[j][0] + k[i][1] * r[1] * k[j][1])
            })
        };
        p = add(
            &mul(&mul(&i_kh, &p), &t(&i_kh)),
            &krk([assumed[2].powi(2), assumed[3].powi(2)]),
        );
        pa = add(
            &mul(&mul(&i_kh, &pa), &t(&i_kh)),
            &krk([truth[2].powi(2), truth[3].powi(2)]),
        );
    }
    pa
}

fn stats_of(c: &Config) -> [f64; 6] {
    [
        c.filter_accel_noise_var_m2_s4(),
        c.filter_bias_var_m2_s4(),
        c.filter_gps_position_sigma_m(),
        c.filter_gps_velocity_sigma_m_s(),
        c.filter_initial_position_sigma_m(),
        c.filter_initial_velocity_sigma_m_s(),
    ]
}

#[test]
fn actual_covariance_matches_an_independent_recursion() {
    let base = Config::default();
    let truth = stats_of(&base);
    for (parameter, factor) in [
        (AssumedStatistic::AccelNoise, 0.5),
        (AssumedStatistic::GpsPosition, 4.0),
        (AssumedStatistic::GpsVelocity, 0.25),
        (AssumedStatistic::BiasPrior, 2.0),
    ] {
        let c = parameter.scaled(&base, factor);
        let (model, schedule) = common::model_of(&c);
        let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
        let tl = &model.timeline;
        let expected = textbook(tl.dt_s, tl.steps_per_fix, tl.fixes(), stats_of(&c), truth);
        let got = actual.last().unwrap().post;
        for i in 0..3 {
            for j in 0..3 {
                approx::assert_relative_eq!(got[(i, j)], expected[i][j], max_relative = 1e-6);
            }
        }
    }
}

#[test]
fn a_tuned_filter_is_its_own_actual_covariance() {
    let (model, schedule) = common::model_of(&Config::default());
    let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
    for (a, f) in actual.iter().zip(&schedule.fixes) {
        assert!((a.post - f.p_post).norm() <= 1e-9 * f.p_post.norm());
        let nees = (f.p_post_inv * a.post).trace();
        approx::assert_relative_eq!(nees, 3.0, max_relative = 1e-9);
    }
}

#[test]
fn actual_covariance_matches_the_monte_carlo_of_a_mistuned_filter() {
    let mut base = Config::default();
    base.profile.duration_s = 6.0;
    let c = AssumedStatistic::GpsPosition.scaled(&base, 0.5);
    let (model, schedule) = common::model_of(&c);
    let model = model.with_truth(TruthModel::Euler);
    let n = 4000;
    let acc = ensemble::run(&model, &schedule, 77, n, |_| {});
    let stats = EnsembleStats::from_sums(&acc, &schedule);
    let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
    // (N − 1)·P_ave/P_actual ~ χ²(N − 1) for every diagonal member: 30 fixes × 3, two-sided
    // at 1e-3 family-wise.
    let members = (actual.len() * 3) as f64;
    let chi = ChiSquared::new(n as f64 - 1.0).unwrap();
    let p = 1e-3 / members / 2.0;
    let (lo, hi) = (chi.inverse_cdf(p), chi.inverse_cdf(1.0 - p));
    for (a, f) in actual.iter().zip(&stats.fixes) {
        for k in 0..3 {
            let x = (n as f64 - 1.0) * f.post.ensemble_cov[k][k] / a.post[(k, k)];
            assert!(
                (lo..=hi).contains(&x),
                "{} s state {k}: {x} not in [{lo}, {hi}]",
                a.time_s
            );
        }
    }
    // The filter's own P is far from it: the negative control.
    let k = 0;
    let last = stats.fixes.last().unwrap();
    let claimed = schedule.fixes.last().unwrap().p_post[(k, k)];
    assert!(last.post.ensemble_cov[k][k] / claimed > 1.5);
}

#[test]
fn predicted_detection_agrees_with_the_measured_within_binomial_bounds() {
    let mut base = Config::default();
    base.profile.duration_s = 6.0;
    base.ensemble.realizations = 300;
    let plan = Plan {
        parameters: vec![
            AssumedStatistic::AccelNoise,
            AssumedStatistic::GpsPosition,
            AssumedStatistic::InitialVelocity,
        ],
        factors: vec![0.25, 0.8, 1.25],
        realizations: 300,
        ensembles: 60,
    };
    let s = sensitivity::run(&base, &plan, &mut Silent).unwrap();
    let k = plan.ensembles as f64;
    let mut compared = 0;
    for c in &s.cases {
        for id in CheckId::ALL {
            let Some(d) = c.predicted[id.index()] else {
                continue;
            };
            let measured = c.detected[id.index()];
            // 3.5 binomial standard errors around the exact bounds, and one ensemble of slack.
            let se = |p: f64| (p * (1.0 - p) / k).sqrt();
            let (lo, hi) = (
                d.lower - 3.5 * se(d.lower) - 1.0 / k,
                d.upper + 3.5 * se(d.upper) + 1.0 / k,
            );
            assert!(
                (lo..=hi).contains(&measured),
                "{} × {}: {} measured {measured}, predicted {:?}",
                c.parameter.name(),
                c.factor,
                id.name(),
                d
            );
            compared += 1;
        }
    }
    assert_eq!(compared, 9 * 4);
}

#[test]
fn half_the_accelerometer_noise_is_detected_at_10000_realizations() {
    let base = Config::default();
    let plan = Plan {
        parameters: vec![AssumedStatistic::AccelNoise],
        factors: vec![0.5],
        realizations: 10_000,
        ensembles: 5,
    };
    let s = sensitivity::run(&base, &plan, &mut Silent).unwrap();
    let c = &s.cases[0];
    let best = CheckId::ALL
        .iter()
        .copied()
        .filter(|id| c.predicted[id.index()].is_some())
        .max_by(|a, b| c.detection(*a).total_cmp(&c.detection(*b)))
        .unwrap();
    assert!(c.detection(best) >= 0.95, "{best:?}: {}", c.detection(best));
    assert!(c.predicted[best.index()].unwrap().lower >= 0.95);
    assert!(c.detected[best.index()] >= 0.95, "{:?}", c.detected);
    // Half the noise σ: the filter is overconfident.
    assert!(c.expected_nees_final > 3.5);
    assert!(c.actual_sigma_final[2] > c.claimed_sigma_final[2]);
    let _ = Model::new(&base).unwrap();
}

#[test]
fn the_same_seed_gives_the_same_numbers_on_any_thread_count() {
    let mut base = Config::default();
    base.profile.duration_s = 2.0;
    let plan = Plan {
        parameters: vec![AssumedStatistic::GpsVelocity],
        factors: vec![0.5, 2.0],
        realizations: 200,
        ensembles: 3,
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| sensitivity::run(&base, &plan, &mut Silent).unwrap())
    };
    assert_eq!(on(1), on(3));
}
