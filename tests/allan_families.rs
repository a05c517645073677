//! Logs beyond the model: white noise + flicker + random walk (N = 10⁻³ m/s/√s, B = 10⁻³ m/s²,
//! K = 10⁻⁴ m/s²/√s), the same + a sinusoid of 4·10⁻³ m/s² at 0.5 Hz (its hump, 2.9·10⁻³ m/s²
//! near τ = 0.74 s, stands about three times above the curve without it, as the real sensor's
//! did), and the same + a linear trend R = 2·10⁻⁵ m/s³ (at the longest τ, 1 300 s, sixteen times the variance of
//! the rest) (`FeatureLog`, 2¹⁸ samples at 100 Hz, 100
//! seeds each, 95 % intervals). On each family, per term, the count of logs whose report is
//! honest — the model accepted and the interval covering the truth, or the model rejected and
//! the IEEE 952 reading within 25 % of the truth or its interval covering it (an unresolved
//! term: its bound at least the truth) — lies in the binomial band of Bin(100, 0.95) at 1 %,
//! [89, 100] (printed: how many IEEE readings were within 25 %, K's on about 4 logs in 10: a
//! 44-minute log reads K with a median relative σ of about 0.37 from the EDF of the points on its
//! +½ line, so its interval, not its value, makes it honest; the count within 25 % lies in the
//! band its readings' own σ's predict, which is checked). No term is negative and no bound below what the longest τ's lower whisker
//! demands, on every log. The negative controls: the fit before this change (unconstrained, on
//! the τ with 30 block means) covers N and B on the sinusoid logs below the band, and K on the
//! trend logs (it takes the trend for a random walk). The sinusoid is named, between 0.25 and
//! 1 Hz, on every sinusoid log and on no other.

use accelcal::allan::fit::Term;
use accelcal::allan::section::binomial_band;
use accelcal::allan::simulate::{FeatureLog, StaticLog};
use accelcal::allan::{Analysis, Feature, Reading, analyse};
use rayon::prelude::*;

const SEEDS: u64 = 100;
const SAMPLES: usize = 1 << 18;
const CONFIDENCE: f64 = 0.95;

const BASE: FeatureLog = FeatureLog {
    base: StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 1e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
        offset_m_s2: 9.80665,
    },
    bias_instability_m_s2: 1e-3,
    sinusoid_amplitude_m_s2: 0.0,
    sinusoid_frequency_hz: 0.5,
    rate_ramp_m_s3: 0.0,
};

const TERMS: [Term; 3] = [
    Term::VelocityRandomWalk,
    Term::BiasInstability,
    Term::AccelerationRandomWalk,
];

fn truth(log: &FeatureLog, t: Term) -> f64 {
    match t {
        Term::VelocityRandomWalk => log.base.velocity_random_walk_m_s_per_sqrt_s,
        Term::BiasInstability => log.bias_instability_m_s2,
        Term::AccelerationRandomWalk => log.base.acceleration_random_walk_m_s2_per_sqrt_s,
        Term::RateRamp => log.rate_ramp_m_s3,
        Term::Quantization => 0.0,
    }
}

/// Per log: whether the model was rejected, and per term of [`TERMS`] whether the report is
/// honest about it — the interval covers the truth (an unresolved term: its bound does), or,
/// the model rejected, the IEEE reading is within 25 % of the truth (an unresolved term: its
/// bound is at least the truth).
fn honest(a: &Analysis, log: &FeatureLog) -> (bool, [bool; 3]) {
    let rejected = a.reading == Reading::Ieee952;
    let ok = TERMS.map(|t| {
        let e = a.term(t).unwrap();
        let truth = truth(log, t);
        match (rejected, e.value) {
            (false, Some(_)) => e.lower.unwrap() <= truth && truth <= e.upper,
            (true, Some(v)) => {
                (v / truth - 1.0).abs() <= 0.25 || (e.lower.unwrap() <= truth && truth <= e.upper)
            }
            (_, None) => truth <= e.upper,
        }
    });
    (rejected, ok)
}

/// Coverage of N, B, K by the fit of the code before the constraint: unconstrained, over the τ
/// with 30 block means only.
fn old_fit_covers(a: &Analysis, log: &FeatureLog) -> [bool; 3] {
    let f = a.fit_before_constraint(&TERMS).unwrap();
    TERMS.map(|t| {
        let e = f.term(t).unwrap();
        e.lower.unwrap_or(0.0) <= truth(log, t) && truth(log, t) <= e.upper
    })
}

