//! Which terms the fit keeps: a term enters the model when the data need it.
//!
//! Every term free in one fit competes with the others for the few long-τ estimates: on a log of
//! white noise and a random walk the bias instability B and the rate ramp R take a share of the
//! random walk's slope, K's standard error grows with them, and K is called unresolved with an
//! upper bound as loose as the most flexible model allows. So the model is chosen first, by
//! forward selection on a nested test (Draper & Smith, *Applied Regression Analysis*, 3rd ed.,
//! §15.2), the likelihood-ratio test the Gauss–Markov term has ([`super::gauss_markov_fit`]):
//!
//! 1. the model starts with the velocity random walk N (white noise, which every sensor has)
//!    and the quantization Q where the shortest τ shows phase noise;
//! 2. each term not in the model is fitted beside it in turn; the best (least weighted residual
//!    T = rᵀWr, [`super::goodness`]) is needed when the drop of T it brings, over the scale g of
//!    its goodness test (T ≈ g·χ²_ν), exceeds the χ²₁ quantile at [`ENTRY_ALPHA`] (Wilks, Ann.
//!    Math. Stat. 9 (1938); θ ≥ 0 is on a bound, which halves the false-entry rate). It enters
//!    with its rivals, the terms whose T exceeds the best's by no more than that: on a 10-minute
//!    log the data need a rising term and cannot tell K from R, and picking one would report a
//!    rate ramp on a fifth of logs that have none. Candidates are ranked by T, not by the drop
//!    over g: g differs between them, and a rate ramp that misses a random walk's curve by
//!    twice the residual can show the larger ratio. Until no term is needed;
//! 3. the values and intervals are those of the selected model's fit, its goodness-of-fit test
//!    that model's. A term in the model need not be resolved: on a short log the random walk
//!    may be needed for the fit (N alone and N + B rejected) and stand only two standard errors
//!    above zero; it is then unresolved, bounded by the model's fit;
//! 4. a term left out is unresolved, its upper bound that of the selected model with that one
//!    term added: the points that would show it constrain it, and the terms the data did not
//!    need do not widen it.

use super::fit::{Fit, FitPoint, Term, TermEstimate, fit};
use super::goodness;
use crate::stats::{Tail, chi_squared_quantile};

/// The nested test's false-entry rate, that of the goodness test.
pub const ENTRY_ALPHA: f64 = goodness::ALPHA;

/// The rule in words, as `allan.json` writes it.
pub const RULE: &str = "forward selection: from the white noise N (with the quantization Q \
    where the shortest tau shows phase noise), the term that fits best beside the model enters \
    when the drop of the weighted residual it brings, over the scale of its goodness test, \
    exceeds entry_critical (the chi-squared quantile of 1 degree of freedom at entry_alpha), \
    together with its rivals, the terms that fit no worse than that drop from it; a term left \
    out is bounded by the fit of the model with it added";

/// The terms the model always holds.
const BASE: [Term; 2] = [Term::Quantization, Term::VelocityRandomWalk];

/// `terms` in the order of [`Term::ALL`].
fn ordered(terms: &[Term]) -> Vec<Term> {
    Term::ALL
        .into_iter()
        .filter(|t| terms.contains(t))
        .collect()
}

/// The χ²₁ quantile a term's drop of T must exceed to enter: 6.63 at [`ENTRY_ALPHA`].
pub fn entry_critical() -> f64 {
    chi_squared_quantile(1.0, ENTRY_ALPHA, Tail::Upper)
}

/// The likelihood-ratio statistic of the nested pair: the drop of rᵀWr from `smaller` to
/// `larger`, over the scale g of `larger`'s goodness test (T ≈ g·χ²_ν, [`super::goodness`]).
fn drop(smaller: &Fit, larger: &Fit) -> f64 {
    (smaller.goodness.statistic - larger.goodness.statistic) / larger.goodness.scale
}

/// The model chosen from `candidates` (every term that may be fitted) by forward selection on
/// the nested test ([module](self)): its fit (`model` the terms chosen), and the fit of it with
/// each candidate left out added; `None` when even the base model's fit is singular.
fn select(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    candidates: &[Term],
    confidence: f64,
) -> Option<(Fit, Vec<(Term, Fit)>)> {
    let critical = entry_critical();
    let fit_of = |model: &[Term]| fit(points, samples, tau0_s, &ordered(model), confidence);
    let mut model: Vec<Term> = BASE
        .into_iter()
        .filter(|t| candidates.contains(t))
        .collect();
    let mut current = fit_of(&model)?;
    // Each pass adds at least the best term, so the loop ends within the candidates' count.
    loop {
        let mut tried: Vec<(Term, Fit)> = candidates
            .iter()
            .filter(|t| !model.contains(t))
            .filter_map(|&t| {
                let mut m = model.clone();
                m.push(t);
                Some((t, fit_of(&m)?))
            })
            .collect();
        tried.sort_by(|a, b| a.1.goodness.statistic.total_cmp(&b.1.goodness.statistic));
        let best = match tried.first() {
            Some((_, best)) if drop(&current, best) > critical => best,
            _ => return Some((current, tried)),
        };
        // The best term and its rivals, those the data cannot tell from it, enter together.
        let rivals = tried.iter().filter(|(_, f)| drop(f, best) <= critical);
        let with: Vec<Term> = model
            .iter()
            .copied()
            .chain(rivals.map(|(t, _)| *t))
            .collect();
        match fit_of(&with) {
            Some(f) => (model, current) = (with, f),
            None => return Some((current, tried)),
        }
    }
}

/// The fit of the model the forward selection (`select`) chooses from `candidates`, with every
/// candidate left out as an unresolved term: its upper bound that of the model's fit with it
/// added (θ̂ kept at zero: the term is not in the model); `None` when the base model's fit is
/// singular.
pub fn fit_selected(
    points: &[FitPoint],
    samples: usize,
    tau0_s: f64,
    candidates: &[Term],
    confidence: f64,
) -> Option<Fit> {
    let (mut f, absent) = select(points, samples, tau0_s, candidates, confidence)?;
    for (term, with) in &absent {
        if let Some(&t) = with.term(*term) {
            f.terms.push(TermEstimate {
                value: None,
                lower: None,
                squared: 0.0,
                ..t
            });
        }
    }
    f.terms
        .sort_by_key(|t| Term::ALL.iter().position(|&u| u == t.term));
    Some(f)
}
