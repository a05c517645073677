//! What the analysis reports from the fit: where the fitted curve holds, which features of the
//! curve the model does not have, and — when the goodness-of-fit test rejects the model — the
//! terms read off the curve the way IEEE Std 952-1997 (annex C) reads them.

use super::edf::chi_squared_interval;
use super::fit::{Fit, Term, TermEstimate, whisker_floor};
use super::{AllanPoint, FitPoint};
use crate::stats::{Tail, chi_squared_quantile};

mod rate_walk;

pub use rate_walk::{LineReading, Usable, rate_walk_line};

/// Which reading the reported terms come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reading {
    /// The constrained fit (the model was not rejected).
    Fit,
    /// Read off the curve (IEEE Std 952, annex C), the model being rejected.
    Ieee952,
}

impl Reading {
    /// The word in `allan.json`'s `fit.reading`.
    pub fn key(self) -> &'static str {
        match self {
            Reading::Fit => "fit",
            Reading::Ieee952 => "ieee952",
        }
    }
}

/// How the fitted curve meets the estimate at one τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Departure {
    /// The fitted σ(τ), m/s².
    pub fit_adev: f64,
    /// (σ̂² − σ²_fit)/√V, V = 2σ⁴_fit/edf (NIST SP 1065 §5.3); `None` without an EDF.
    pub standardized: Option<f64>,
    /// σ̂/σ_fit.
    pub ratio: f64,
    /// Whether the fitted σ lies inside the estimate's χ² interval at 1 − α/k, α the
    /// goodness-of-fit test's, k the points with an EDF (Bonferroni: on a log drawn from the
    /// model, any point departs with probability at most α); true without an EDF.
    pub holds: bool,
}

/// The departure of `fit` from every point.
pub fn departures(points: &[AllanPoint], fit: &Fit) -> Vec<Departure> {
    let k = points.iter().filter(|p| p.edf.is_some()).count().max(1);
    let confidence = 1.0 - fit.goodness.alpha / k as f64;
    points
        .iter()
        .map(|p| {
            let f = fit.avar_at(p.tau_s).max(0.0);
            let fit_adev = f.sqrt();
            Departure {
                fit_adev,
                standardized: p
                    .edf
                    .map(|e| (p.adev * p.adev - f) / (2.0 * f * f / e).sqrt()),
                ratio: p.adev / fit_adev,
                holds: p.edf.is_none_or(|e| {
                    let (lo, hi) = chi_squared_interval(p.adev, e, confidence);
                    lo <= fit_adev && fit_adev <= hi
                }),
            }
        })
        .collect()
}

/// A feature of the curve the white/flicker/random-walk model does not have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feature {
    /// A hump above the fit at short-to-mid τ: a sinusoid of frequency f₀ ≈ 0.371/τ_peak
    /// (IEEE Std 952, annex C: σ²(τ) = Ω₀²·(sin²(πf₀τ)/(πf₀τ))², largest near τ = 0.371/f₀).
    Sinusoid {
        /// τ of the largest departure, s.
        tau_peak_s: f64,
        /// f₀, Hz.
        frequency_hz: f64,
        /// σ̂/σ_fit there.
        ratio: f64,
    },
    /// A rise of slope +1 at the long τ: a linear trend of the bias (rate ramp).
    Trend {
        /// The first τ of the rise, s.
        from_tau_s: f64,
        /// σ̂/σ_fit at the longest τ.
        ratio: f64,
    },
}

/// The local slope of ln σ against ln τ at each point (central differences, one-sided at the
/// ends).
pub fn local_slopes(points: &[AllanPoint]) -> Vec<f64> {
    let k = points.len();
    (0..k)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(k - 1));
            if a == b {
                return f64::NAN;
            }
            (points[b].adev / points[a].adev).ln() / (points[b].tau_s / points[a].tau_s).ln()
        })
        .collect()
}

