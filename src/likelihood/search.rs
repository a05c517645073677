//! A bounded maximum of a smooth function of a few variables: Newton's method with
//! finite-difference derivatives, an active set at the bounds and a backtracking line search.
//!
//! The log-likelihood of a drive is smooth in the logarithms of the noise statistics and costs
//! O(fixes) to evaluate; with at most four variables a Newton step from differences (1 + 2m +
//! m(m − 1)/2 evaluations for m free variables) converges in a handful of iterations, fewer
//! evaluations than a quasi-Newton or a simplex method need for the same accuracy.

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

/// Step of the finite differences, in the variables' units (logarithms: a relative 10⁻³).
const STEP: f64 = 1e-3;
/// The largest Newton step in any variable (a factor e³ ≈ 20 in a statistic).
const MAX_STEP: f64 = 3.0;
/// Converged when an iteration gains less than this (log-likelihood units).
const GAIN_TOLERANCE: f64 = 1e-7;
/// Iterations of Newton's method at most.
const MAX_ITERATIONS: usize = 100;

/// A function of a few variables on a box, counting its evaluations.
pub struct Objective<'f> {
    f: &'f (dyn Fn(&[f64]) -> f64 + Sync),
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    evaluations: AtomicU64,
}

/// A maximum of an [`Objective`] over some of its variables, the others held.
#[derive(Clone, Debug)]
pub struct Maximum {
    /// Where.
    pub u: Vec<f64>,
    /// The function's value there.
    pub value: f64,
    /// The Hessian there by finite differences, over every variable searched (zero rows and
    /// columns for the held ones).
    pub hessian: Vec<Vec<f64>>,
}

impl<'f> Objective<'f> {
    /// `f` on the box [lo, hi].
    pub fn new(f: &'f (dyn Fn(&[f64]) -> f64 + Sync), lo: Vec<f64>, hi: Vec<f64>) -> Self {
        Self {
            f,
            lo,
            hi,
            evaluations: AtomicU64::new(0),
        }
    }

    /// Evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// f(u), a non-finite value as −∞.
    pub fn value(&self, u: &[f64]) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let v = (self.f)(u);
        if v.is_finite() { v } else { f64::NEG_INFINITY }
    }

    fn clamp(&self, u: &mut [f64]) {
        for ((x, lo), hi) in u.iter_mut().zip(&self.lo).zip(&self.hi) {
            *x = x.clamp(*lo, *hi);
        }
    }

    /// The gradient and Hessian over the variables `free` at `u` (value `fu`): central
    /// differences for the gradient and the diagonal, forward differences for the rest; the
    /// 2m + m(m − 1)/2 evaluations in parallel (each independent of the others, so the result
    /// does not depend on the threads).
    fn derivatives(&self, u: &[f64], fu: f64, free: &[usize]) -> (Vec<f64>, Vec<Vec<f64>>) {
        let n = u.len();
        let mut g = vec![0.0; n];
        let mut h = vec![vec![0.0; n]; n];
        let mut moves: Vec<Vec<(usize, f64)>> = Vec::new();
        for &i in free {
            moves.push(vec![(i, STEP)]);
            moves.push(vec![(i, -STEP)]);
        }
        for (a, &i) in free.iter().enumerate() {
            for &j in &free[a + 1..] {
                moves.push(vec![(i, STEP), (j, STEP)]);
            }
        }
        let values: Vec<f64> = moves
            .par_iter()
            .map(|m| {
                let mut v = u.to_vec();
                for &(i, d) in m {
                    v[i] += d;
                }
                self.value(&v)
            })
            .collect();
        let mut plus = vec![0.0; n];
        for (k, &i) in free.iter().enumerate() {
            let (fp, fm) = (values[2 * k], values[2 * k + 1]);
            plus[i] = fp;
            g[i] = (fp - fm) / (2.0 * STEP);
            h[i][i] = (fp - 2.0 * fu + fm) / (STEP * STEP);
        }
        let mut k = 2 * free.len();
        for (a, &i) in free.iter().enumerate() {
            for &j in &free[a + 1..] {
                let hij = (values[k] - plus[i] - plus[j] + fu) / (STEP * STEP);
                h[i][j] = hij;
                h[j][i] = hij;
                k += 1;
            }
        }
        (g, h)
    }

    /// The maximum over the variables `free`, from `u0` (the others held at `u0`'s values),
    /// with the Hessian there.
    pub fn maximize(&self, u0: &[f64], free: &[usize]) -> Maximum {
        let mut m = self.climb(u0, free);
        let (_, hessian) = self.derivatives(&m.u, m.value, free);
        m.hessian = hessian;
        m
    }

    /// The maximum over the variables `free`, from `u0`, without its Hessian (empty): a
    /// profile's inner search, which needs the value only.
    pub fn climb(&self, u0: &[f64], free: &[usize]) -> Maximum {
        let mut u = u0.to_vec();
        self.clamp(&mut u);
        let mut fu = self.value(&u);
        for _ in 0..MAX_ITERATIONS {
            let (g, h) = self.derivatives(&u, fu, free);
            // Variables at a bound whose gradient points out of the box stay there.
            let moving: Vec<usize> = free
                .iter()
                .copied()
                .filter(|&i| {
                    !(u[i] <= self.lo[i] && g[i] < 0.0 || u[i] >= self.hi[i] && g[i] > 0.0)
                })
                .collect();
            if moving.is_empty() {
                break;
            }
            let d = newton_step(&g, &h, &moving);
            let Some((un, fnew)) = self.line_search(&u, fu, &d) else {
                break;
            };
            let gain = fnew - fu;
            (u, fu) = (un, fnew);
            if gain < GAIN_TOLERANCE {
                break;
            }
        }
        Maximum {
            u,
            value: fu,
            hessian: Vec::new(),
        }
    }

    /// The first of d, d/2, d/4, … (projected onto the box) that increases f.
    fn line_search(&self, u: &[f64], fu: f64, d: &[f64]) -> Option<(Vec<f64>, f64)> {
        let mut t = 1.0;
        for _ in 0..40 {
            let mut v: Vec<f64> = u.iter().zip(d).map(|(x, d)| x + t * d).collect();
            self.clamp(&mut v);
            if v == u {
                return None;
            }
            let fv = self.value(&v);
            if fv > fu {
                return Some((v, fv));
            }
            t *= 0.5;
        }
        None
    }
}

