//! The filter's covariance against an independent computation written here with plain arrays:
//! the covariance recursion in its textbook (non-Joseph) form, with an explicit 2×2 inverse.

mod common;

use accelcal::config::Config;
use approx::assert_relative_eq;
use common::plain::{M3, mul, transpose};

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
        // S = H P Hᵀ + R with H selecting position and velocity.
        let s = [[p[0][0] + rp, p[0][1]], [p[1][0], p[1][1] + rv]];
        let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        let s_inv = [
            [s[1][1] / det, -s[0][1] / det],
            [-s[1][0] / det, s[0][0] / det],
        ];
        // K = P Hᵀ S⁻¹ (3×2).
        let mut k = [[0.0; 2]; 3];
        for i in 0..3 {
            for j in 0..2 {
                k[i][j] = p[i][0] * s_inv[0][j] + p[i][1] * s_inv[1][j];
            }
        }
        // P⁺ = (I − K H) P⁻.
        let mut ikh = [[0.0; 3]; 3];
        for i in 0..3 {
            ikh[i][i] = 1.0;
            ikh[i][0] -= k[i][0];
            ikh[i][1] -= k[i][1];
        }
        p = mul(&ikh, &prior);
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
