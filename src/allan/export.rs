//! The files of `accelcal allan`, as bytes: `allan.json`, `noise.toml` and `imu.yaml`. No IO.

use serde::Serialize;

use super::{Analysis, Feature, Reading, Term, TermEstimate};
use crate::format::sig;

#[path = "export_gauss_markov.rs"]
mod gauss_markov_records;
pub use gauss_markov_records::{GaussMarkovRecord, GaussMarkovTestRecord, IntervalRecord};

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
    /// R, m/s³ (a linear trend of the bias).
    pub rate_ramp_m_s3: TermRecord,
    /// Q, m/s, when the shortest τ shows phase noise; null otherwise.
    pub quantization_m_s: Option<TermRecord>,
    /// Where the terms above come from: "fit" (the constrained fit, not rejected) or "ieee952"
    /// (read off the curve, the fit rejected).
    pub reading: &'static str,
    /// The goodness-of-fit test of the constrained fit.
    pub goodness: GoodnessRecord,
    /// Features of the curve the model lacks (a sinusoid's hump, a trend).
    pub features: Vec<FeatureRecord>,
    /// The τ the fit used, s.
    pub tau_s: Vec<f64>,
    /// A term is a value when it stands this many standard errors above zero.
    pub resolution_sigmas: f64,
    /// The keys of the terms the selected model holds ([`super::select`]); a term above and not
    /// here is absent: unresolved, its bound that of the model with it added.
    pub model: Vec<&'static str>,
    /// How the model was chosen.
    pub selection: SelectionRecord,
}

/// `fit.selection` of `allan.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelectionRecord {
    /// The rule, in words.
    pub rule: &'static str,
    /// The nested test's false-entry rate.
    pub entry_alpha: f64,
    /// A term enters when the drop of T over the goodness test's scale exceeds this χ²₁
    /// quantile at `entry_alpha`.
    pub entry_critical: f64,
}

/// `fit.goodness` of `allan.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GoodnessRecord {
    /// T = rᵀWr of the σ² residuals.
    pub statistic: f64,
    /// The Satterthwaite degrees of freedom ν of T ≈ g·χ²_ν.
    pub dof: f64,
    /// The scale g.
    pub scale: f64,
    /// P(g·χ²_ν > T).
    pub p_value: f64,
    /// The stated false-rejection rate.
    pub alpha: f64,
    /// "pass" or "fail" (p < α).
    pub verdict: &'static str,
    /// The τ of the largest standardized residual, s.
    pub worst_tau_s: f64,
}

/// One entry of `fit.features`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeatureRecord {
    /// "sinusoid" or "trend".
    pub kind: &'static str,
    /// The τ of a sinusoid's largest departure, or the first τ of a trend's rise, s.
    pub tau_s: f64,
    /// A sinusoid's frequency 0.371/τ_peak, Hz (null for a trend).
    pub frequency_hz: Option<f64>,
    /// σ̂/σ_fit at that τ (a trend: at the longest τ).
    pub ratio: f64,
}

impl From<&Feature> for FeatureRecord {
    fn from(f: &Feature) -> Self {
        match *f {
            Feature::Sinusoid {
                tau_peak_s,
                frequency_hz,
                ratio,
            } => Self {
                kind: "sinusoid",
                tau_s: tau_peak_s,
                frequency_hz: Some(frequency_hz),
                ratio,
            },
            Feature::Trend { from_tau_s, ratio } => Self {
                kind: "trend",
                tau_s: from_tau_s,
                frequency_hz: None,
                ratio,
            },
        }
    }
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
    /// The constrained fit's σ(τ) at each τ, m/s².
    pub fit_adev_m_s2: Vec<f64>,
    /// (σ̂² − σ²_fit)/√(2σ⁴_fit/edf) at each τ (null without an EDF).
    pub fit_departure_sigmas: Vec<Option<f64>>,
    /// Whether the fitted σ lies inside the estimate's interval at each τ.
    pub fit_holds: Vec<bool>,
    /// The fitted terms.
    pub fit: FitRecord,
    /// The Gauss–Markov bias.
    pub gauss_markov: GaussMarkovRecord,
}