/// The step solving (−H + λ·I)·d = g over the `moving` variables, λ ≥ 0 the smallest (from 0,
/// then growing) that makes the matrix positive definite; no longer than [`MAX_STEP`] in any
/// variable.
fn newton_step(g: &[f64], h: &[Vec<f64>], moving: &[usize]) -> Vec<f64> {
    let m = moving.len();
    let scale = moving.iter().map(|&i| h[i][i].abs()).fold(1e-12, f64::max);
    let mut lambda = 0.0;
    let mut d = vec![0.0; g.len()];
    for _ in 0..80 {
        let a = nalgebra::DMatrix::from_fn(m, m, |r, c| {
            -h[moving[r]][moving[c]] + if r == c { lambda } else { 0.0 }
        });
        if let Some(chol) = a.cholesky() {
            let b = nalgebra::DVector::from_fn(m, |r, _| g[moving[r]]);
            let x = chol.solve(&b);
            for (r, &i) in moving.iter().enumerate() {
                d[i] = x[r];
            }
            break;
        }
        lambda = if lambda == 0.0 {
            1e-8 * scale
        } else {
            lambda * 4.0
        };
    }
    let longest = d.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
    if longest > MAX_STEP {
        d.iter_mut().for_each(|x| *x *= MAX_STEP / longest);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_an_interior_maximum_and_stops_at_a_bound() {
        // A concave quadratic with a correlated Hessian, maximum at (1, −2, 0.5).
        let f = |u: &[f64]| {
            let d = [u[0] - 1.0, u[1] + 2.0, u[2] - 0.5];
            -(3.0 * d[0] * d[0] + 2.0 * d[0] * d[1] + d[1] * d[1] + 5.0 * d[2] * d[2])
        };
        let o = Objective::new(&f, vec![-10.0; 3], vec![10.0; 3]);
        let m = o.maximize(&[4.0, 4.0, 4.0], &[0, 1, 2]);
        for (x, t) in m.u.iter().zip([1.0, -2.0, 0.5]) {
            assert!((x - t).abs() < 1e-5, "{:?}", m.u);
        }
        assert!((m.hessian[0][1] + 2.0).abs() < 1e-2, "{:?}", m.hessian);
        // The bound u₂ ≤ 0 holds it there; the others still maximise (u₀, u₁ do not depend
        // on u₂).
        let o = Objective::new(&f, vec![-10.0; 3], vec![10.0, 10.0, 0.0]);
        let m = o.maximize(&[4.0, 4.0, -4.0], &[0, 1, 2]);
        assert_eq!(m.u[2], 0.0);
        assert!((m.u[0] - 1.0).abs() < 1e-5 && (m.u[1] + 2.0).abs() < 1e-5);
        // Holding a variable: the conditional maximum, u₁ = −2 − (u₀ − 1) at u₀ = 3.
        let m = o.maximize(&[3.0, 0.0, 0.0], &[1, 2]);
        assert_eq!(m.u[0], 3.0);
        assert!((m.u[1] + 4.0).abs() < 1e-5, "{:?}", m.u);
        assert!(o.evaluations() > 0);
    }

    #[test]
    fn a_function_that_is_not_concave_still_climbs() {
        // Rosenbrock's valley, negated: the maximum at (1, 1).
        let f = |u: &[f64]| -(100.0 * (u[1] - u[0] * u[0]).powi(2) + (1.0 - u[0]).powi(2));
        let o = Objective::new(&f, vec![-5.0; 2], vec![5.0; 2]);
        let m = o.maximize(&[-1.2, 1.0], &[0, 1]);
        assert!(
            (m.u[0] - 1.0).abs() < 1e-3 && (m.u[1] - 1.0).abs() < 1e-3,
            "{:?}",
            m.u
        );
    }
}
