//! The Gauss–Markov term of the Allan variance, fitted where a hump shows one: its σ and
//! correlation time T_c together with the other terms, a test of whether the log shows it, and
//! intervals for both.
//!
//! # Model and fit
//! σ²(τ) = Σ_j θ_j c_j(τ) + σ²·g(τ/T_c), the terms θ of [`super::fit`] (IEEE Std 952-1997,
//! annex C) and g the unit Allan variance of a first-order Gauss–Markov process
//! ([`super::gauss_markov::unit_avar`]; El-Sheimy, Hou & Niu, IEEE Trans. Instrum. Meas. 57(1),
//! 2008). For a fixed T_c the model is linear in (θ, σ²), so T_c is profiled (variable
//! projection; Golub & Pereyra, SIAM J. Numer. Anal. 10(2), 1973): at each T_c of a log grid
//! ([`GRID_PER_OCTAVE`] a factor of two, from a quarter of the shortest fitted τ to twice the
//! longest) the iterated weighted NNLS of [`super::fit`] with the column g(τ/T_c) beside the
//! others gives the weighted residual T(T_c) = rᵀWr; the least T on the grid is refined by a
//! golden-section search in ln T_c between its neighbours.
//!
//! # The test
//! The log shows the term when four things hold:
//! 1. the term improves the fit: ΔT = T_without − T_with, over the scale g of the goodness test
//!    of the fit with the term (T ≈ g·χ²_ν, [`super::goodness`]), exceeds the χ²₂ quantile at
//!    α = [`goodness::ALPHA`] (a likelihood-ratio test for the two parameters σ², T_c; Wilks,
//!    Ann. Math. Stat. 9 (1938). T_c is not defined without the term (Davies, Biometrika 74
//!    (1987)) and σ² ≥ 0 is on a bound, which move the null distribution in opposite
//!    directions: the false-alarm rate is measured in tests/allan_gauss_markov.rs, not assumed);
//! 2. the fit with the term describes the points: its goodness-of-fit test ([`super::goodness`])
//!    passes at α (a hump the model rejected with and without the term is a vibration's or a
//!    sinusoid's, not a bias's);
//! 3. σ² stands [`RESOLUTION_SIGMAS`] standard errors above zero, as every term must;
//! 4. the hump's peak, [`PEAK_U`]·T_c, lies inside the fitted τ: a T_c beyond the log is not
//!    determined by it.
//!
//! # Intervals
//! From the fit linearized at its optimum (Gauss–Newton): the Jacobian J holds the free terms'
//! columns, g(τ/T̂_c) for σ² and ∂(σ̂²g)/∂ln T_c = −σ̂² u g′(u) (u = τ/T̂_c), and the covariance of
//! (θ, σ², ln T_c) is the sandwich H·JᵀW·C·WJ·H, H = (JᵀWJ)⁻¹, as [`super::fit`] makes it.
//! C, the covariance of the estimates across τ, has no closed form for the process (its filter is
//! not piecewise polynomial, [`super::covariance`]); it is built from the process's two
//! asymptotes, the random walk K² = 2σ²/T_c below T_c and the white noise N² = 2σ²T_c above,
//! each the exact covariance beside the other terms, the smaller of the two at each pair of τ
//! (each asymptote's Allan variance bounds the process's from above). That is the assumption.
//! For σ² the correlations of that C are kept with each estimate's χ² variance 2σ⁴_fit/edf (NIST
//! SP 1065 §5.3; the EDF of the noise identified at its τ, Greenhall & Riley 2003); for ln T_c
//! the asymptotes' variances themselves, raised to at least the χ² one. Measured over 200 logs
//! (tests/allan_gauss_markov.rs, T_c = 10 s, 200 T_c long): the mean squared error over the
//! claimed variance is 0.69 for σ² (conservative) and 1.13 for ln T_c (slightly narrow); the
//! 95 % intervals cover σ in 194 of 200 logs (band [181, 197]) and T_c in 189 of the 200 that
//! resolve the term (band [181, 197]), the term fitted beside the selected model. σ² gets the
//! scaled-χ² interval with ν = 2σ̂⁴/Var(σ̂²) of every term (Satterthwaite, Biometrics Bulletin 2
//! (1946)), σ its square root; T_c the normal interval of ln T_c, exp(ln T̂_c ± z·se), positive
//! and skewed as a scale parameter is. An unresolved σ has the upper bound of
//! [`term_interval`] at the best-fitting T_c.

