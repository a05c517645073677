//! The noise terms from the Allan variance: a weighted least-squares fit of
//!
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²·τ/3 + R²·τ²/2
//!
//! (IEEE Std 952-1997, annex C; IEEE Std 1293-2018: Q quantization, N velocity random walk, B
//! bias instability, K acceleration random walk, R rate ramp), linear in the squared terms
//! θ = (Q², N², B², K², R²), with θ ≥ 0 ([`super::nnls`]) and the weights of the estimates' χ²
//! distributions, w = edf / (2σ⁴), σ² taken from the fit itself (iterated, so that the weights do
//! not follow the estimates' own scatter). Every τ with an EDF enters, the long ones with the
//! little weight their few degrees of freedom give them.
//!
//! The fit's nominal covariance (AᵀWA)⁻¹ treats the estimates as independent. They are not
//! (neighbouring τ share their data), so the covariance reported is the sandwich
//! H·AᵀW·C·WA·H, H = (A_FᵀWA_F)⁻¹ over the terms F off their zero bound, with C the exact
//! covariance of the estimates for the fitted white-phase, white-rate and random-walk levels
//! ([`super::covariance`]). The bias-instability and rate-ramp terms have no such closed form and
//! enter C not at all: with a strong flicker floor the intervals of the other terms are too narrow
//! by its share, which the goodness-of-fit test ([`super::goodness`]) is there to catch.
//!
//! Each squared term gets a scaled-χ² interval with ν = 2θ̂²/Var(θ̂) degrees of freedom
//! (Satterthwaite), which keeps the skew of a term that few long-τ estimates determine; the
//! term's interval is its square root. A term whose estimate is not [`RESOLUTION_SIGMAS`]
//! standard errors above zero is unresolved: it has an upper bound and no value. The bound is
//! never below what the whiskers of the τ that show it demand, given the others ([`whisker_floor`]).

use nalgebra::{DMatrix, DVector};

use super::covariance::{NoiseLevels, avar_covariance_matrix};
use super::edf::chi_squared_interval;
use super::goodness::{self, Correlation, Goodness};
use super::nnls::{Solution, nnls, solve_on};
use crate::stats::{Tail, chi_squared_quantile, normal_bound};

/// A term must stand this many standard errors above zero to be reported as a value (a
/// false detection rate of 0.13 % when the term is absent).
pub const RESOLUTION_SIGMAS: f64 = 3.0;

/// Reweighting passes of the fit.
const PASSES: usize = 4;

/// A noise term of the Allan variance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Term {
    /// Quantization Q, m/s: σ² = 3Q²/τ² (slope −1 in σ).
    Quantization,
    /// Velocity random walk N, m/s/√s: σ² = N²/τ (slope −½).
    VelocityRandomWalk,
    /// Bias instability B, m/s²: σ² = (2 ln 2/π) B² (slope 0).
    BiasInstability,
    /// Acceleration random walk K, m/s²/√s: σ² = K²τ/3 (slope +½).
    AccelerationRandomWalk,
    /// Rate ramp R, m/s³: σ² = R²τ²/2 (slope +1; a linear trend of the bias).
    RateRamp,
}

impl Term {
    /// Every term, in the order of θ.
    pub const ALL: [Term; 5] = [
        Term::Quantization,
        Term::VelocityRandomWalk,
        Term::BiasInstability,
        Term::AccelerationRandomWalk,
        Term::RateRamp,
    ];

    /// ∂σ²/∂θ at τ: the term's column of the design matrix.
    pub fn coefficient(self, tau_s: f64) -> f64 {
        match self {
            Term::Quantization => 3.0 / (tau_s * tau_s),
            Term::VelocityRandomWalk => 1.0 / tau_s,
            Term::BiasInstability => 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI,
            Term::AccelerationRandomWalk => tau_s / 3.0,
            Term::RateRamp => tau_s * tau_s / 2.0,
        }
    }

    /// The slope of σ(τ) on log–log axes.
    pub fn slope(self) -> f64 {
        match self {
            Term::Quantization => -1.0,
            Term::VelocityRandomWalk => -0.5,
            Term::BiasInstability => 0.0,
            Term::AccelerationRandomWalk => 0.5,
            Term::RateRamp => 1.0,
        }
    }

    /// The key of the term in `allan.json`'s `fit`.
    pub fn key(self) -> &'static str {
        match self {
            Term::Quantization => "quantization_m_s",
            Term::VelocityRandomWalk => "velocity_random_walk_m_s_per_sqrt_s",
            Term::BiasInstability => "bias_instability_m_s2",
            Term::AccelerationRandomWalk => "acceleration_random_walk_m_s2_per_sqrt_s",
            Term::RateRamp => "rate_ramp_m_s3",
        }
    }
}