/// The features named when the model is rejected: the largest departure above the fit before
/// the minimum of the curve (a sinusoid), a rise of slope ≥ ¾ above the fit at the longest τ
/// (a trend). A resolved rate ramp is named as a trend in any case.
pub fn features(points: &[AllanPoint], d: &[Departure], fit: &Fit) -> Vec<Feature> {
    let mut out = vec![];
    let rejected = fit.goodness.rejected;
    let minimum = (0..points.len())
        .min_by(|&i, &j| points[i].adev.total_cmp(&points[j].adev))
        .unwrap_or(0);
    let hump = (0..minimum)
        .filter(|&i| !d[i].holds && d[i].ratio > 1.0)
        .max_by(|&i, &j| d[i].ratio.total_cmp(&d[j].ratio));
    if let (true, Some(i)) = (rejected, hump) {
        out.push(Feature::Sinusoid {
            tau_peak_s: points[i].tau_s,
            frequency_hz: 0.371 / points[i].tau_s,
            ratio: d[i].ratio,
        });
    }
    let slopes = local_slopes(points);
    let last = points.len() - 1;
    let ramp = fit.term(Term::RateRamp).is_some_and(|t| t.value.is_some());
    let rising = rejected && !d[last].holds && d[last].ratio > 1.0 && slopes[last] >= 0.75;
    if ramp || rising {
        let from = (minimum..=last)
            .find(|&i| slopes[i] >= 0.75)
            .unwrap_or(last);
        out.push(Feature::Trend {
            from_tau_s: points[from].tau_s,
            ratio: d[last].ratio,
        });
    }
    out
}

/// A squared term θ read from estimates with ν degrees of freedom, with its χ² interval.
fn read_term(term: Term, theta: f64, nu: f64, confidence: f64) -> TermEstimate {
    let p = (1.0 - confidence) / 2.0;
    let lo = nu * theta / chi_squared_quantile(nu, p, Tail::Upper);
    let hi = nu * theta / chi_squared_quantile(nu, p, Tail::Lower);
    TermEstimate {
        term,
        value: Some(theta.sqrt()),
        lower: Some(lo.sqrt()),
        upper: hi.sqrt(),
        squared: theta,
        squared_sigma: theta * (2.0 / nu).sqrt(),
        squared_sigma_nominal: theta * (2.0 / nu).sqrt(),
    }
}

/// An unresolved term with the upper bound `upper`.
fn unresolved(term: Term, upper: f64) -> TermEstimate {
    TermEstimate {
        term,
        value: None,
        lower: None,
        upper,
        squared: 0.0,
        squared_sigma: f64::NAN,
        squared_sigma_nominal: f64::NAN,
    }
}

/// The terms read off the curve (IEEE Std 952-1997, annex C, fig. C.2): B = σ_min/0.664 from the
/// minimum; K by [`rate_walk_line`], the +½ line fitted to every point right of the minimum it
/// dominates; every other term from the line of its slope through the points whose local slope
/// is within ¼ of it (left of the minimum for Q and N, right of it for R) and whose σ² is at
/// least twice the minimum's — N read at τ = 1 s, i.e. θ = (σ²(τ) − σ²_min)/c(τ) averaged in
/// log over those points, EDF-weighted (the floor σ²_min taken off each point so that the points
/// near the minimum do not lift the asymptote).
/// Intervals of B, N, Q, R: χ² with the smallest EDF among the points a term comes from — the
/// widest of their own intervals, a conservative choice: the points share their data, and their
/// spread about the line is the misfit the reading ignores. A term with no such points is
/// unresolved, bounded by the tightest upper whisker, and never below what a lower whisker
/// demands given the other terms. `samples` is the log's length (for the correlation of the
/// estimates across τ).
pub fn ieee952(
    points: &[AllanPoint],
    terms: &[Term],
    samples: usize,
    confidence: f64,
) -> Vec<TermEstimate> {
    let usable: Vec<Usable> = points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| Some((i, p, p.edf?, p.interval?)))
        .filter(|(_, p, _, _)| p.adev > 0.0)
        .collect();
    let slopes = local_slopes(points);
    let minimum = usable
        .iter()
        .min_by(|a, b| a.1.adev.total_cmp(&b.1.adev))
        .map_or(0, |u| u.0);
    let floor = usable
        .iter()
        .find(|u| u.0 == minimum)
        .map_or(0.0, |u| u.1.adev * u.1.adev);
    let tightest_bound = |c: &dyn Fn(f64) -> f64| {
        usable
            .iter()
            .map(|u| u.3.1 * u.3.1 / c(u.1.tau_s))
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    };
    let mut out: Vec<TermEstimate> = terms
        .iter()
        .map(|&term| {
            let c = |tau: f64| term.coefficient(tau);
            if term == Term::BiasInstability {
                return match usable.iter().find(|u| u.0 == minimum) {
                    Some((_, p, edf, _)) => {
                        read_term(term, p.adev * p.adev / c(p.tau_s), *edf, confidence)
                    }
                    None => unresolved(term, f64::INFINITY),
                };
            }
            if term == Term::AccelerationRandomWalk {
                // Read below, once N is known.
                return unresolved(term, f64::INFINITY);
            }
            slope_reading(term, &usable, &slopes, minimum, floor, confidence)
                .unwrap_or_else(|| unresolved(term, tightest_bound(&c)))
        })
        .collect();
    let n_squared = out
        .iter()
        .find(|t| t.term == Term::VelocityRandomWalk && t.value.is_some())
        .map_or(0.0, |t| t.squared);
    if let Some(k) = out
        .iter_mut()
        .find(|t| t.term == Term::AccelerationRandomWalk)
    {
        let tau0_s = points[0].tau_s / points[0].m as f64;
        *k = match rate_walk_line(&usable, minimum, n_squared, samples, tau0_s) {
            Some(l) => line_term(k.term, l, confidence),
            None => unresolved(k.term, tightest_bound(&|t| k.term.coefficient(t))),
        };
    }
    let fit_points: Vec<FitPoint> = usable
        .iter()
        .map(|u| FitPoint {
            m: u.1.m,
            tau_s: u.1.tau_s,
            avar: u.1.adev * u.1.adev,
            edf: u.2,
        })
        .collect();
    let theta: Vec<f64> = out.iter().map(|t| t.squared).collect();
    for (j, t) in out.iter_mut().enumerate() {
        if t.value.is_none() {
            let floor = whisker_floor(&fit_points, terms, &theta, j, confidence);
            t.upper = t.upper.max(floor.sqrt());
        }
    }
    out
}