use nalgebra::{DMatrix, DVector};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use super::fit::{
    FitPoint, RESOLUTION_SIGMAS, Term, design, exact_covariance, sandwich, term_interval,
    weighted_fit, with_edf_variances,
};
use super::gauss_markov::{PEAK_U, unit_avar};
use super::goodness::{self, Correlation};
use super::nnls::Solution;
use crate::stats::normal_bound;

/// Points of the T_c grid per factor of two.
pub const GRID_PER_OCTAVE: f64 = 4.0;

/// Golden-section steps of the refinement (the bracket shrinks by 0.618 each).
const REFINE_STEPS: usize = 24;

/// The Gauss–Markov term of one log.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussMarkov {
    /// Whether the log shows the term (the four conditions of the [module](self)).
    pub resolved: bool,
    /// Why not, in words; `None` when resolved.
    pub reason: Option<String>,
    /// σ of the process (unit of the samples); `None` when not resolved.
    pub sigma: Option<f64>,
    /// Lower end of σ's interval; `None` when not resolved.
    pub sigma_lower: Option<f64>,
    /// Upper end of σ's interval, or, not resolved, the upper bound on σ at the best-fitting T_c
    /// (NaN when the fit could not be made).
    pub sigma_upper: f64,
    /// T_c, s; `None` when not resolved.
    pub correlation_time_s: Option<f64>,
    /// Lower end of T_c's interval, s.
    pub correlation_time_lower_s: Option<f64>,
    /// Upper end of T_c's interval, s.
    pub correlation_time_upper_s: Option<f64>,
    /// The best-fitting σ and T_c (s), resolved or not; NaN when the fit could not be made.
    pub fitted: (f64, f64),
    /// ΔT/g, the test's statistic.
    pub statistic: f64,
    /// P(χ²₂ > ΔT/g).
    pub p_value: f64,
    /// The goodness-of-fit p-value of the fit with the term ([`super::goodness`]).
    pub goodness_p_value: f64,
    /// The test's stated false-alarm rate.
    pub alpha: f64,
}

impl GaussMarkov {
    /// A term the fit could not be made for, with the reason.
    fn unfitted(reason: &str) -> Self {
        Self {
            resolved: false,
            reason: Some(reason.to_string()),
            sigma: None,
            sigma_lower: None,
            sigma_upper: f64::NAN,
            correlation_time_s: None,
            correlation_time_lower_s: None,
            correlation_time_upper_s: None,
            fitted: (f64::NAN, f64::NAN),
            statistic: f64::NAN,
            p_value: f64::NAN,
            goodness_p_value: f64::NAN,
            alpha: goodness::ALPHA,
        }
    }

    /// The σ²(τ) the term adds at its best fit (zero when the fit could not be made).
    pub fn avar_at(&self, tau_s: f64) -> f64 {
        let (sigma, tc) = self.fitted;
        if sigma.is_finite() && tc > 0.0 {
            sigma * sigma * unit_avar(tau_s / tc)
        } else {
            0.0
        }
    }
}

/// The design of `terms` with the Gauss–Markov column g(τ/T_c) last.
fn design_with(base: &DMatrix<f64>, points: &[FitPoint], tc_s: f64) -> DMatrix<f64> {
    let k = base.ncols();
    DMatrix::from_fn(points.len(), k + 1, |i, j| {
        if j < k {
            base[(i, j)]
        } else {
            unit_avar(points[i].tau_s / tc_s)
        }
    })
}