/// One Allan variance estimate the fit uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitPoint {
    /// Averaging factor m.
    pub m: usize,
    /// τ = m·τ₀, s.
    pub tau_s: f64,
    /// σ̂²(τ), (m/s²)².
    pub avar: f64,
    /// Equivalent degrees of freedom of σ̂²(τ).
    pub edf: f64,
}

/// A fitted term with its interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermEstimate {
    /// The term.
    pub term: Term,
    /// The estimate (√θ̂); `None` when unresolved.
    pub value: Option<f64>,
    /// Lower end of the interval; `None` when unresolved.
    pub lower: Option<f64>,
    /// Upper end of the interval, or the upper bound of an unresolved term.
    pub upper: f64,
    /// θ̂, the squared term as fitted (≥ 0 in the constrained fit).
    pub squared: f64,
    /// Standard error of θ̂ from the sandwich covariance (of the unconstrained fit for a term
    /// at its zero bound).
    pub squared_sigma: f64,
    /// Standard error of θ̂ by the nominal (AᵀWA)⁻¹, taking the estimates as independent.
    pub squared_sigma_nominal: f64,
}

/// The fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// Every fitted term, in the order of [`Term::ALL`].
    pub terms: Vec<TermEstimate>,
    /// The selected model's terms ([`super::select`]); the rest of `terms` are absent, bounded.
    pub model: Vec<Term>,
    /// The points fitted.
    pub points: Vec<FitPoint>,
    /// The interval's confidence.
    pub confidence: f64,
    /// Whether the model describes the points.
    pub goodness: Goodness,
    /// The same test with a wrong Σ, the negative control of the tests: the estimates taken as
    /// independent, each with as many degrees of freedom as it has overlapping differences
    /// (n + 1 − 2m) instead of its EDF.
    pub goodness_naive: Goodness,
}

impl Fit {
    /// The estimate of `term`, if fitted.
    pub fn term(&self, term: Term) -> Option<&TermEstimate> {
        self.terms.iter().find(|t| t.term == term)
    }

    /// The fitted σ²(τ) with θ̂ as fitted.
    pub fn avar_at(&self, tau_s: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| t.squared * t.term.coefficient(tau_s))
            .sum()
    }
}

/// The design matrix of `terms` at the τ of `points`.
pub(super) fn design(points: &[FitPoint], terms: &[Term]) -> DMatrix<f64> {
    DMatrix::from_fn(points.len(), terms.len(), |i, j| {
        terms[j].coefficient(points[i].tau_s)
    })
}

/// The iterated weighted fit of `points` on the columns of `a`, constrained (θ ≥ 0) or not, with
/// the weights of the last pass; `None` when the normal equations are singular.
pub(super) fn weighted_fit(
    points: &[FitPoint],
    a: &DMatrix<f64>,
    constrained: bool,
) -> Option<(Solution, DVector<f64>)> {
    let s = DVector::from_iterator(points.len(), points.iter().map(|p| p.avar));
    let mut predicted = s.clone();
    let mut out = None;
    for _ in 0..PASSES {
        let w = DVector::from_fn(points.len(), |i, _| {
            let var = if predicted[i] > 0.0 && predicted[i].is_finite() {
                predicted[i]
            } else {
                points[i].avar
            };
            points[i].edf / (2.0 * var * var)
        });
        let sol = if constrained {
            nnls(a, &s, &w)?
        } else {
            solve_on(a, &s, &w, &vec![true; a.ncols()])?
        };
        predicted = a * &sol.theta;
        out = Some((sol, w));
    }
    out
}

/// The interval of a squared term θ̂ with variance `var` at `confidence`, as (value, lower,
/// upper) of √θ.
///
/// # Formula
/// Resolved (θ̂ > 3σ): ν = 2θ̂²/σ², θ ∈ [νθ̂/χ²_{1−p/2}(ν), νθ̂/χ²_{p/2}(ν)], p = 1 − confidence;
/// unresolved: θ ≤ max(θ̂, 0) + z_{1−p/2}·σ.
pub fn term_interval(theta: f64, var: f64, confidence: f64) -> (Option<f64>, Option<f64>, f64) {
    let sigma = var.max(0.0).sqrt();
    let p = (1.0 - confidence) / 2.0;
    if theta > RESOLUTION_SIGMAS * sigma && sigma > 0.0 {
        let nu = 2.0 * theta * theta / var;
        let lo = nu * theta / chi_squared_quantile(nu, p, Tail::Upper);
        let hi = nu * theta / chi_squared_quantile(nu, p, Tail::Lower);
        (Some(theta.sqrt()), Some(lo.sqrt()), hi.sqrt())
    } else {
        let bound = theta.max(0.0) + normal_bound(2.0 * p) * sigma;
        (None, None, bound.sqrt())
    }
}

