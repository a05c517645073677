//! The validation of `accelcal allan` the report shows: the coverage of the intervals of N and K
//! over many simulated static logs whose terms are known, and the log the report simulates. The
//! section itself (its view and template) is [`crate::report::static_noise`].

use rayon::prelude::*;
use serde::Serialize;

use super::fit::term_interval;
use super::simulate::StaticLog;
use super::{AllanError, Analysis, Term, analyse};

/// How often the intervals of N and K contained the truth over `seeds` simulated logs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Coverage {
    /// Simulated logs.
    pub seeds: u64,
    /// Samples per log.
    pub samples: usize,
    /// The intervals' confidence.
    pub confidence: f64,
    /// The false-alarm rate of the band.
    pub false_alarm_rate: f64,
    /// The binomial band of covered counts, both ends accepted.
    pub band: (u64, u64),
    /// Intervals of N (sandwich covariance) that covered.
    pub n_covered: u64,
    /// Intervals of K that covered (an unresolved K covers when its bound does).
    pub k_covered: u64,
    /// Intervals of N from the fit's nominal standard errors that covered.
    pub n_nominal_covered: u64,
    /// The same for K.
    pub k_nominal_covered: u64,
    /// Logs whose K was unresolved.
    pub k_unresolved: u64,
    /// Mean of (N̂² − N²)² over the mean sandwich variance of N̂²: near 1 when the claimed
    /// scatter is the actual one (a check of both sides: too wide as well as too narrow).
    pub n_scatter_ratio: f64,
    /// The same for K².
    pub k_scatter_ratio: f64,
    /// The same for N² with the nominal variance.
    pub n_nominal_scatter_ratio: f64,
    /// The same for K² with the nominal variance.
    pub k_nominal_scatter_ratio: f64,
}

pub use crate::stats::binomial_band;

/// Whether the reported interval of `term` in `a` contains `truth` (the fit's, or the IEEE 952
/// reading's when the fit is rejected); `nominal` takes the fit's nominal standard error instead.
pub fn covers(a: &Analysis, term: Term, truth: f64, nominal: bool) -> bool {
    let reported = if nominal {
        a.fit.term(term)
    } else {
        a.term(term)
    };
    let Some(t) = reported else {
        return false;
    };
    let (lower, upper) = if nominal {
        let (_, lo, hi) = term_interval(t.squared, t.squared_sigma_nominal.powi(2), a.confidence);
        (lo.unwrap_or(0.0), hi)
    } else {
        (t.lower.unwrap_or(0.0), t.upper)
    };
    lower <= truth && truth <= upper
}

/// The coverage study: `seeds` logs of `samples` samples of `log` (seeds 0, 1, …), analysed in
/// memory on all threads, intervals at `confidence`, the band at `false_alarm_rate`.
pub fn coverage(
    log: &StaticLog,
    seeds: u64,
    samples: usize,
    confidence: f64,
    false_alarm_rate: f64,
) -> Result<Coverage, AllanError> {
    let (n, k) = (
        log.velocity_random_walk_m_s_per_sqrt_s,
        log.acceleration_random_walk_m_s2_per_sqrt_s,
    );
    let per_seed: Vec<[f64; 11]> = (0..seeds)
        .into_par_iter()
        .map(|seed| {
            let a = analyse(&log.samples(samples, seed), log.sample_period_s, confidence)?;
            let (tn, tk) = (
                a.fit.term(Term::VelocityRandomWalk),
                a.fit.term(Term::AccelerationRandomWalk),
            );
            let unresolved = tk.is_some_and(|t| t.value.is_none());
            let error = |t: Option<&super::TermEstimate>, truth: f64| {
                t.map_or([f64::NAN; 3], |t| {
                    [
                        (t.squared - truth * truth).powi(2),
                        t.squared_sigma.powi(2),
                        t.squared_sigma_nominal.powi(2),
                    ]
                })
            };
            let (en, ek) = (error(tn, n), error(tk, k));
            let flag = |b: bool| b as u64 as f64;
            Ok([
                flag(covers(&a, Term::VelocityRandomWalk, n, false)),
                flag(covers(&a, Term::AccelerationRandomWalk, k, false)),
                flag(covers(&a, Term::VelocityRandomWalk, n, true)),
                flag(covers(&a, Term::AccelerationRandomWalk, k, true)),
                flag(unresolved),
                en[0],
                en[1],
                en[2],
                ek[0],
                ek[1],
                ek[2],
            ])
        })
        .collect::<Result<_, AllanError>>()?;
    let sum = |i: usize| per_seed.iter().map(|c| c[i]).sum::<f64>();
    Ok(Coverage {
        seeds,
        samples,
        confidence,
        false_alarm_rate,
        band: binomial_band(seeds, confidence, false_alarm_rate),
        n_covered: sum(0) as u64,
        k_covered: sum(1) as u64,
        n_nominal_covered: sum(2) as u64,
        k_nominal_covered: sum(3) as u64,
        k_unresolved: sum(4) as u64,
        n_scatter_ratio: sum(5) / sum(6),
        k_scatter_ratio: sum(8) / sum(9),
        n_nominal_scatter_ratio: sum(5) / sum(7),
        k_nominal_scatter_ratio: sum(8) / sum(10),
    })
}

/// The static log the report simulates: 100 Hz, N = 2·10⁻³ m/s/√s (about 200 µg/√Hz),
/// K = 10⁻⁴ m/s²/√s, on a 1 g offset; its Allan minimum lies near τ = 40 s.
pub const REPORT_LOG: StaticLog = StaticLog {
    sample_period_s: 0.01,
    velocity_random_walk_m_s_per_sqrt_s: 2e-3,
    acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
    offset_m_s2: 9.80665,
};

/// Samples of each log of the report's section (10⁶: 2.8 h at 100 Hz).
pub const REPORT_SAMPLES: usize = 1_000_000;

/// Simulated static logs of the report's validation: enough for a coverage of 95 % intervals to
/// be judged inside a binomial band at 1 % (about 4 s on 2 cores).
pub const REPORT_SEEDS: u64 = 100;

/// The coverage study the report shows: [`REPORT_SEEDS`] logs of [`REPORT_LOG`] of
/// [`REPORT_SAMPLES`] each, 95 % intervals, a band at a 1 % false-alarm rate.
///
/// # Errors
/// [`AllanError`] only if the simulated logs were too short, which they are not.
pub fn report_coverage() -> Result<Coverage, AllanError> {
    coverage(&REPORT_LOG, REPORT_SEEDS, REPORT_SAMPLES, 0.95, 0.01)
}