/// The covariance of the estimates at `points` for the fitted terms `theta` and the
/// Gauss–Markov process `(σ², T_c)`, by its two asymptotes ([module](self)): the exact covariance
/// with the process taken as the random walk K² = 2σ²/T_c it is for τ ≪ T_c, and as the white
/// noise N² = 2σ²T_c it is for τ ≫ T_c, the smaller of the two at each pair of τ (each asymptote's
/// Allan variance bounds the process's from above, 2u/3 ≥ g(u) ≤ 2/u).
fn covariance(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    theta: &DVector<f64>,
    (s2, tc_s): (f64, f64),
) -> DMatrix<f64> {
    let c = exact_covariance(points, samples, tau0_s, terms, theta);
    if s2 <= 0.0 {
        return c;
    }
    let with = |t: Term, extra: f64| {
        let mut terms = terms.to_vec();
        let mut theta: Vec<f64> = theta.iter().map(|x| x.max(0.0)).collect();
        match terms.iter().position(|&x| x == t) {
            Some(j) => theta[j] += extra,
            None => {
                terms.push(t);
                theta.push(extra);
            }
        }
        let theta = DVector::from_vec(theta);
        exact_covariance(points, samples, tau0_s, &terms, &theta)
    };
    let walk = with(Term::AccelerationRandomWalk, 2.0 * s2 / tc_s);
    let white = with(Term::VelocityRandomWalk, 2.0 * s2 * tc_s);
    DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| walk[(i, j)].min(white[(i, j)]))
}

/// The covariance Σ_ij = ρ_ij √(V_i V_j) with ρ the correlation of `c` and V_i = 2σ⁴_fit,i/edf_i
/// the χ² variance of each estimate for its EDF (NIST SP 1065 §5.3): the variances of the noise
/// identified at each τ, the correlations of the asymptotes' covariance.
fn with_edf_scale(c: &DMatrix<f64>, points: &[FitPoint], fitted: &DVector<f64>) -> DMatrix<f64> {
    let v: Vec<f64> = (0..points.len())
        .map(|i| 2.0 * fitted[i].max(0.0).powi(2) / points[i].edf)
        .collect();
    DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| {
        let d = c[(i, i)] * c[(j, j)];
        let rho = if i == j {
            1.0
        } else if d > 0.0 {
            c[(i, j)] / d.sqrt()
        } else {
            0.0
        };
        rho * (v[i] * v[j]).sqrt()
    })
}

/// The weighted residual rᵀWr of a constrained fit on the columns of `a`.
fn residual(points: &[FitPoint], a: &DMatrix<f64>) -> f64 {
    weighted_fit(points, a, true).map_or(f64::INFINITY, |(sol, w)| {
        let r = a * &sol.theta;
        (0..points.len())
            .map(|i| w[i] * (points[i].avar - r[i]).powi(2))
            .sum()
    })
}

/// (JᵀWJ)⁻¹ with the columns scaled to unit weighted norm before the inversion (their
/// magnitudes span many decades); `None` when singular.
fn scaled_inverse(j: &DMatrix<f64>, w: &DVector<f64>) -> Option<DMatrix<f64>> {
    let d: Vec<f64> = (0..j.ncols())
        .map(|c| {
            let n: f64 = (0..j.nrows()).map(|i| w[i] * j[(i, c)].powi(2)).sum();
            if n > 0.0 { 1.0 / n.sqrt() } else { 1.0 }
        })
        .collect();
    let js = DMatrix::from_fn(j.nrows(), j.ncols(), |i, c| j[(i, c)] * d[c]);
    let wj = DMatrix::from_fn(j.nrows(), j.ncols(), |i, c| w[i] * js[(i, c)]);
    let inv = (js.transpose() * wj).try_inverse()?;
    Some(DMatrix::from_fn(j.ncols(), j.ncols(), |a, b| {
        inv[(a, b)] * d[a] * d[b]
    }))
}

