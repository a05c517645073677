//! The selected model resolves what the data plainly show and bounds what they do not as tightly
//! as the points allow (`accelcal::allan::select`).
//!
//! Family: 10⁶ samples at 100 Hz of white noise N = 2·10⁻³ m/s/√s, with a random walk of the bias
//! K = 5·10⁻⁵ m/s²/√s (at τ = 1 000 s its deviation is 14× the white noise's, on about 15
//! degrees of freedom) or without one (K = 0). Over 200 logs of each, at 68.3 % intervals:
//!
//! - with K: K resolved on ≥ 97 % (194 of 200), its interval covering the truth a number of times
//!   inside the binomial band Bin(200, 0.683) at a 1 % false-alarm rate;
//! - without: K's upper bound at most 10× the bound the longest τ alone allows, √(3·U/τ_max) with
//!   U the upper end of σ̂²(τ_max)'s χ² interval, on ≥ 90 % (180 of 200); and covering (K = 0
//!   below the bound, that is K not resolved) on all but the share Bin(200, 0.317) allows at 1 %.
//!
//! - without: the goodness test rejects at most the upper end of Bin(200, 0.01)'s band at 1 %.
//!   Its negative control: the same model refitted with the EDF of the noise identified at each
//!   τ, not the least α identified up to it, rejects more (a white noise read as flicker phase
//!   from 30 block means claims 16 times its EDF).
//!
//! The negative controls of the first two, on the same points: the fit with every term always in (`fit::fit`)
//! fails the first bullet, and with its bound floored by every τ's lower whisker (not only the τ
//! where K would show, `fit::whisker_floor`) the second: that was the fit before selection.

use accelcal::allan::edf::{chi_squared_interval, greenhall_edf};
use accelcal::allan::fit::FitPoint;
use accelcal::allan::fit::{self, Fit, Term};
use accelcal::allan::goodness::ALPHA;
use accelcal::allan::section::binomial_band;
use accelcal::allan::simulate::StaticLog;
use accelcal::allan::{Analysis, analyse};
use rayon::prelude::*;

const SEEDS: u64 = 200;
const SAMPLES: usize = 1_000_000;
const CONFIDENCE: f64 = 0.683;
const FALSE_ALARM: f64 = 0.01;

fn log(k: f64) -> StaticLog {
    StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: k,
        offset_m_s2: 9.80665,
    }
}

/// The fit of every candidate term on the points `a` fitted: the negative control.
fn all_terms(a: &Analysis) -> Fit {
    let terms: Vec<Term> = Term::ALL
        .into_iter()
        .filter(|&t| a.fit.term(t).is_some())
        .collect();
    fit::fit(
        &a.fit.points,
        a.samples,
        a.sample_period_s,
        &terms,
        a.confidence,
    )
    .expect("the full fit is not singular")
}

/// K's bound in `fit` floored by what every point's lower whisker demands of it given the
/// other terms, θ_K ≥ max_i (L_i² − Σ_{j≠K} θ_j c_j(τ_i)) / c_K(τ_i): the floor over every τ.
fn every_tau_bound(fit: &Fit) -> f64 {
    let floor = fit
        .points
        .iter()
        .map(|p| {
            let lower = chi_squared_interval(p.avar.sqrt(), p.edf, fit.confidence).0;
            let others: f64 = fit
                .terms
                .iter()
                .filter(|t| t.term != Term::AccelerationRandomWalk)
                .map(|t| t.squared * t.term.coefficient(p.tau_s))
                .sum();
            (lower * lower - others) / Term::AccelerationRandomWalk.coefficient(p.tau_s)
        })
        .fold(0.0, f64::max);
    let k = fit.term(Term::AccelerationRandomWalk).expect("K is fitted");
    k.upper.max(floor.sqrt())
}

/// K's (resolved, covered `truth`, upper end) in `fit`.
fn k_of(fit: &Fit, truth: f64) -> (bool, bool, f64) {
    let t = fit.term(Term::AccelerationRandomWalk).expect("K is fitted");
    let covered = match (t.lower, t.value) {
        (Some(lo), Some(_)) => lo <= truth && truth <= t.upper,
        _ => truth <= t.upper,
    };
    (t.value.is_some(), covered, t.upper)
}

/// The bound on K that the longest τ's upper whisker allows: K²·τ/3 ≤ U.
fn longest_tau_bound(a: &Analysis) -> f64 {
    let p = a
        .points
        .iter()
        .rfind(|p| p.interval.is_some() && p.edf.is_some())
        .expect("a point with an interval");
    let upper = p.interval.expect("an interval").1;
    upper * (3.0 / p.tau_s).sqrt()
}