/// A point shows a term where its share c_t(τ)/σ̂²(τ) is at least this part of the largest.
pub const SHOWING_SHARE: f64 = 0.5;

/// The least squared bound of `terms[t]` that the lower whiskers of the points where the term
/// would show allow, given the other terms at `theta`.
///
/// # Formula
/// θ_t ≥ max_i (L_i² − Σ_{j≠t} θ_j c_j(τ_i)) / c_t(τ_i), L_i the lower end of σ̂(τ_i)'s χ²
/// interval at `confidence` (NIST SP 1065, eq. 45), over the points i whose share
/// c_t(τ_i)/σ̂²(τ_i) is at least [`SHOWING_SHARE`] of the largest (the longest τ for K and R, the
/// shortest for Q, the curve's floor for B): elsewhere a point's chance excess over the others,
/// divided by the term's tiny column there, would demand a K far above what the longest τ allows.
pub fn whisker_floor(
    points: &[FitPoint],
    terms: &[Term],
    theta: &[f64],
    t: usize,
    confidence: f64,
) -> f64 {
    let share = |p: &FitPoint| terms[t].coefficient(p.tau_s) / p.avar;
    let largest = points.iter().map(share).fold(0.0, f64::max);
    points
        .iter()
        .filter(|p| share(p) >= SHOWING_SHARE * largest)
        .map(|p| {
            let lower = chi_squared_interval(p.avar.sqrt(), p.edf, confidence).0;
            let others: f64 = (0..terms.len())
                .filter(|&j| j != t)
                .map(|j| theta[j].max(0.0) * terms[j].coefficient(p.tau_s))
                .sum();
            (lower * lower - others).max(0.0) / terms[t].coefficient(p.tau_s)
        })
        .fold(0.0, f64::max)
}

/// The sandwich covariance H·AᵀW·C·WA·H of a solution.
pub(super) fn sandwich(
    a: &DMatrix<f64>,
    w: &DVector<f64>,
    h: &DMatrix<f64>,
    c: &DMatrix<f64>,
) -> DMatrix<f64> {
    let wa = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| w[i] * a[(i, j)]);
    h * (wa.transpose() * c * &wa) * h
}

/// Fits `terms` to `points` of a log of `samples` samples τ₀ apart with θ ≥ 0, with intervals
/// at `confidence`; `None` when the fit is singular (fewer points than terms).
pub fn fit(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    confidence: f64,
) -> Option<Fit> {
    estimate(points, samples, tau0_s, terms, confidence, true)
}

/// The fit as it was before the constraint: unconstrained, a term's θ̂ may be negative, and no
/// whisker floor on the bounds. Kept for the tests' negative control.
pub fn fit_unconstrained(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    confidence: f64,
) -> Option<Fit> {
    estimate(points, samples, tau0_s, terms, confidence, false)
}

/// The exact covariance of the estimates at `points` for the white-phase, white-rate and
/// random-walk levels of `theta`.
pub(super) fn exact_covariance(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    theta: &DVector<f64>,
) -> DMatrix<f64> {
    let level = |t: Term| {
        terms
            .iter()
            .position(|&x| x == t)
            .map_or(0.0, |j| theta[j].max(0.0))
    };
    let levels = NoiseLevels {
        white_phase: level(Term::Quantization) / (tau0_s * tau0_s),
        white_rate: level(Term::VelocityRandomWalk) / tau0_s,
        rate_walk: level(Term::AccelerationRandomWalk) * tau0_s,
    };
    let factors: Vec<usize> = points.iter().map(|p| p.m).collect();
    let c = avar_covariance_matrix(samples, &factors, &levels);
    DMatrix::from_fn(points.len(), points.len(), |i, j| c[i][j])
}