/// The ln T_c of least weighted residual: the grid, then the golden-section refinement.
fn best_ln_tc(points: &[FitPoint], base: &DMatrix<f64>) -> Option<f64> {
    let first = points.first()?.tau_s;
    let last = points.last()?.tau_s;
    let (lo, hi) = ((first / 4.0).ln(), (2.0 * last).ln());
    let step = std::f64::consts::LN_2 / GRID_PER_OCTAVE;
    let count = ((hi - lo) / step).ceil() as usize + 1;
    let cost = |x: f64| residual(points, &design_with(base, points, x.exp()));
    let grid: Vec<(f64, f64)> = (0..count)
        .map(|i| lo + i as f64 * step)
        .map(|x| (x, cost(x)))
        .collect();
    let (k, _) = grid
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1))?;
    let (mut a, mut b) = (
        grid[k.saturating_sub(1)].0,
        grid[(k + 1).min(grid.len() - 1)].0,
    );
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (cost(c), cost(d));
    for _ in 0..REFINE_STEPS {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = cost(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = cost(d);
        }
    }
    Some(if fc < fd { c } else { d })
}

/// The test's ΔT/g, its p-value and the goodness-of-fit p-value of the fit with the term: the
/// weighted residual without the term less that with it (`sol`, `w` on the design `a`), over the
/// scale g of the goodness test of the fit with it.
fn test_statistic(
    points: &[FitPoint],
    a: &DMatrix<f64>,
    base: &DMatrix<f64>,
    (sol, w): (&Solution, &DVector<f64>),
    c: &DMatrix<f64>,
) -> (f64, f64, f64) {
    let s = DVector::from_iterator(points.len(), points.iter().map(|p| p.avar));
    let edf: Vec<f64> = points.iter().map(|p| p.edf).collect();
    let taus: Vec<f64> = points.iter().map(|p| p.tau_s).collect();
    let fit = goodness::WeightedFit {
        design: a,
        avar: &s,
        edf: &edf,
        tau_s: &taus,
        theta: &sol.theta,
        h: &sol.h,
        weights: w,
    };
    let g = goodness::test(&fit, c, Correlation::Exact);
    let fitted = a * &sol.theta;
    let t_with: f64 = (0..points.len())
        .map(|i| w[i] * (s[i] - fitted[i]).powi(2))
        .sum();
    let statistic = ((residual(points, base) - t_with) / g.scale).max(0.0);
    let p_value = ChiSquared::new(2.0).map_or(f64::NAN, |chi| chi.sf(statistic));
    (statistic, p_value, g.p_value)
}

/// Var(σ̂²) with the covariance `c_sigma` and Var(ln T̂_c) with `c_tc` of the fit linearized at
/// (`sol`, T̂_c = `tc`), the Gauss–Markov column last in `a` ([module](self)).
fn linearized_variances(
    points: &[FitPoint],
    a: &DMatrix<f64>,
    (sol, w): (&Solution, &DVector<f64>),
    tc: f64,
    (c_sigma, c_tc): (&DMatrix<f64>, &DMatrix<f64>),
) -> (f64, f64) {
    let k = a.ncols() - 1;
    let s2 = sol.theta[k];
    let free: Vec<usize> = (0..k).filter(|&j| sol.free[j]).collect();
    let deriv = |u: f64| {
        let h: f64 = 1e-4;
        (unit_avar(u * h.exp()) - unit_avar(u * (-h).exp())) / (2.0 * h)
    };
    let cols = free.len() + 2;
    let jac = DMatrix::from_fn(points.len(), cols, |i, j| {
        let u = points[i].tau_s / tc;
        if j < free.len() {
            a[(i, free[j])]
        } else if j == free.len() {
            unit_avar(u)
        } else {
            -s2 * deriv(u)
        }
    });
    let Some(h) = scaled_inverse(&jac, w) else {
        return (f64::NAN, f64::NAN);
    };
    (
        sandwich(&jac, w, &h, c_sigma)[(cols - 2, cols - 2)],
        sandwich(&jac, w, &h, c_tc)[(cols - 1, cols - 1)],
    )
}

