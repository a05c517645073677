//! Each sentence flipped by changing the numbers it is chosen by.

use super::super::{FixSeries, of};
use super::*;
use crate::calibrate::nis::nis_test;
use crate::state::BiasModel;

/// 200 fixes at 10 Hz whose residuals are `r(i)` with unit diag S (half of it the GPS's:
/// R = 0.5), NIS `nis`, and a bias whose filtered estimate is `b(i)` with variance 2 against a
/// smoothed 0 with variance 1.
fn series(r: impl Fn(usize) -> f64, nis: f64, b: impl Fn(usize) -> f64) -> Vec<FixSeries> {
    (0..200)
        .map(|i| FixSeries {
            t_s: 0.1 * i as f64,
            residual: [r(i), r(i)],
            s_diag: [1.0, 1.0],
            nis,
            bias_filtered: [b(i), 2.0],
            bias_smoothed: [0.0, 1.0],
        })
        .collect()
}

/// A sequence that passes every test: ±1 in a pattern with no correlation at lags 1–20.
fn white(i: usize) -> f64 {
    // The signs of a maximal-length shift register: autocorrelation −1/255 at every lag.
    let mut state = 1u8;
    for _ in 0..i % 255 {
        let bit = (state >> 7) ^ (state >> 5) ^ (state >> 4) ^ (state >> 3);
        state = (state << 1) | (bit & 1);
    }
    if state & 1 == 1 { 1.0 } else { -1.0 }
}

fn sentences(s: &[FixSeries], model: BiasModel) -> Vec<String> {
    let nis = nis_test(&s.iter().map(|f| f.nis).collect::<Vec<_>>(), 0.01);
    of(s, [0.5f64.sqrt(); 2], model, &nis, 0.01).findings
}

fn any(found: &[String], words: &str) -> bool {
    found.iter().any(|s| s.contains(words))
}

#[test]
fn a_consistent_series_says_nothing_rejects() {
    let found = sentences(&series(white, 2.0, |_| 0.0), BiasModel::Constant);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("No diagnostic rejects"), "{found:?}");
}

#[test]
fn correlated_innovations_name_their_lags_and_the_fix_rate() {
    // Residuals constant over runs of 4 fixes: correlated at lags 1–3.
    let found = sentences(&series(|i| white(i / 4), 2.0, |_| 0.0), BiasModel::Constant);
    assert!(
        any(
            &found,
            "The position innovations are correlated at lags 1–3"
        ),
        "{found:?}"
    );
    assert!(
        any(
            &found,
            "not white at 10 Hz; consider a larger filter.gps_position"
        ),
        "{found:?}"
    );
    assert!(any(
        &found,
        "The velocity innovations are correlated at lags 1–3"
    ));
    assert_eq!(lag_runs(&[1, 2, 3, 5, 7, 8]), "1–3, 5, 7–8");
    // The velocity's advice names the integration's drift, and the bias model's next step.
    let drift = "consider a larger filter.accel_noise_var_m2_s4, bias_model = \"random_walk\"";
    assert!(any(&found, drift), "{found:?}");
    let walk = BiasModel::RandomWalk {
        k_m_s2_per_sqrt_s: 0.01,
    };
    let found = sentences(&series(|i| white(i / 4), 2.0, |_| 0.0), walk);
    assert!(
        any(&found, "accel_noise_var_m2_s4, a faster bias drift"),
        "{found:?}"
    );
    // Small and slow: a lower fix rate, not the smaller σ their size suggests.
    let found = sentences(
        &series(|i| 0.3 * white(i / 4), 2.0, |_| 0.0),
        BiasModel::Constant,
    );
    assert!(
        any(
            &found,
            "rather than the smaller filter.gps_position_sigma_m"
        ),
        "{found:?}"
    );
    // Alternating signs: negatively correlated, the filter overshoots.
    let found = sentences(
        &series(
            |i| white(i / 2) * if i % 2 == 0 { 1.0 } else { -1.0 },
            2.0,
            |_| 0.0,
        ),
        BiasModel::Constant,
    );
    assert!(
        any(&found, "innovations are negatively correlated at lag"),
        "{found:?}"
    );
    assert!(any(
        &found,
        "consider a smaller filter.accel_noise_var_m2_s4"
    ));
}

#[test]
fn mean_squares_point_to_the_gps_sigma_or_the_integration() {
    // Residuals ±2 with R = 0.5 of S = 1: mean square 4, r² − (S − R) = 3.5.
    let large = series(|i| 2.0 * white(i), 8.0, |_| 0.0);
    let found = sentences(&large, BiasModel::Constant);
    assert!(
        any(&found, "The NIS sum 1600 is above its band"),
        "{found:?}"
    );
    assert!(any(
        &found,
        "The position innovations are larger than predicted"
    ));
    assert!(any(
        &found,
        "is too small; the residuals suggest about 1.9 m."
    ));
    // Large and slow: the caveat that the integration may be to blame.
    let slow = series(|i| 2.0 * white(i / 4), 8.0, |_| 0.0);
    let found = sentences(&slow, BiasModel::Constant);
    assert!(
        any(&found, "which a drifting integration explains as well"),
        "{found:?}"
    );
    // Residuals ±0.5: mean square 0.25, below; r² − (S − R) < 0: no σ suggested.
    let small = series(|i| 0.5 * white(i), 0.5, |_| 0.0);
    let found = sentences(&small, BiasModel::Constant);
    assert!(any(&found, "is below its band"), "{found:?}");
    assert!(any(
        &found,
        "is too large; the residuals are smaller than the integration's"
    ));
    // The GPS's share of S small: the integration's statistics are named.
    let mut s = series(|i| 2.0 * white(i), 8.0, |_| 0.0);
    s.iter_mut().for_each(|f| f.s_diag = [10.0, 10.0]);
    s.iter_mut()
        .for_each(|f| f.residual = f.residual.map(|r| r * 10f64.sqrt()));
    let found = sentences(&s, BiasModel::Constant);
    assert!(
        any(&found, "only 5\u{202f}% of that prediction is the GPS's"),
        "{found:?}"
    );
}

#[test]
fn a_straying_bias_suggests_its_model() {
    // d_i = b_i / √(2 − 1): 0.5 everywhere passes; 6 at one fix fails.
    let steady = sentences(&series(white, 2.0, |_| 0.5), BiasModel::Constant);
    assert!(!any(&steady, "strays"), "{steady:?}");
    let drift = |i: usize| if i == 50 { 6.0 } else { 0.5 };
    let found = sentences(&series(white, 2.0, drift), BiasModel::Constant);
    assert!(
        any(&found, "by up to 6 σ of their difference (at t = 5 s"),
        "{found:?}"
    );
    assert!(any(&found, "try bias_model = \"random_walk\""));
    let walk = BiasModel::RandomWalk {
        k_m_s2_per_sqrt_s: 0.01,
    };
    let found = sentences(&series(white, 2.0, drift), walk);
    assert!(any(
        &found,
        "a larger filter.bias_random_walk_m_s2_per_sqrt_s"
    ));
}

#[test]
fn too_many_fixes_outside_the_per_fix_band_are_named_by_time() {
    let mut s = series(white, 2.0, |_| 0.0);
    for f in s.iter_mut().skip(10).step_by(20) {
        f.nis = 30.0;
    }
    let found = sentences(&s, BiasModel::Constant);
    assert!(
        any(
            &found,
            "10 fixes lie outside the per-fix NIS band [0.01, 10.6] (10 above, 0 \
             below) where chance explains at most 6"
        ),
        "{found:?}"
    );
    assert!(any(&found, "at t = 1, 3, 5, 7, 9, … s"));
}