/// No reported or fitted term negative, and no unresolved bound below what the longest τ's lower
/// whisker demands given the other reported terms.
fn physical(a: &Analysis) -> bool {
    let last = a
        .points
        .iter()
        .rev()
        .find(|p| p.interval.is_some())
        .unwrap();
    let lower = last.interval.unwrap().0;
    let all_positive = a.fit.terms.iter().all(|t| t.squared >= 0.0)
        && a.terms
            .iter()
            .all(|t| t.value.is_none_or(|v| v >= 0.0) && t.upper >= 0.0);
    let bounds_hold = a.terms.iter().filter(|t| t.value.is_none()).all(|t| {
        let others: f64 = a
            .terms
            .iter()
            .filter(|u| u.term != t.term)
            .map(|u| u.squared.max(0.0) * u.term.coefficient(last.tau_s))
            .sum();
        let need = ((lower * lower - others).max(0.0) / t.term.coefficient(last.tau_s)).sqrt();
        t.upper >= need * (1.0 - 1e-12)
    });
    all_positive && bounds_hold
}

struct Study {
    rejected: u64,
    honest: [u64; 3],
    old_covered: [u64; 3],
    physical: u64,
    sinusoid_named: u64,
    trend_named: u64,
    within_quarter: [u64; 3],
    /// K's IEEE readings' relative σ, one per log where K was read with a value.
    k_relative_sigma: Vec<f64>,
}

/// One log: rejected, honest per term, the old fit's coverage per term, physical, the features
/// named (a sinusoid between 0.25 and 1 Hz, a trend), the IEEE reading within 25 % per term,
/// and K's IEEE reading's relative σ when it has a value.
type PerLog = (
    bool,
    [bool; 3],
    [bool; 3],
    bool,
    [bool; 2],
    [bool; 3],
    Option<f64>,
);

/// The relative σ of K's IEEE reading, σ(K̂)/K̂ = σ(θ̂)/(2θ̂) (θ = K², its σ from the EDF of
/// the points read and their correlation across τ), when the model is rejected and K has a value.
fn k_relative_sigma(a: &Analysis) -> Option<f64> {
    let e = a.term(Term::AccelerationRandomWalk)?;
    (a.reading == Reading::Ieee952 && e.value.is_some())
        .then(|| e.squared_sigma / (2.0 * e.squared))
}

/// The probability that a normal estimate of relative σ `r` lands within 25 % of its truth.
fn within_quarter_probability(r: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    let z = Normal::new(0.0, 1.0).unwrap();
    2.0 * z.cdf(0.25 / r) - 1.0
}

fn within_quarter(a: &Analysis, log: &FeatureLog) -> [bool; 3] {
    TERMS.map(|t| {
        a.reading == Reading::Ieee952
            && a.term(t)
                .and_then(|e| e.value)
                .is_some_and(|v| (v / truth(log, t) - 1.0).abs() <= 0.25)
    })
}

fn named(a: &Analysis) -> [bool; 2] {
    [
        a.features.iter().any(|f| {
            matches!(f, Feature::Sinusoid { frequency_hz, .. } if (0.25..=1.0).contains(frequency_hz))
        }),
        a.features.iter().any(|f| matches!(f, Feature::Trend { .. })),
    ]
}

fn study(log: &FeatureLog) -> Study {
    let per: Vec<PerLog> = (0..SEEDS)
        .into_par_iter()
        .map(|seed| {
            let a = analyse(&log.samples(SAMPLES, seed), 0.01, CONFIDENCE).unwrap();
            let (r, h) = honest(&a, log);
            (
                r,
                h,
                old_fit_covers(&a, log),
                physical(&a),
                named(&a),
                within_quarter(&a, log),
                k_relative_sigma(&a),
            )
        })
        .collect();
    let count = |f: &dyn Fn(&PerLog) -> bool| per.iter().filter(|p| f(p)).count() as u64;
    Study {
        rejected: count(&|p| p.0),
        honest: [0, 1, 2].map(|j| count(&|p| p.1[j])),
        old_covered: [0, 1, 2].map(|j| count(&|p| p.2[j])),
        physical: count(&|p| p.3),
        sinusoid_named: count(&|p| p.4[0]),
        trend_named: count(&|p| p.4[1]),
        within_quarter: [0, 1, 2].map(|j| count(&|p| p.5[j])),
        k_relative_sigma: per.iter().filter_map(|p| p.6).collect(),
    }
}

