//! The noise terms from the Allan variance: a weighted least-squares fit of
//!
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²·τ/3
//!
//! (IEEE Std 952-1997, annex C; IEEE Std 1293-2018: Q quantization, N velocity random walk, B
//! bias instability, K acceleration random walk), linear in the squared terms θ = (Q², N², B²,
//! K²), with the weights of the estimates' χ² distributions, w = edf / (2σ⁴), σ² taken from the
//! fit itself (iterated, so that the weights do not follow the estimates' own scatter).
//!
//! The fit's nominal covariance (AᵀWA)⁻¹ treats the estimates as independent. They are not
//! (neighbouring τ share their data), so the covariance reported is the sandwich
//! H·AᵀW·C·WA·H, H = (AᵀWA)⁻¹, with C the exact covariance of the estimates for the fitted
//! white-phase, white-rate and random-walk levels ([`super::covariance`]). The bias-instability
//! term has no such closed form and enters C not at all: with a strong flicker floor the
//! intervals of the other terms are too narrow by its share.
//!
//! Each squared term gets a scaled-χ² interval with ν = 2θ̂²/Var(θ̂) degrees of freedom
//! (Satterthwaite), which keeps the skew of a term that few long-τ estimates determine; the
//! term's interval is its square root. A term whose estimate is not [`RESOLUTION_SIGMAS`]
//! standard errors above zero is unresolved: it has an upper bound and no value.

use nalgebra::{DMatrix, DVector};

use super::covariance::{NoiseLevels, avar_covariance_matrix};
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
}

impl Term {
    /// Every term, in the order of θ.
    pub const ALL: [Term; 4] = [
        Term::Quantization,
        Term::VelocityRandomWalk,
        Term::BiasInstability,
        Term::AccelerationRandomWalk,
    ];

    /// ∂σ²/∂θ at τ: the term's column of the design matrix.
    pub fn coefficient(self, tau_s: f64) -> f64 {
        match self {
            Term::Quantization => 3.0 / (tau_s * tau_s),
            Term::VelocityRandomWalk => 1.0 / tau_s,
            Term::BiasInstability => 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI,
            Term::AccelerationRandomWalk => tau_s / 3.0,
        }
    }

    /// The slope of σ(τ) on log–log axes.
    pub fn slope(self) -> f64 {
        match self {
            Term::Quantization => -1.0,
            Term::VelocityRandomWalk => -0.5,
            Term::BiasInstability => 0.0,
            Term::AccelerationRandomWalk => 0.5,
        }
    }

    /// The key of the term in `allan.json`'s `fit`.
    pub fn key(self) -> &'static str {
        match self {
            Term::Quantization => "quantization_m_s",
            Term::VelocityRandomWalk => "velocity_random_walk_m_s_per_sqrt_s",
            Term::BiasInstability => "bias_instability_m_s2",
            Term::AccelerationRandomWalk => "acceleration_random_walk_m_s2_per_sqrt_s",
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
    /// θ̂, the squared term as fitted (may be negative for an absent term).
    pub squared: f64,
    /// Standard error of θ̂ from the sandwich covariance.
    pub squared_sigma: f64,
    /// Standard error of θ̂ by the nominal (AᵀWA)⁻¹, taking the estimates as independent.
    pub squared_sigma_nominal: f64,
}

/// The fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// Every fitted term, in the order of [`Term::ALL`].
    pub terms: Vec<TermEstimate>,
    /// The points fitted.
    pub points: Vec<FitPoint>,
    /// The interval's confidence.
    pub confidence: f64,
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

/// θ̂ and (AᵀWA)⁻¹ of the weighted fit of `points` on `terms`, with the weights of the last
/// pass; `None` when the normal equations are singular.
fn weighted_fit(
    points: &[FitPoint],
    terms: &[Term],
) -> Option<(DVector<f64>, DMatrix<f64>, DVector<f64>)> {
    let a = DMatrix::from_fn(points.len(), terms.len(), |i, j| {
        terms[j].coefficient(points[i].tau_s)
    });
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
        let wa = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| w[i] * a[(i, j)]);
        let h = (a.transpose() * &wa).try_inverse()?;
        let theta = &h * (wa.transpose() * &s);
        predicted = &a * &theta;
        out = Some((theta, h, w));
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

/// Fits `terms` to `points` of a log of `samples` samples τ₀ apart, with intervals at
/// `confidence`; `None` when the fit is singular (fewer points than terms).
pub fn fit(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    terms: &[Term],
    confidence: f64,
) -> Option<Fit> {
    if points.len() < terms.len() {
        return None;
    }
    let (theta, h, w) = weighted_fit(points, terms)?;
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
    let c = DMatrix::from_fn(points.len(), points.len(), |i, j| c[i][j]);
    let wa = DMatrix::from_fn(points.len(), terms.len(), |i, j| {
        w[i] * terms[j].coefficient(points[i].tau_s)
    });
    let sandwich = &h * (wa.transpose() * c * &wa) * &h;
    let estimates = terms
        .iter()
        .enumerate()
        .map(|(j, &term)| {
            let (value, lower, upper) = term_interval(theta[j], sandwich[(j, j)], confidence);
            TermEstimate {
                term,
                value,
                lower,
                upper,
                squared: theta[j],
                squared_sigma: sandwich[(j, j)].max(0.0).sqrt(),
                squared_sigma_nominal: h[(j, j)].max(0.0).sqrt(),
            }
        })
        .collect();
    Some(Fit {
        terms: estimates,
        points: points.to_vec(),
        confidence,
    })
}
