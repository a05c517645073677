//! The files of `accelcal allan`, as bytes: `allan.json`, `noise.toml` and `imu.yaml`. No IO.

use serde::Serialize;

use super::{Analysis, Term, TermEstimate};
use crate::format::sig;

/// A term in `allan.json`: `value` null when unresolved, `upper` then its upper bound.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TermRecord {
    /// The estimate, or null.
    pub value: Option<f64>,
    /// Lower end of the interval, or null.
    pub lower: Option<f64>,
    /// Upper end of the interval, or the upper bound.
    pub upper: f64,
}

impl From<&TermEstimate> for TermRecord {
    fn from(t: &TermEstimate) -> Self {
        Self {
            value: t.value,
            lower: t.lower,
            upper: t.upper,
        }
    }
}

/// The `fit` object of `allan.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitRecord {
    /// N, m/s/√s.
    pub velocity_random_walk_m_s_per_sqrt_s: TermRecord,
    /// B, m/s².
    pub bias_instability_m_s2: TermRecord,
    /// K, m/s²/√s.
    pub acceleration_random_walk_m_s2_per_sqrt_s: TermRecord,
    /// Q, m/s, when the shortest τ shows phase noise; null otherwise.
    pub quantization_m_s: Option<TermRecord>,
    /// The τ the fit used, s.
    pub tau_s: Vec<f64>,
    /// A term is a value when it stands this many standard errors above zero.
    pub resolution_sigmas: f64,
}

/// `allan.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanRecord {
    /// Samples n.
    pub samples: usize,
    /// τ₀, the median step, s.
    pub sample_period_s: f64,
    /// The confidence of every interval.
    pub confidence: f64,
    /// τ = m·τ₀ at octave spacing, s.
    pub tau_s: Vec<f64>,
    /// The overlapping Allan deviation, m/s².
    pub adev_m_s2: Vec<f64>,
    /// Lower end of its χ² interval, m/s² (null where no EDF applies).
    pub adev_lower_m_s2: Vec<Option<f64>>,
    /// Upper end, m/s².
    pub adev_upper_m_s2: Vec<Option<f64>>,
    /// Equivalent degrees of freedom (Greenhall & Riley).
    pub edf: Vec<Option<f64>>,
    /// The noise exponent α of S_y ∝ f^α identified at each τ.
    pub noise_alpha: Vec<Option<i32>>,
    /// The fitted terms.
    pub fit: FitRecord,
}

fn record(a: &Analysis, term: Term) -> Option<TermRecord> {
    a.fit.term(term).map(TermRecord::from)
}

impl AllanRecord {
    /// The record of an analysis.
    pub fn new(a: &Analysis) -> Self {
        let unfitted = TermRecord {
            value: None,
            lower: None,
            upper: f64::NAN,
        };
        let term = |t| record(a, t).unwrap_or_else(|| unfitted.clone());
        Self {
            samples: a.samples,
            sample_period_s: a.sample_period_s,
            confidence: a.confidence,
            tau_s: a.points.iter().map(|p| p.tau_s).collect(),
            adev_m_s2: a.points.iter().map(|p| p.adev).collect(),
            adev_lower_m_s2: a.points.iter().map(|p| p.interval.map(|i| i.0)).collect(),
            adev_upper_m_s2: a.points.iter().map(|p| p.interval.map(|i| i.1)).collect(),
            edf: a.points.iter().map(|p| p.edf).collect(),
            noise_alpha: a.points.iter().map(|p| p.noise.map(|n| n.alpha)).collect(),
            fit: FitRecord {
                velocity_random_walk_m_s_per_sqrt_s: term(Term::VelocityRandomWalk),
                bias_instability_m_s2: term(Term::BiasInstability),
                acceleration_random_walk_m_s2_per_sqrt_s: term(Term::AccelerationRandomWalk),
                quantization_m_s: record(a, Term::Quantization),
                tau_s: a.fit.points.iter().map(|p| p.tau_s).collect(),
                resolution_sigmas: super::fit::RESOLUTION_SIGMAS,
            },
        }
    }
}

/// `allan.json`, pretty-printed.
pub fn allan_json(a: &Analysis) -> String {
    let mut s = serde_json::to_string_pretty(&AllanRecord::new(a)).expect("serializable");
    s.push('\n');
    s
}