/// The term of a line reading with its interval: the value √θ̂ and the scaled-χ² interval of
/// ν = 2θ̂²/Var(θ̂) degrees of freedom (Satterthwaite 1946), as the fit's terms
/// (`fit::term_interval`'s resolved branch) — a value whenever the curve shows the line, its
/// interval as wide as the few degrees of freedom of the long τ make it.
fn line_term(term: Term, l: LineReading, confidence: f64) -> TermEstimate {
    let sigma = l.variance.max(0.0).sqrt();
    let nu = 2.0 * l.theta * l.theta / l.variance;
    TermEstimate {
        squared_sigma: sigma,
        squared_sigma_nominal: sigma,
        ..read_term(term, l.theta, nu, confidence)
    }
}

/// θ read on the line of `term`'s slope as IEEE 952 does (see [`ieee952`]): the EDF-weighted log
/// mean of (σ̂² − floor)/c(τ) over the points on the term's side of the minimum whose local slope
/// is within ¼ of the term's and whose σ̂² is at least twice the floor; χ² with their smallest
/// EDF. `None` without such points.
fn slope_reading(
    term: Term,
    usable: &[Usable],
    slopes: &[f64],
    minimum: usize,
    floor: f64,
    confidence: f64,
) -> Option<TermEstimate> {
    let side = |i: usize| match term.slope() < 0.0 {
        true => i < minimum,
        false => i > minimum,
    };
    let chosen: Vec<_> = usable
        .iter()
        .filter(|u| side(u.0) && (slopes[u.0] - term.slope()).abs() <= 0.25)
        .filter(|u| u.1.adev * u.1.adev >= 2.0 * floor)
        .collect();
    if chosen.is_empty() {
        return None;
    }
    let c = |tau: f64| term.coefficient(tau);
    let weight: f64 = chosen.iter().map(|u| u.2).sum();
    let log_theta: f64 = chosen
        .iter()
        .map(|u| u.2 * ((u.1.adev * u.1.adev - floor) / c(u.1.tau_s)).ln())
        .sum::<f64>()
        / weight;
    let nu = chosen.iter().map(|u| u.2).fold(f64::INFINITY, f64::min);
    Some(read_term(term, log_theta.exp(), nu, confidence))
}

/// The τ where the fitted curve leaves the estimates' intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// The shortest τ that departs, s.
    pub from_tau_s: f64,
    /// The longest, s.
    pub to_tau_s: f64,
    /// How many τ depart.
    pub count: usize,
    /// The least σ̂/σ_fit among them.
    pub least_ratio: f64,
    /// The largest.
    pub largest_ratio: f64,
}

/// The span of the τ whose interval excludes the fit; `None` when the fit holds everywhere.
pub fn departing_span(points: &[AllanPoint], d: &[Departure]) -> Option<Span> {
    let out: Vec<usize> = (0..points.len()).filter(|&i| !d[i].holds).collect();
    let (&first, &last) = (out.first()?, out.last()?);
    let ratios = out.iter().map(|&i| d[i].ratio);
    Some(Span {
        from_tau_s: points[first].tau_s,
        to_tau_s: points[last].tau_s,
        count: out.len(),
        least_ratio: ratios.clone().fold(f64::INFINITY, f64::min),
        largest_ratio: ratios.fold(0.0, f64::max),
    })
}
