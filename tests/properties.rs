//! Property tests: for random valid parameters the filter's covariance stays symmetric and
//! positive definite over many cycles, and estimates stay finite.

mod common;

use accelcal::config::Config;
use accelcal::filter::FilterSchedule;
use accelcal::model::Model;
use accelcal::realization;
use proptest::prelude::*;

/// (accelerometer rate, GPS rate) pairs that divide.
const RATES: [(f64, f64); 5] = [
    (200.0, 5.0),
    (100.0, 10.0),
    (50.0, 1.0),
    (400.0, 20.0),
    (200.0, 50.0),
];

fn config_strategy() -> impl Strategy<Value = Config> {
    (
        0..RATES.len(),
        2u32..=500,
        1e-8f64..1.0,
        1e-6f64..1.0,
        1e-3f64..100.0,
        1e-4f64..10.0,
        1e-2f64..100.0,
        1e-3f64..10.0,
        any::<bool>(),
    )
        .prop_map(|(rate, fixes, w, bvar, sp, sv, p0, v0, at_start)| {
            let mut c = Config::default();
            let (ra, rg) = RATES[rate];
            c.accelerometer.sample_rate_hz = ra;
            c.gps.sample_rate_hz = rg;
            // A whole number of GPS periods, within the fix limit whatever fix_at_start says.
            c.profile.duration_s = f64::from(fixes) / rg;
            c.accelerometer.noise_var_m2_s4 = w;
            c.accelerometer.bias_var_m2_s4 = bvar;
            c.gps.position_sigma_m = sp;
            c.gps.velocity_sigma_m_s = sv;
            c.initial.position_sigma_m = p0;
            c.initial.velocity_sigma_m_s = v0;
            c.gps.fix_at_start = at_start;
            c
        })
}

fn assert_spd(p: &accelcal::state::StateMatrix, what: &str) {
    let asym = (p - p.transpose()).abs().max();
    assert!(asym <= 1e-12 * p.abs().max(), "{what}: asymmetry {asym}");
    assert!(p.cholesky().is_some(), "{what}: not positive definite: {p}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn covariance_stays_symmetric_positive_definite(config in config_strategy()) {
        let model = Model::new(&config).expect("generated configurations are valid");
        let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
        prop_assert_eq!(schedule.fixes.len(), model.timeline.fixes());
        for f in &schedule.fixes {
            assert_spd(&f.p_prior, "P⁻");
            assert_spd(&f.p_post, "P⁺");
            // The update never increases the variance of any component.
            for k in 0..3 {
                prop_assert!(f.p_post[(k, k)] <= f.p_prior[(k, k)] * (1.0 + 1e-12));
            }
        }
    }

    #[test]
    fn estimates_stay_finite(config in config_strategy(), seed in any::<u64>()) {
        let model = Model::new(&config).expect("valid");
        let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
        let r = realization::record(&model, &schedule, seed, 0);
        prop_assert_eq!(r.samples.len(), model.timeline.steps + 1);
        for f in &r.fixes {
            prop_assert!(f.post.iter().chain(&f.prior).chain(&f.residual).all(|x| x.is_finite()));
        }
    }
}

#[test]
fn covariance_stays_positive_definite_over_many_cycles() {
    // Ten hours at 200 Hz with 5 Hz fixes: 180,000 update cycles. The covariance recursion needs
    // no ensemble, so the time grid is built directly, past the ensemble's fix limit.
    let model = Model::new(&Config::default()).unwrap();
    let timeline = accelcal::model::Timeline {
        dt_s: 0.005,
        steps: 7_200_000,
        steps_per_fix: 40,
        fix_steps: (1..=180_000).map(|i| 40 * i).collect(),
    };
    let schedule = FilterSchedule::new(&timeline, &model.filter_stats).expect("positive definite");
    assert_eq!(schedule.fixes.len(), 180_000);
    for f in &schedule.fixes {
        assert_spd(&f.p_post, "P⁺");
    }
}