fn check(name: &str, log: &FeatureLog) -> Study {
    let s = study(log);
    eprintln!(
        "{name}: rejected {} of {SEEDS}; honest N {} B {} K {}; old fit covers N {} B {} K {}; physical {}; named a sinusoid {}, a trend {}; IEEE reading within 25 %: N {} B {} K {}",
        s.rejected,
        s.honest[0],
        s.honest[1],
        s.honest[2],
        s.old_covered[0],
        s.old_covered[1],
        s.old_covered[2],
        s.physical,
        s.sinusoid_named,
        s.trend_named,
        s.within_quarter[0],
        s.within_quarter[1],
        s.within_quarter[2]
    );
    if !s.k_relative_sigma.is_empty() {
        let (expected, sd) = k_within_quarter_expected(&s);
        eprintln!(
            "{name}: K's IEEE reading has a value on {} logs, median relative σ {:.3} (from the EDF \
             of its points): within 25 % expected on {expected:.1} ± {sd:.1} of them, found {}",
            s.k_relative_sigma.len(),
            median(&s.k_relative_sigma),
            s.within_quarter[2]
        );
    }
    s
}

fn median(x: &[f64]) -> f64 {
    let mut v = x.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// How many of K's readings land within 25 % of the truth if each is normal about it with its
/// own σ: the sum of the probabilities and its standard deviation (Poisson binomial).
fn k_within_quarter_expected(s: &Study) -> (f64, f64) {
    let p: Vec<f64> = s
        .k_relative_sigma
        .iter()
        .map(|&r| within_quarter_probability(r))
        .collect();
    let expected: f64 = p.iter().sum();
    let var: f64 = p.iter().map(|p| p * (1.0 - p)).sum();
    (expected, var.sqrt())
}

#[test]
fn reports_are_honest_on_every_family_and_the_old_fit_is_not_on_the_sinusoid() {
    let band = binomial_band(SEEDS, CONFIDENCE, 0.01);
    assert_eq!(band, (89, 100));
    let inside = |k: u64| (band.0..=band.1).contains(&k);
    let sinusoid = FeatureLog {
        sinusoid_amplitude_m_s2: 4e-3,
        ..BASE
    };
    let trend = FeatureLog {
        rate_ramp_m_s3: 2e-5,
        ..BASE
    };
    for (name, log) in [("flicker", BASE), ("sinusoid", sinusoid), ("trend", trend)] {
        let s = check(name, &log);
        assert_eq!(
            s.physical, SEEDS,
            "{name}: a negative term or a bound below a whisker"
        );
        for (j, t) in TERMS.iter().enumerate() {
            assert!(
                inside(s.honest[j]),
                "{name}: {t:?} honest in {} of {SEEDS}",
                s.honest[j]
            );
        }
        let expected_sinusoids = if name == "sinusoid" { SEEDS } else { 0 };
        assert_eq!(
            s.sinusoid_named, expected_sinusoids,
            "{name}: sinusoids named"
        );
        if name == "trend" {
            assert!(
                !inside(s.old_covered[2]),
                "the negative control passed: the old fit covers K {} on the trend logs",
                s.old_covered[2]
            );
        }
        if name == "sinusoid" {
            assert!(s.rejected >= 99, "{name}: rejected {}", s.rejected);
            // K's reading is as good as its own σ says: the count within 25 % lies within
            // z_{0.995}·sd of the count its σ's predict (normal approximation, 1 % two-sided).
            let (expected, sd) = k_within_quarter_expected(&s);
            let found = s.within_quarter[2] as f64;
            assert!(
                (found - expected).abs() <= 2.576 * sd + 0.5,
                "K within 25 % on {found} logs, its σ's predict {expected:.1} ± {sd:.1}"
            );
            assert!(
                !inside(s.old_covered[0]) && !inside(s.old_covered[1]),
                "the negative control passed: the old fit covers N {} B {}",
                s.old_covered[0],
                s.old_covered[1]
            );
        }
    }
}