fn record(a: &Analysis, term: Term) -> Option<TermRecord> {
    a.term(term).map(TermRecord::from)
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
        let g = &a.fit.goodness;
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
            fit_adev_m_s2: a.departures.iter().map(|d| d.fit_adev).collect(),
            fit_departure_sigmas: a.departures.iter().map(|d| d.standardized).collect(),
            fit_holds: a.departures.iter().map(|d| d.holds).collect(),
            fit: FitRecord {
                velocity_random_walk_m_s_per_sqrt_s: term(Term::VelocityRandomWalk),
                bias_instability_m_s2: term(Term::BiasInstability),
                acceleration_random_walk_m_s2_per_sqrt_s: term(Term::AccelerationRandomWalk),
                rate_ramp_m_s3: term(Term::RateRamp),
                quantization_m_s: record(a, Term::Quantization),
                reading: a.reading.key(),
                goodness: GoodnessRecord {
                    statistic: g.statistic,
                    dof: g.dof,
                    scale: g.scale,
                    p_value: g.p_value,
                    alpha: g.alpha,
                    verdict: if g.rejected { "fail" } else { "pass" },
                    worst_tau_s: g.worst_tau_s,
                },
                features: a.features.iter().map(FeatureRecord::from).collect(),
                tau_s: a.fit.points.iter().map(|p| p.tau_s).collect(),
                resolution_sigmas: super::fit::RESOLUTION_SIGMAS,
                model: a.fit.model.iter().map(|t| t.key()).collect(),
                selection: SelectionRecord {
                    rule: super::select::RULE,
                    entry_alpha: super::select::ENTRY_ALPHA,
                    entry_critical: super::select::entry_critical(),
                },
            },
            gauss_markov: GaussMarkovRecord::from(&a.gauss_markov),
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
pub(crate) fn num(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

/// `x` rounded to ten significant digits: a rate from a median step carries the time stamps'
/// rounding (10⁻¹¹ s on a day-long log), which a configuration should not.
pub(crate) fn ten_digits(x: f64) -> f64 {
    format!("{x:.9e}").parse().unwrap_or(x)
}

/// The value of `term` for a file another tool reads: the estimate, else the upper bound, with
/// a comment saying which.
fn value_or_bound(a: &Analysis, term: Term) -> (f64, &'static str) {
    match a.term(term) {
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
    s.push_str(&reading_comment(a));
    let k = a.term(Term::AccelerationRandomWalk);
    let b = a.term(Term::BiasInstability);
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

/// The comment of `noise.toml` and `imu.yaml` saying which reading the terms come from.
pub fn reading_comment(a: &Analysis) -> String {
    let g = &a.fit.goodness;
    match a.reading {
        Reading::Fit => format!(
            "# Terms from the model fit (goodness of fit: p = {} ≥ α = {}).\n",
            sig(g.p_value, 2),
            g.alpha
        ),
        Reading::Ieee952 => format!(
            "# The model fit was rejected (p = {} < α = {}; worst at τ = {} s): the terms are\n\
             # read off the curve the IEEE Std 952 way (N on the −½ line, B = σ_min/0.664, K on\n\
             # the +½ line), with intervals from the EDF of the points they come from.\n",
            sig(g.p_value, 2),
            g.alpha,
            sig(g.worst_tau_s, 3)
        ),
    }
}

/// `imu.yaml`: the accelerometer's terms in the convention of Kalibr, OpenVINS and VINS-Mono.
pub fn imu_yaml(a: &Analysis, source: &str) -> String {
    let (n, n_note) = value_or_bound(a, Term::VelocityRandomWalk);
    let (k, k_note) = value_or_bound(a, Term::AccelerationRandomWalk);
    format!(
        "# Accelerometer noise measured by `accelcal allan` from {source}: {} samples.\n{}\
         # Continuous-time densities: noise density N in m/s²/√Hz (= m/s/√s), random walk K in\n\
         # m/s³/√Hz (= m/s²/√s).\n\
         accelerometer_noise_density: {}{}\n\
         accelerometer_random_walk: {}{}\n\
         update_rate: {}\n",
        a.samples,
        reading_comment(a),
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
        for t in &mut a.terms {
            if t.term == term {
                t.value = Some(value);
            } else if t.term != Term::VelocityRandomWalk {
                t.value = None;
            }
        }
        if a.fit.term(term).is_none() {
            let mut t = a.terms[0];
            t.term = term;
            t.value = Some(value);
            a.terms.push(t);
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