/// A number as TOML or YAML reads it back: shortest round trip.
fn num(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

/// `x` rounded to ten significant digits: a rate from a median step carries the time stamps'
/// rounding (10⁻¹¹ s on a day-long log), which a configuration should not.
fn ten_digits(x: f64) -> f64 {
    format!("{x:.9e}").parse().unwrap_or(x)
}

/// The value of `term` for a file another tool reads: the estimate, else the upper bound, with
/// a comment saying which.
fn value_or_bound(a: &Analysis, term: Term) -> (f64, &'static str) {
    match a.fit.term(term) {
        Some(TermEstimate { value: Some(v), .. }) => (*v, ""),
        Some(t) => (
            t.upper,
            " (upper bound: this log does not resolve the term)",
        ),
        None => (f64::NAN, ""),
    }
}

/// Ratio of the flicker floor B to the steady-state σ of a first-order Gauss–Markov process
/// whose Allan deviation peaks at that floor (IEEE Std 952, annex C: σ_peak ≈ 0.6643·σ_b
/// near τ ≈ 1.89 τ_b).
pub const GAUSS_MARKOV_PEAK_RATIO: f64 = 0.6643;

/// `noise.toml`: the `[accelerometer]` and `[filter]` keys of the measured terms, for
/// `calibrate --config`. The bias is a random walk with K when K is resolved, else a
/// Gauss–Markov process with τ_b at the Allan minimum when B is resolved, else a random walk
/// with K's upper bound.
pub fn noise_toml(a: &Analysis, source: &str) -> String {
    let (n, n_note) = value_or_bound(a, Term::VelocityRandomWalk);
    let per_sample_var = n * n / a.sample_period_s;
    let rate_hz = 1.0 / a.sample_period_s;
    let mut s = format!(
        "# Noise terms measured by `accelcal allan` from {source}: {} samples, τ₀ = {} s.\n\
         # Per-sample variance = N²/τ₀ with N = {} m/s/√s{n_note}.\n\n\
         [accelerometer]\nsample_rate_hz = {}\nnoise_var_m2_s4 = {}\n\n\
         [filter]\naccel_noise_var_m2_s4 = {}\n",
        a.samples,
        num(a.sample_period_s),
        sig(n, 4),
        num(ten_digits(rate_hz)),
        num(per_sample_var),
        num(per_sample_var)
    );
    let k = a.fit.term(Term::AccelerationRandomWalk);
    let b = a.fit.term(Term::BiasInstability);
    let k_resolved = k.is_some_and(|t| t.value.is_some());
    match (k_resolved, b.and_then(|t| t.value)) {
        (false, Some(b_value)) => {
            let tau_b = a.tau_at_minimum_s() / 1.89;
            let sigma_b = b_value / GAUSS_MARKOV_PEAK_RATIO;
            s.push_str(&format!(
                "# B = {} m/s² dominates: a first-order Gauss–Markov bias, τ_b from the Allan\n\
                 # minimum (τ_min/1.89), stationary σ_b = B/{GAUSS_MARKOV_PEAK_RATIO} (variance\n\
                 # σ_b², driving noise √(2σ_b²/τ_b)).\n\
                 bias_model = \"gauss_markov\"\nbias_correlation_time_s = {}\n\
                 bias_var_m2_s4 = {}\n",
                sig(b_value, 4),
                num(tau_b),
                num(sigma_b * sigma_b)
            ));
        }
        _ => {
            let (k_value, k_note) = value_or_bound(a, Term::AccelerationRandomWalk);
            s.push_str(&format!(
                "# A random walk of the bias with K = {} m/s²/√s{k_note}.\n\
                 bias_model = \"random_walk\"\nbias_random_walk_m_s2_per_sqrt_s = {}\n",
                sig(k_value, 4),
                num(k_value)
            ));
        }
    }
    s
}

/// `imu.yaml`: the accelerometer's terms in the convention of Kalibr, OpenVINS and VINS-Mono.
pub fn imu_yaml(a: &Analysis, source: &str) -> String {
    let (n, n_note) = value_or_bound(a, Term::VelocityRandomWalk);
    let (k, k_note) = value_or_bound(a, Term::AccelerationRandomWalk);
    format!(
        "# Accelerometer noise measured by `accelcal allan` from {source}: {} samples.\n\
         # Continuous-time densities: noise density N in m/s²/√Hz (= m/s/√s), random walk K in\n\
         # m/s³/√Hz (= m/s²/√s).\n\
         accelerometer_noise_density: {}{}\n\
         accelerometer_random_walk: {}{}\n\
         update_rate: {}\n",
        a.samples,
        num(n),
        comment(n_note),
        num(k),
        comment(k_note),
        num(ten_digits(1.0 / a.sample_period_s))
    )
}

fn comment(note: &str) -> String {
    if note.is_empty() {
        String::new()
    } else {
        format!("  #{note}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{analyse, simulate::StaticLog};
    use crate::config::Config;
    use crate::model::Model;

    /// The analysis of a white-noise log with K or B set as resolved, as `noise_toml` sees it.
    fn analysis_with(term: Term, value: f64) -> Analysis {
        let log = StaticLog {
            sample_period_s: 0.01,
            velocity_random_walk_m_s_per_sqrt_s: 2e-3,
            acceleration_random_walk_m_s2_per_sqrt_s: 0.0,
            offset_m_s2: 0.0,
        };
        let mut a = analyse(&log.samples(20_000, 3), 0.01, 0.683).unwrap();
        for t in &mut a.fit.terms {
            if t.term == term {
                t.value = Some(value);
            } else if t.term != Term::VelocityRandomWalk {
                t.value = None;
            }
        }
        if a.fit.term(term).is_none() {
            let mut t = a.fit.terms[0];
            t.term = term;
            t.value = Some(value);
            a.fit.terms.push(t);
        }
        a
    }

    /// Both bias models `noise.toml` can choose are configurations the model accepts as they are
    /// (a Gauss–Markov bias takes σ_b² as `bias_var_m2_s4`, not a random walk's K, which the
    /// model refuses as a key it does not use).
    #[test]
    fn noise_toml_is_a_configuration_the_model_accepts() {
        for (term, model) in [
            (Term::AccelerationRandomWalk, "random_walk"),
            (Term::BiasInstability, "gauss_markov"),
        ] {
            let text = noise_toml(&analysis_with(term, 1e-4), "test.csv");
            assert!(
                text.contains(&format!("bias_model = \"{model}\"")),
                "{text}"
            );
            let config = Config::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            Model::new(&config).unwrap_or_else(|e| panic!("{e}\n{text}"));
        }
    }
}
