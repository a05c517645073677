//! Whether the bias's interval rests on a model the data reject, and an interval that does not
//! rest on white innovations: the bias's variance scaled by the long-run variance of its own
//! innovation terms.
//!
//! The filter's σ of the bias assumes innovations that are independent, each of variance S_i.
//! When the GPS errors are correlated over several fixes, the filter counts every fix as new
//! information and its σ is too small. The bias's error at the last fix is a linear function of
//! the GPS errors, Σ_i a_iᵀ v_i, with the weights a_i of the filter's own gains and transitions;
//! its variance under correlated errors is Σ_{i,j} a_iᵀ Cov(v_i, v_j) a_j. The innovations r_i
//! carry the errors' correlation, so the ratio of a kernel (HAC) estimate of the variance of
//! Σ ψ_i, ψ_i = a_iᵀ r_i, to its white value Σ_i a_iᵀ S_i a_i scales the filter's variance
//! (Newey & West 1987; the influence-function form of the sandwich, White 1980). The weights matter: the bias draws on the fixes through a kernel of the filter's
//! memory, not through a smooth average of the whole drive, so the innovations' long-run
//! variance at frequency zero (Grenander 1954's factor for a smooth weighted sum) overstates what
//! the bias needs by about three on the simulated drives with a Gauss–Markov GPS error of
//! τ = 1–5 s; that long-run variance per measured component is kept in `summary.json` as a
//! diagnostic.

use serde::Serialize;

use crate::state::{ErrorState, MeasMatrix, StateMatrix, StateVector};
use crate::stats::normal_bound;

use super::bartlett::weighted_autocovariance;
use super::diagnose::Diagnostics;
use super::forward::FilteredFix;
use super::nis::NisTest;

/// Measured components M.
const M: usize = ErrorState::MEAS;
/// The confidence of the bias's intervals, printed and robust.
pub const CONFIDENCE: f64 = 0.95;
/// The Bartlett bandwidth of the bias's innovation terms as a fraction b = S/n of the fixes
/// (a fixed-b bandwidth, Kiefer & Vogelsang 2005, Econometric Theory 21(6): 1130–1164). The
/// MSE-optimal rules (Andrews 1991's AR(1) plug-in, Newey & West 1994) grow as n^{1/3} and
/// give 13–22 fixes here, which cuts off a GPS error correlated over τ = 5 s (25 fixes at
/// 5 Hz) and left the interval covering 180 of 200 drives; a bandwidth that is a fixed share of
/// the drive keeps the correlation of any τ short of the drive's length. Without a mean taken
/// out (the innovations' mean is 0 under the model), the fixed-b distribution of the ratio is
/// narrower than the normal (simulated: the 97.5 % point of |t| is 1.71 at b = 0.2 for white
/// terms of equal weight), so the normal bound is kept.
pub const BANDWIDTH_SHARE: f64 = 0.2;
/// The largest AR(1) coefficient the prewhitening takes (Andrews & Monahan 1992, §3: near 1
/// the recolouring 1/(1 − φ)² explodes).
const MAX_AR1: f64 = 0.97;

/// The long-run variance of one measured component's standardized innovations
/// u_i = r_i / √S_i,kk.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LongRunVariance {
    /// The component: "position" or "velocity".
    pub measurement: &'static str,
    /// The long-run variance 2π·f_u(0) = Σ_j γ_u(j), estimated: 1 for a consistent filter.
    pub long_run_variance: f64,
    /// The prewhitening AR(1) coefficient φ̂.
    pub ar1: f64,
    /// The Bartlett bandwidth S of the prewhitened sequence, in fixes.
    pub bandwidth_fixes: f64,
}

/// `summary.json`'s `bias_robust`: the bias with an interval that does not assume white
/// innovations of variance S_i.
///
/// # Formula
/// σ_robust = σ·√F, F = max(1, λ_b) with λ_b the bias's own long-run variance ratio
/// ([`bias_variance_factor`]): the Bartlett estimate of Var(Σ ψ_i) over its white value. The interval is b̂ ± z·σ_robust, z the normal bound at 1 − [`CONFIDENCE`].
/// For white innovations of the predicted variance λ_b ≈ 1; for innovations whose only fault is
/// their scale it is their mean square weighted as the bias weighs them; for correlated GPS
/// errors it counts the fixes that are not new information. F is never below 1, so the interval
/// is never narrower than the filter's. It still assumes the filter's bias model: a bias that
/// drifts while the filter holds it constant (the bias-path test) is not covered by any
/// rescaling.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiasRobust {
    /// The bias estimate, m/s² (the filter's).
    pub value: f64,
    /// σ_robust, m/s².
    pub sigma: f64,
    /// The interval's lower end, m/s².
    pub lower: f64,
    /// Its upper end, m/s².
    pub upper: f64,
    /// Its confidence.
    pub confidence: f64,
    /// F: the factor on the filter's variance of the bias.
    pub variance_factor: f64,
    /// How σ_robust is found, in words.
    pub method: &'static str,
    /// The Bartlett bandwidth of the bias's innovation terms, in fixes.
    pub bandwidth_fixes: f64,
    /// Each measured component's long-run variance (a diagnostic: the innovations' own
    /// correlation, not the factor).
    pub measurements: Vec<LongRunVariance>,
}