/// The selected model refitted with each point's EDF from the noise identified at its own τ.
fn identified_edf_rejects(a: &Analysis) -> bool {
    let points: Vec<FitPoint> = a
        .fit
        .points
        .iter()
        .map(|p| {
            let alpha = a
                .points
                .iter()
                .find(|q| q.m == p.m)
                .and_then(|q| q.noise)
                .expect("a fitted point has a noise")
                .alpha
                .clamp(-2, 2);
            let edf = greenhall_edf(alpha, 2, p.m as f64, (a.samples + 1) as f64, true);
            FitPoint {
                edf: edf.unwrap_or(p.edf),
                ..*p
            }
        })
        .collect();
    fit::fit(
        &points,
        a.samples,
        a.sample_period_s,
        &a.fit.model,
        a.confidence,
    )
    .expect("the model's fit is not singular")
    .goodness
    .rejected
}

struct Run {
    /// (resolved, covered, upper) of K for the selected and the all-terms fits.
    selected: (bool, bool, f64),
    full: (bool, bool, f64),
    /// The all-terms fit's bound floored by every τ.
    full_every_tau: f64,
    reference: f64,
    model: Vec<Term>,
    /// Whether the goodness test rejects the selected model, and with the identified EDF.
    rejected: (bool, bool),
}

fn runs(k: f64) -> Vec<Run> {
    let log = log(k);
    (0..SEEDS)
        .into_par_iter()
        .map(|seed| {
            let a = analyse(&log.samples(SAMPLES, seed), log.sample_period_s, CONFIDENCE)
                .expect("the log analyses");
            let full = all_terms(&a);
            Run {
                selected: k_of(&a.fit, k),
                full: k_of(&full, k),
                full_every_tau: every_tau_bound(&full),
                reference: longest_tau_bound(&a),
                model: a.fit.model.clone(),
                rejected: (a.fit.goodness.rejected, identified_edf_rejects(&a)),
            }
        })
        .collect()
}

fn count(runs: &[Run], f: impl Fn(&Run) -> bool) -> u64 {
    runs.iter().filter(|r| f(r)).count() as u64
}

#[test]
fn a_random_walk_is_resolved_and_covered_and_the_full_fit_loses_it() {
    let runs = runs(5e-5);
    let resolved = count(&runs, |r| r.selected.0);
    let covered = count(&runs, |r| r.selected.1);
    let full_resolved = count(&runs, |r| r.full.0);
    let with_k = count(&runs, |r| r.model.contains(&Term::AccelerationRandomWalk));
    let band = binomial_band(SEEDS, CONFIDENCE, FALSE_ALARM);
    eprintln!(
        "K resolved {resolved}/{SEEDS} (in the model {with_k}), covered {covered} (band {band:?}); \
         the full fit resolves {full_resolved}"
    );
    assert!(resolved >= 194, "K resolved on {resolved} of {SEEDS}");
    assert!(
        (band.0..=band.1).contains(&covered),
        "K covered {covered} of {SEEDS}, band {band:?}"
    );
    assert!(
        full_resolved < 194,
        "the negative control passed: the full fit resolves K on {full_resolved} of {SEEDS}"
    );
}

#[test]
fn without_a_random_walk_the_bound_is_what_the_longest_tau_allows() {
    let runs = runs(0.0);
    let tight = count(&runs, |r| r.selected.2 <= 10.0 * r.reference);
    let full_tight = count(&runs, |r| r.full_every_tau <= 10.0 * r.reference);
    let missed = count(&runs, |r| !r.selected.1);
    let mut ratios: Vec<f64> = runs.iter().map(|r| r.selected.2 / r.reference).collect();
    ratios.sort_by(f64::total_cmp);
    let band = binomial_band(SEEDS, 1.0 - CONFIDENCE, FALSE_ALARM);
    eprintln!(
        "K bound within 10x of the longest tau's on {tight}/{SEEDS} (full fit floored by every tau {full_tight}); \
         bound/reference median {:.3}, largest {:.3}; K = 0 missed {missed} (at most {})",
        ratios[ratios.len() / 2],
        ratios[ratios.len() - 1],
        band.1
    );
    let rejected = count(&runs, |r| r.rejected.0);
    let identified_rejected = count(&runs, |r| r.rejected.1);
    let gof = binomial_band(SEEDS, ALPHA, FALSE_ALARM);
    eprintln!(
        "goodness rejects {rejected}/{SEEDS}, with the identified EDF {identified_rejected} \
         (band {gof:?})"
    );
    assert!(tight >= 180, "K's bound tight on {tight} of {SEEDS}");
    assert!(rejected <= gof.1, "white-only logs rejected: {rejected}");
    assert!(
        identified_rejected > gof.1,
        "the negative control passed: {identified_rejected} rejected with the identified EDF"
    );
    assert!(missed <= band.1, "K = 0 outside the interval on {missed}");
    assert!(
        full_tight < 180,
        "the negative control passed: the every-τ bound is tight on {full_tight} of {SEEDS}"
    );
}
