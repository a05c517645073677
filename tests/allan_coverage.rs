//! The fit's intervals cover: over 100 synthetic static logs of 10⁶ samples (white noise plus a
//! random walk of the bias, known N and K), the 95 % intervals of N and K contain the truth a
//! number of times inside the binomial band at a 1 % false-alarm rate; the nominal standard
//! errors of the weighted fit, taken at face value, fall below it (the negative control).

use accelcal::allan::fit::term_interval;
use accelcal::allan::simulate::StaticLog;
use accelcal::allan::{Term, analyse};
use accelcal::stats::clopper_pearson;
use rayon::prelude::*;

const SEEDS: u64 = 100;
const SAMPLES: usize = 1_000_000;
const CONFIDENCE: f64 = 0.95;
/// The false-alarm rate of the coverage band.
const FALSE_ALARM: f64 = 0.01;

const LOG: StaticLog = StaticLog {
    sample_period_s: 0.01,
    velocity_random_walk_m_s_per_sqrt_s: 2e-3,
    acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
    offset_m_s2: 9.80665,
};

/// The two-sided band of covered counts among `n` intervals of coverage `p` at `alpha`: the
/// largest lower and smallest upper count with at most alpha/2 probability outside each.
fn binomial_band(n: u64, p: f64, alpha: f64) -> (u64, u64) {
    use statrs::distribution::{Binomial, DiscreteCDF};
    let b = Binomial::new(p, n).unwrap();
    let lower = (0..=n).find(|&k| b.cdf(k) > alpha / 2.0).unwrap();
    let upper = (0..=n)
        .rev()
        .find(|&k| k == 0 || b.cdf(k - 1) < 1.0 - alpha / 2.0)
        .unwrap();
    (lower, upper)
}

#[derive(Default, Clone, Copy)]
struct Covered {
    n: u64,
    k: u64,
    n_nominal: u64,
    k_nominal: u64,
}

fn covers(t: &accelcal::allan::TermEstimate, truth: f64, nominal: bool) -> bool {
    let (lower, upper) = if nominal {
        let (_, lo, hi) = term_interval(t.squared, t.squared_sigma_nominal.powi(2), CONFIDENCE);
        (lo.unwrap_or(0.0), hi)
    } else {
        (t.lower.unwrap_or(0.0), t.upper)
    };
    lower <= truth && truth <= upper
}

#[test]
fn intervals_of_n_and_k_cover_and_nominal_errors_do_not() {
    let per_seed: Vec<Covered> = (0..SEEDS)
        .into_par_iter()
        .map(|seed| {
            let y = LOG.samples(SAMPLES, seed);
            let a = analyse(&y, LOG.sample_period_s, CONFIDENCE).unwrap();
            let n = a.fit.term(Term::VelocityRandomWalk).unwrap();
            let k = a.fit.term(Term::AccelerationRandomWalk).unwrap();
            assert!(k.value.is_some(), "seed {seed}: K unresolved");
            let (n_true, k_true) = (
                LOG.velocity_random_walk_m_s_per_sqrt_s,
                LOG.acceleration_random_walk_m_s2_per_sqrt_s,
            );
            Covered {
                n: covers(n, n_true, false) as u64,
                k: covers(k, k_true, false) as u64,
                n_nominal: covers(n, n_true, true) as u64,
                k_nominal: covers(k, k_true, true) as u64,
            }
        })
        .collect();
    let total = per_seed.iter().fold(Covered::default(), |a, c| Covered {
        n: a.n + c.n,
        k: a.k + c.k,
        n_nominal: a.n_nominal + c.n_nominal,
        k_nominal: a.k_nominal + c.k_nominal,
    });
    let (lo, hi) = binomial_band(SEEDS, CONFIDENCE, FALSE_ALARM);
    eprintln!(
        "covered of {SEEDS}: N {} K {} (nominal: N {} K {}); band [{lo}, {hi}]",
        total.n, total.k, total.n_nominal, total.k_nominal
    );
    let _ = clopper_pearson;
    assert!((lo..=hi).contains(&total.n), "N covered {} times", total.n);
    assert!((lo..=hi).contains(&total.k), "K covered {} times", total.k);
    assert!(
        total.n_nominal < lo || total.k_nominal < lo,
        "the negative control passed: nominal N {} K {}",
        total.n_nominal,
        total.k_nominal
    );
}