/// [`BiasRobust::method`].
pub const METHOD: &str = "the filter's variance times the long-run variance ratio of the \
    bias's innovation terms a_i'r_i (Bartlett estimate with a bandwidth of a fifth of the fixes, \
    fixed-b as Kiefer & Vogelsang 2005), at least 1";

/// The tests whose rejection makes the bias's interval conditional on a model the data reject,
/// by their names: `nis` (the NIS sum), `whiteness_position`, `whiteness_velocity` (each
/// measured component's whiteness), `bias_path` (the bias against its smoothed path). Each
/// rejects a consistent filter with probability at most α, α/M and α: together at most 3α.
/// The per-fix NIS count and the mean-square tests are left out: they ask of the innovations'
/// scale what the NIS sum asks, and would add to the rate without adding a fault.
pub fn rejected_by(nis: &NisTest, d: &Diagnostics) -> Vec<String> {
    let mut out = Vec::new();
    if nis.verdict == "fail" {
        out.push("nis".to_string());
    }
    for m in &d.measurements {
        if m.whiteness.verdict == "fail" {
            out.push(format!("whiteness_{}", m.measurement));
        }
    }
    if d.bias.verdict == "fail" {
        out.push("bias_path".to_string());
    }
    out
}

/// The words that go next to an interval resting on the model the tests `rejected` reject:
/// "assumes a model the data reject (nis, whiteness_position)"; empty when none does.
pub fn conditional_words(rejected: &[String]) -> String {
    if rejected.is_empty() {
        return String::new();
    }
    format!("assumes a model the data reject ({})", rejected.join(", "))
}

/// A rejecting test named for a reader: `nis` → "the NIS test", `whiteness_position` → "the
/// position innovations' whiteness", `bias_path` → "the bias-path test".
pub fn test_words(id: &str) -> String {
    match id {
        "nis" => "the NIS test".to_string(),
        "bias_path" => "the bias-path test".to_string(),
        other => match other.strip_prefix("whiteness_") {
            Some(m) => format!("the {m} innovations' whiteness"),
            None => other.to_string(),
        },
    }
}

/// [`conditional_words`] for a page: the tests named in words, "a, b and c".
pub fn conditional_page_words(rejected: &[String]) -> String {
    let names: Vec<String> = rejected.iter().map(|r| test_words(r)).collect();
    match names.as_slice() {
        [] => String::new(),
        [one] => format!("assumes a model the data reject ({one})"),
        [rest @ .., last] => format!(
            "assumes a model the data reject ({} and {last})",
            rest.join(", ")
        ),
    }
}

impl BiasRobust {
    /// The robust bias in words: "−0.613172 ± 0.0213 m/s² (95 % interval [−0.655, −0.571]),
    /// the filter's variance × 5540 from the innovations' long-run variance as the bias weighs
    /// them", the ends with the
    /// digits of [`crate::format::interval`] (the estimate with at least 6); and that it still assumes the bias model when
    /// `bias_path` is among the `rejected`.
    pub fn words(&self, rejected: &[String]) -> String {
        use crate::format::{interval_digits, sig};
        let d = interval_digits(self.value, self.lower, self.upper, 3);
        let mut out = format!(
            "{} ± {} m/s² ({} % interval [{}, {}]), the filter's variance × {} from the \
             innovations' long-run variance as the bias weighs them",
            sig(self.value, d.max(6)),
            sig(self.sigma, 3),
            sig(100.0 * self.confidence, 2),
            sig(self.lower, d),
            sig(self.upper, d),
            sig(self.variance_factor, 3),
        );
        if rejected.iter().any(|r| r == "bias_path") {
            out.push_str(
                "; it still assumes the filter's bias model, which the bias-path test rejects",
            );
        }
        out
    }
}

