//! The filter's covariance against an independent computation written here with plain arrays:
//! the covariance recursion in its textbook (non-Joseph) form, with an explicit 2×2 inverse.

mod common;

use accelcal::config::Config;
use approx::assert_relative_eq;
use common::plain::{M3, gps_gain, i_minus_kh, mul, transpose};

fn reference(fix_count: usize) -> Vec<(M3, M3)> {
    let dt: f64 = 0.005;
    let w = 0.0004;
    let (rp, rv) = (1.0, 0.04f64 * 0.04);
    let phi = [[1.0, dt, -dt * dt / 2.0], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]];
    let g = [-dt * dt / 2.0, -dt, 0.0];
    let mut p: M3 = [[100.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.01]];
    let mut out = Vec::new();
    for _ in 0..fix_count {
        for _ in 0..40 {
            p = mul(&mul(&phi, &p), &transpose(&phi));
            for i in 0..3 {
                for j in 0..3 {
                    p[i][j] += g[i] * g[j] * w;
                }
            }
        }
        let prior = p;
        // P⁺ = (I − K H) P⁻, H selecting position and velocity.
        p = mul(&i_minus_kh(&gps_gain(&prior, rp, rv)), &prior);
        out.push((prior, p));
    }
    out
}

#[test]
fn covariance_matches_an_independent_computation_at_several_fixes() {
    let (_, schedule) = common::model_of(&Config::default());
    let reference = reference(150);
    for i in [0, 1, 9, 49, 100, 149] {
        let (prior, post) = &reference[i];
        let fix = &schedule.fixes[i];
        for r in 0..3 {
            for c in 0..3 {
                let tol = 1e-9 * (prior[r][r] * prior[c][c]).sqrt();
                assert_relative_eq!(
                    fix.p_prior[(r, c)],
                    prior[r][c],
                    epsilon = tol,
                    max_relative = 1e-8
                );
                let tol = 1e-9 * (post[r][r] * post[c][c]).sqrt();
                assert_relative_eq!(
                    fix.p_post[(r, c)],
                    post[r][c],
                    epsilon = tol,
                    max_relative = 1e-8
                );
            }
        }
    }
}

#[test]
fn bias_becomes_observable_and_its_sigma_shrinks() {
    let (_, schedule) = common::model_of(&Config::default());
    let sigma_b = |i: usize| schedule.fixes[i].p_post[(2, 2)].sqrt();
    assert!(sigma_b(0) > sigma_b(10) && sigma_b(10) > sigma_b(149));
    // 30 s of velocity fixes at 4 cm/s pin the bias far below its 0.1 m/s² prior.
    assert!(sigma_b(149) < 0.01, "final σ_b = {}", sigma_b(149));
}
