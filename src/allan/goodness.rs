//! Whether the fitted model describes the measured Allan variance: a weighted sum of squared
//! residuals with its null distribution from the estimates' EDF and their correlation across τ.
//!
//! # Formula
//! r = s − Aθ̂ (the σ² estimates less the fit), T = rᵀWr with W = diag(edf_i / (2σ⁴_fit,i)).
//! Under the model r = P e, P = I − A_F H A_FᵀW (F the terms off their zero bound), e ~ (0, Σ),
//! Σ_ij = ρ_ij √(V_i V_j), V_i = 2σ⁴_fit,i / edf_i (the χ² variance of an estimate with edf_i
//! degrees of freedom; NIST SP 1065 §5.3) and ρ the correlation of the exact covariance of the
//! estimates at the fitted levels ([`super::covariance`]). T is a quadratic form in e; with
//! M = PᵀWPΣ, E(T) = tr M and Var T = 2 tr M², and T ≈ g·χ²_ν with g = Var/(2E), ν = 2E²/Var
//! (Satterthwaite, "An approximate distribution of estimates of variance components",
//! Biometrics Bulletin 2 (1946); Box, Ann. Math. Stat. 25 (1954), theorem 3.1).

use nalgebra::{DMatrix, DVector};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The rate at which the test rejects a log drawn from the model.
pub const ALPHA: f64 = 0.01;

/// The test's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goodness {
    /// T = rᵀWr.
    pub statistic: f64,
    /// ν, the Satterthwaite degrees of freedom.
    pub dof: f64,
    /// g, the scale of χ²_ν.
    pub scale: f64,
    /// P(g·χ²_ν > T).
    pub p_value: f64,
    /// The stated false-rejection rate.
    pub alpha: f64,
    /// p < α.
    pub rejected: bool,
    /// The τ of the largest standardized residual |r_i|/√V_i, s.
    pub worst_tau_s: f64,
}

/// Which covariance of the estimates the null distribution assumes: the exact one, or (the
/// negative control of the tests) the estimates taken as independent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Correlation {
    /// ρ from the exact covariance.
    Exact,
    /// ρ = I.
    Ignored,
}

/// A weighted fit as the test sees it.
#[derive(Clone, Copy, Debug)]
pub struct WeightedFit<'a> {
    /// The design matrix A.
    pub design: &'a DMatrix<f64>,
    /// The estimates σ̂², (m/s²)².
    pub avar: &'a DVector<f64>,
    /// Their EDF.
    pub edf: &'a [f64],
    /// Their τ, s.
    pub tau_s: &'a [f64],
    /// θ̂.
    pub theta: &'a DVector<f64>,
    /// (A_FᵀWA_F)⁻¹ placed in the full matrix, zero off the support F.
    pub h: &'a DMatrix<f64>,
    /// The weights W.
    pub weights: &'a DVector<f64>,
}

/// The test of the fit `f` with the exact covariance `c` of the estimates at the fitted levels.
pub fn test(f: &WeightedFit, c: &DMatrix<f64>, correlation: Correlation) -> Goodness {
    let (a, s, edf, taus, theta, h, w) =
        (f.design, f.avar, f.edf, f.tau_s, f.theta, f.h, f.weights);
    let k = s.len();
    let fitted = a * theta;
    let r = s - &fitted;
    let v: Vec<f64> = (0..k)
        .map(|i| 2.0 * fitted[i].max(f64::MIN_POSITIVE).powi(2) / edf[i])
        .collect();
    let rho = |i: usize, j: usize| {
        if i == j {
            return 1.0;
        }
        let d = c[(i, i)] * c[(j, j)];
        match correlation {
            Correlation::Exact if d > 0.0 => c[(i, j)] / d.sqrt(),
            _ => 0.0,
        }
    };
    let sigma = DMatrix::from_fn(k, k, |i, j| rho(i, j) * (v[i] * v[j]).sqrt());
    let wm = DMatrix::from_diagonal(w);
    let p = DMatrix::identity(k, k) - a * h * a.transpose() * &wm;
    let m = p.transpose() * &wm * &p * &sigma;
    let e = m.trace();
    let var = 2.0 * (&m * &m).trace();
    let statistic: f64 = (0..k).map(|i| w[i] * r[i] * r[i]).sum();
    let (scale, dof) = (var / (2.0 * e), 2.0 * e * e / var);
    let p_value = ChiSquared::new(dof)
        .ok()
        .filter(|_| dof.is_finite())
        .map_or(f64::NAN, |chi| chi.sf(statistic / scale));
    let worst = (0..k)
        .max_by(|&i, &j| (r[i].abs() / v[i].sqrt()).total_cmp(&(r[j].abs() / v[j].sqrt())))
        .unwrap_or(0);
    Goodness {
        statistic,
        dof,
        scale,
        p_value,
        alpha: ALPHA,
        rejected: p_value < ALPHA,
        worst_tau_s: taus.get(worst).copied().unwrap_or(f64::NAN),
    }
}