/// Why the term is not resolved, or `None` when it is ([module](self), the four conditions).
fn reason(
    (statistic, p_value, goodness_p): (f64, f64, f64),
    sigma_resolved: bool,
    peak_s: f64,
    (first, last): (f64, f64),
) -> Option<String> {
    if p_value.is_nan() || p_value >= goodness::ALPHA {
        Some(format!(
            "no hump: the term improves the fit by ΔT/g = {statistic:.3}, p = {p_value:.3} ≥ α = {}",
            goodness::ALPHA
        ))
    } else if goodness_p.is_nan() || goodness_p < goodness::ALPHA {
        Some(format!(
            "not a Gauss–Markov bias's hump: the model with the term is rejected too (goodness of fit p = {goodness_p:.2e} < α = {})",
            goodness::ALPHA
        ))
    } else if !sigma_resolved {
        Some(format!(
            "no hump: σ² is not {RESOLUTION_SIGMAS} standard errors above zero"
        ))
    } else if !(first..=last).contains(&peak_s) {
        Some(format!(
            "T_c beyond the log: the hump's peak 1.89·T_c = {peak_s:.4e} s lies outside the fitted τ, [{first:.4e}, {last:.4e}] s"
        ))
    } else {
        None
    }
}

/// Fits the Gauss–Markov term beside `terms` to `points` of a log of `samples` samples τ₀ apart,
/// tests whether the log shows it and gives its intervals at `confidence` ([module](self)).
pub fn fit_gauss_markov(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    confidence: f64,
) -> GaussMarkov {
    let k = terms.len();
    if points.len() < k + 3 {
        return GaussMarkov::unfitted("too few τ to fit two more parameters");
    }
    let base = design(points, terms);
    let Some(ln_tc) = best_ln_tc(points, &base) else {
        return GaussMarkov::unfitted("the fit is singular");
    };
    let tc = ln_tc.exp();
    let a = design_with(&base, points, tc);
    let Some((sol, w)) = weighted_fit(points, &a, true) else {
        return GaussMarkov::unfitted("the fit is singular");
    };
    let s2 = sol.theta[k];
    let fitted = &a * &sol.theta;
    let theta_terms = DVector::from_iterator(k, sol.theta.iter().take(k).copied());
    let c = covariance(points, samples, tau0_s, terms, &theta_terms, (s2, tc));
    let c_sigma = with_edf_scale(&c, points, &fitted);
    let c_tc = with_edf_variances(&c, points, &fitted);
    let (statistic, p_value, goodness_p) = test_statistic(points, &a, &base, (&sol, &w), &c_sigma);
    let (var_s2, var_ln) = linearized_variances(points, &a, (&sol, &w), tc, (&c_sigma, &c_tc));
    let (value, lower, upper) = term_interval(s2, var_s2, confidence);
    let z = normal_bound(1.0 - confidence);
    let se_ln = var_ln.max(0.0).sqrt();
    let range = (points[0].tau_s, points[points.len() - 1].tau_s);
    let sigma_resolved = value.is_some() && se_ln.is_finite();
    let reason = reason(
        (statistic, p_value, goodness_p),
        sigma_resolved,
        PEAK_U * tc,
        range,
    );
    let resolved = reason.is_none();
    let keep = |x: Option<f64>| x.filter(|_| resolved);
    GaussMarkov {
        resolved,
        reason,
        sigma: keep(value),
        sigma_lower: keep(lower),
        sigma_upper: upper,
        correlation_time_s: keep(Some(tc)),
        correlation_time_lower_s: keep(Some((ln_tc - z * se_ln).exp())),
        correlation_time_upper_s: keep(Some((ln_tc + z * se_ln).exp())),
        fitted: (s2.max(0.0).sqrt(), tc),
        statistic,
        p_value,
        goodness_p_value: goodness_p,
        alpha: goodness::ALPHA,
    }
}
