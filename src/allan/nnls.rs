//! Weighted least squares with every coefficient non-negative.
//!
//! min_θ Σ_i w_i (s_i − (Aθ)_i)² subject to θ ≥ 0 (Lawson & Hanson, *Solving Least Squares
//! Problems*, 1974, ch. 23). The Allan model has at most five columns, so instead of the active-set
//! iteration every support (subset of free columns) is tried: the optimum of the convex problem is
//! the unconstrained solution on its own support, and every feasible support solution is a feasible
//! point, so the feasible support solution of least weighted residual is the optimum — exactly, with
//! no iteration to converge. The columns are scaled to unit weighted norm before the normal
//! equations are inverted (their magnitudes span twenty decades over the τ of a long log).

use nalgebra::{DMatrix, DVector};

/// The solution on one support: θ (zeros off the support) and H = (A_FᵀWA_F)⁻¹ placed in a
/// full-size matrix (zeros off the support).
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// The coefficients.
    pub theta: DVector<f64>,
    /// (A_FᵀWA_F)⁻¹ on the support F, zero elsewhere.
    pub h: DMatrix<f64>,
    /// Whether each column is in the support.
    pub free: Vec<bool>,
}

/// The weighted least-squares solution of `a`θ ≈ `s` on the columns `free` only; `None` when
/// the normal equations are singular.
pub fn solve_on(
    a: &DMatrix<f64>,
    s: &DVector<f64>,
    w: &DVector<f64>,
    free: &[bool],
) -> Option<Solution> {
    let cols: Vec<usize> = (0..a.ncols()).filter(|&j| free[j]).collect();
    let k = cols.len();
    let mut theta = DVector::zeros(a.ncols());
    let mut h = DMatrix::zeros(a.ncols(), a.ncols());
    if k > 0 {
        let scale: Vec<f64> = cols
            .iter()
            .map(|&j| {
                let n: f64 = (0..a.nrows()).map(|i| w[i] * a[(i, j)].powi(2)).sum();
                if n > 0.0 { 1.0 / n.sqrt() } else { 1.0 }
            })
            .collect();
        let af = DMatrix::from_fn(a.nrows(), k, |i, c| a[(i, cols[c])] * scale[c]);
        let wa = DMatrix::from_fn(a.nrows(), k, |i, c| w[i] * af[(i, c)]);
        let hs = (af.transpose() * &wa).try_inverse()?;
        let ts = &hs * (wa.transpose() * s);
        for (c, &j) in cols.iter().enumerate() {
            theta[j] = ts[c] * scale[c];
            for (d, &l) in cols.iter().enumerate() {
                h[(j, l)] = hs[(c, d)] * scale[c] * scale[d];
            }
        }
    }
    Some(Solution {
        theta,
        h,
        free: free.to_vec(),
    })
}

/// The non-negative weighted least-squares solution; `None` when every support is singular.
pub fn nnls(a: &DMatrix<f64>, s: &DVector<f64>, w: &DVector<f64>) -> Option<Solution> {
    let k = a.ncols();
    let mut best: Option<(f64, Solution)> = None;
    for mask in 0u32..(1 << k) {
        let free: Vec<bool> = (0..k).map(|j| mask & (1 << j) != 0).collect();
        let Some(sol) = solve_on(a, s, w, &free) else {
            continue;
        };
        if sol.theta.iter().any(|&t| t < 0.0) {
            continue;
        }
        let r = s - a * &sol.theta;
        let cost: f64 = (0..r.len()).map(|i| w[i] * r[i] * r[i]).sum();
        if best.as_ref().is_none_or(|(c, _)| cost < *c) {
            best = Some((cost, sol));
        }
    }
    best.map(|(_, s)| s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_negative_unconstrained_coefficient_is_set_to_zero() {
        // s = 1 + x with a third column that, free, would take a negative coefficient.
        let a = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0]);
        let s = DVector::from_vec(vec![3.0, 2.0, 1.0, 0.5]);
        let w = DVector::from_element(4, 1.0);
        let free = solve_on(&a, &s, &w, &[true, true]).unwrap();
        assert!(free.theta[1] < 0.0);
        let c = nnls(&a, &s, &w).unwrap();
        assert_eq!(c.theta[1], 0.0);
        assert!((c.theta[0] - 6.5 / 4.0).abs() < 1e-12, "{}", c.theta[0]);
        assert_eq!(c.free, vec![true, false]);
    }
}