/// The robust interval of the bias `value` with the filter's σ `sigma`, from the innovations of
/// `fixes` ([`BiasRobust`]).
pub fn bias_robust(value: f64, sigma: f64, fixes: &[FilteredFix]) -> BiasRobust {
    let measurements: Vec<LongRunVariance> = (0..M)
        .map(|k| {
            let u: Vec<f64> = fixes
                .iter()
                .map(|f| f.residual[k] / f.s[(k, k)].sqrt())
                .collect();
            let (long_run_variance, ar1, bandwidth_fixes) = long_run_variance(&u);
            LongRunVariance {
                measurement: ErrorState::MEASURED[k].key,
                long_run_variance,
                ar1,
                bandwidth_fixes,
            }
        })
        .collect();
    let (ratio, bandwidth_fixes) = bias_variance_factor(fixes);
    let factor = if ratio.is_finite() {
        ratio.max(1.0)
    } else {
        1.0
    };
    let s = sigma * factor.sqrt();
    let z = normal_bound(1.0 - CONFIDENCE);
    BiasRobust {
        value,
        sigma: s,
        lower: value - z * s,
        upper: value + z * s,
        confidence: CONFIDENCE,
        variance_factor: factor,
        method: METHOD,
        bandwidth_fixes,
        measurements,
    }
}

/// The bias's innovation terms ψ_i = a_iᵀ r_i and their predicted variances a_iᵀ S_i a_i, fix by
/// fix: a_i the weight with which fix i's measurement error enters the bias's error at the
/// last fix, the innovation r_i standing in for that error's correlation.
///
/// # Formula
/// The filter's error obeys e⁺_i = (I − K_i H)·Φ_i·e⁺_{i−1} − K_i v_i (+ process noise), v_i
/// the GPS error (the error-budget recursion, Gelb 1974, Applied Optimal Estimation §7.1), so
/// the bias's error at the last fix N is −Σ_i a_iᵀ v_i + …, a_iᵀ = e_bᵀ Ψ(N, i) K_i,
/// Ψ(N, i) = (I − K_N H)Φ_N ⋯ (I − K_{i+1} H)Φ_{i+1}. Run backwards: λ_N = e_b, a_i = K_iᵀ λ_i,
/// λ_{i−1} = Φ_iᵀ (I − K_i H)ᵀ λ_i; K_i = P⁻_i Hᵀ S_i⁻¹ (Maybeck 1979, eq. 5-46).
pub fn bias_terms(fixes: &[FilteredFix]) -> (Vec<f64>, Vec<f64>) {
    // H of the error state: GPS sees the position and velocity errors.
    let mut h = nalgebra::SMatrix::<f64, M, { ErrorState::DIM }>::zeros();
    h[(ErrorState::GPS_POSITION, ErrorState::POSITION)] = 1.0;
    h[(ErrorState::GPS_VELOCITY, ErrorState::VELOCITY)] = 1.0;
    let mut lambda = StateVector::zeros();
    lambda[ErrorState::BIAS] = 1.0;
    let (mut psi, mut predicted) = (vec![0.0; fixes.len()], vec![0.0; fixes.len()]);
    for (i, f) in fixes.iter().enumerate().rev() {
        let Some(s_inv) = f.s.try_inverse() else {
            return (vec![], vec![]);
        };
        let s_inv: MeasMatrix = s_inv;
        let gain = f.p_prior.matrix() * h.transpose() * s_inv;
        let a = gain.transpose() * lambda;
        psi[i] = a.dot(&f.residual);
        predicted[i] = (a.transpose() * f.s * a)[(0, 0)];
        let closed: StateMatrix = StateMatrix::identity() - gain * h;
        lambda = f.phi_from_previous.transpose() * (closed.transpose() * lambda);
    }
    (psi, predicted)
}

/// The bias's long-run variance ratio λ_b and the bandwidth S it used, in fixes: NaN without
/// fixes.
///
/// # Formula
/// λ_b = [Σ_i ψ_i² + 2 Σ_{1 ≤ j < S} (1 − j/S) Σ_i ψ_i ψ_{i+j}] / min(Σ_i ψ_i², Σ_i a_iᵀ S_i a_i)
/// ([`bias_terms`]), the Bartlett kernel of Newey & West (1987, Econometrica 55(3): 703–708)
/// about the known mean 0, S = [`BANDWIDTH_SHARE`]·n. The denominator is the white value
/// Σ a_iᵀ S_i a_i when the terms are larger than predicted (so an excess of scale counts, the
/// classic NIS rescaling), and their own Σ ψ_i² when smaller: a GPS error correlated over many
/// fixes is partly taken into the filter's states, which makes the innovations smaller than
/// predicted while the bias's error grows, so a shortfall of scale is not credited.
pub fn bias_variance_factor(fixes: &[FilteredFix]) -> (f64, f64) {
    let (psi, predicted) = bias_terms(fixes);
    let white: f64 = predicted.iter().sum();
    let n = psi.len();
    let bandwidth = (BANDWIDTH_SHARE * n as f64).max(1.0);
    if n == 0 || white <= 0.0 {
        return (f64::NAN, bandwidth);
    }
    let (long_run, gamma0) = weighted_autocovariance(&psi, bandwidth);
    (long_run.max(0.0) / white.min(gamma0), bandwidth)
}