/// The covariance `c` with each variance raised to at least the χ² variance 2σ⁴_fit/edf of its
/// estimate, the correlations kept: C′_ij = ρ_ij √(V′_i V′_j), V′_i = max(C_ii, 2σ⁴_fit,i/edf_i).
/// The exact covariance knows only white phase, white rate and random-walk noise; where flicker
/// (B) dominates, the EDF of the noise identified at that τ (Greenhall & Riley 2003) carries its
/// share of the variance, and the correlation of the other noises stands in for its own.
pub(super) fn with_edf_variances(
    c: &DMatrix<f64>,
    points: &[FitPoint],
    fitted: &DVector<f64>,
) -> DMatrix<f64> {
    let k = points.len();
    let v: Vec<f64> = (0..k)
        .map(|i| c[(i, i)].max(2.0 * fitted[i].max(0.0).powi(2) / points[i].edf))
        .collect();
    DMatrix::from_fn(k, k, |i, j| {
        if i == j {
            return v[i];
        }
        let d = c[(i, i)] * c[(j, j)];
        if d > 0.0 {
            c[(i, j)] / d.sqrt() * (v[i] * v[j]).sqrt()
        } else {
            0.0
        }
    })
}

/// The goodness-of-fit test of `sol`, and the negative control's (see [`Fit::goodness_naive`]).
fn goodness_tests(
    points: &[FitPoint],
    samples: usize,
    a: &DMatrix<f64>,
    sol: &Solution,
    w: &DVector<f64>,
    c: &DMatrix<f64>,
) -> (Goodness, Goodness) {
    let s = DVector::from_iterator(points.len(), points.iter().map(|p| p.avar));
    let edf: Vec<f64> = points.iter().map(|p| p.edf).collect();
    let taus: Vec<f64> = points.iter().map(|p| p.tau_s).collect();
    let naive_edf: Vec<f64> = points
        .iter()
        .map(|p| (samples + 1 - 2 * p.m) as f64)
        .collect();
    let naive_w = DVector::from_fn(points.len(), |i, _| naive_edf[i] / edf[i] * w[i]);
    let naive_h = solve_on(a, &s, &naive_w, &sol.free).map_or(sol.h.clone(), |n| n.h);
    let exact_fit = goodness::WeightedFit {
        design: a,
        avar: &s,
        edf: &edf,
        tau_s: &taus,
        theta: &sol.theta,
        h: &sol.h,
        weights: w,
    };
    let naive_fit = goodness::WeightedFit {
        edf: &naive_edf,
        h: &naive_h,
        weights: &naive_w,
        ..exact_fit
    };
    let exact = goodness::test(&exact_fit, c, Correlation::Exact);
    let naive = goodness::test(&naive_fit, c, Correlation::Ignored);
    (exact, naive)
}

fn estimate(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    confidence: f64,
    constrained: bool,
) -> Option<Fit> {
    if points.len() < terms.len() {
        return None;
    }
    let a = design(points, terms);
    let (sol, w) = weighted_fit(points, &a, constrained)?;
    let theta = &sol.theta;
    let c = exact_covariance(points, samples, tau0_s, terms, theta);
    let c = if constrained {
        with_edf_variances(&c, points, &(&a * theta))
    } else {
        c
    };
    let cov = sandwich(&a, &w, &sol.h, &c);
    // The unconstrained direction of a term at its zero bound.
    let s = DVector::from_iterator(points.len(), points.iter().map(|p| p.avar));
    let free = solve_on(&a, &s, &w, &vec![true; terms.len()]);
    let free_cov = free.as_ref().map(|f| sandwich(&a, &w, &f.h, &c));
    let z = normal_bound(1.0 - confidence);
    let theta_list: Vec<f64> = theta.iter().copied().collect();
    let estimates = terms
        .iter()
        .enumerate()
        .map(|(j, &term)| {
            let var = if sol.free[j] {
                cov[(j, j)]
            } else {
                free_cov.as_ref().map_or(f64::NAN, |c| c[(j, j)])
            };
            let (mut value, mut lower, mut upper) = term_interval(theta[j], var, confidence);
            if constrained && value.is_none() {
                let mut bound = upper * upper;
                if let (Some(f), Some(fc)) = (&free, &free_cov) {
                    bound = bound.max(f.theta[j].max(0.0) + z * fc[(j, j)].max(0.0).sqrt());
                }
                bound = bound.max(whisker_floor(points, terms, &theta_list, j, confidence));
                (value, lower, upper) = (None, None, bound.sqrt());
            }
            TermEstimate {
                term,
                value,
                lower,
                upper,
                squared: theta[j],
                squared_sigma: var.max(0.0).sqrt(),
                squared_sigma_nominal: sol.h[(j, j)].max(0.0).sqrt(),
            }
        })
        .collect();
    let (goodness, goodness_naive) = goodness_tests(points, samples, &a, &sol, &w, &c);
    Some(Fit {
        terms: estimates,
        model: terms.to_vec(),
        points: points.to_vec(),
        confidence,
        goodness,
        goodness_naive,
    })
}