/// The long-run variance λ = Σ_j γ(j) of a sequence `u` of mean 0, with the AR(1) coefficient
/// and the bandwidth it used: (λ, φ̂, S). 1 below 3 values.
///
/// # Formula
/// Prewhitened kernel estimate (Andrews & Monahan 1992, Econometrica 60(4): 953–966):
/// φ̂ = Σ u_t·u_{t−1} / Σ u_{t−1}², clamped to ±0.97; e_t = u_t − φ̂·u_{t−1};
/// γ̂_e(j) = (1/n) Σ e_t·e_{t+j} (about the known mean 0, as the whiteness test);
/// λ_e = γ̂_e(0) + 2 Σ_{1 ≤ j < S} (1 − j/S)·γ̂_e(j), the Bartlett kernel of Newey & West
/// (1987, Econometrica 55(3): 703–708), with the bandwidth of Andrews (1991, Econometrica
/// 59(3): 817–858, eq. (6.2) and §6's AR(1) plug-in) S = 1.1447·(α̂·n)^{1/3},
/// α̂ = 4ρ̂² / ((1 − ρ̂)²(1 + ρ̂)²), ρ̂ the lag-1 coefficient of e; recoloured,
/// λ = λ_e / (1 − φ̂)². An AR(1) sequence (a first-order Gauss–Markov error sampled at the
/// fixes) is whitened by the first step, which leaves the kernel little bias to make.
pub fn long_run_variance(u: &[f64]) -> (f64, f64, f64) {
    let n = u.len();
    if n < 3 {
        return (1.0, 0.0, 0.0);
    }
    let ar1 = |x: &[f64]| {
        let den: f64 = x[..x.len() - 1].iter().map(|a| a * a).sum();
        let num: f64 = x.windows(2).map(|w| w[0] * w[1]).sum();
        if den > 0.0 { num / den } else { 0.0 }
    };
    let phi = ar1(u).clamp(-MAX_AR1, MAX_AR1);
    let e: Vec<f64> = u.windows(2).map(|w| w[1] - phi * w[0]).collect();
    let rho = ar1(&e).clamp(-MAX_AR1, MAX_AR1);
    let m = e.len() as f64;
    let alpha = 4.0 * rho * rho / ((1.0 - rho).powi(2) * (1.0 + rho).powi(2));
    let bandwidth = (1.1447 * (alpha * m).cbrt()).min(m - 1.0);
    let lambda_e = weighted_autocovariance(&e, bandwidth).0 / m;
    (lambda_e.max(0.0) / (1.0 - phi).powi(2), phi, bandwidth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Stream;

    /// An AR(1) sequence of unit variance with coefficient `phi`, from seed `seed`.
    fn ar1(phi: f64, n: usize, seed: u64) -> Vec<f64> {
        let mut s = Stream::new(seed, 0);
        let innovation = (1.0 - phi * phi).sqrt();
        let mut x = s.normal();
        (0..n)
            .map(|_| {
                x = phi * x + innovation * s.normal();
                x
            })
            .collect()
    }

    #[test]
    fn long_run_variance_of_ar1_sequences_is_near_its_closed_form() {
        // λ = (1 + φ)/(1 − φ) for unit variance. Averaged over 400 sequences of 2 000 values
        // the estimate's relative error is within 10 %; white sequences give 1.
        for (phi, truth) in [(0.0, 1.0), (0.5, 3.0), (0.9, 19.0)] {
            let mean = (0..400)
                .map(|seed| long_run_variance(&ar1(phi, 2000, seed)).0)
                .sum::<f64>()
                / 400.0;
            assert!(
                (mean / truth - 1.0).abs() < 0.1,
                "φ {phi}: {mean} vs {truth}"
            );
        }
        // The negative control: the variance alone (what the white model uses) misses it.
        let u = ar1(0.9, 2000, 1);
        let var = u.iter().map(|x| x * x).sum::<f64>() / 2000.0;
        assert!(var < 2.0 && long_run_variance(&u).0 > 10.0);
        assert_eq!(long_run_variance(&[1.0, 2.0]), (1.0, 0.0, 0.0));
    }
}
