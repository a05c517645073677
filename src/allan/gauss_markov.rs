//! The Allan variance of a first-order Gauss–Markov process: the hump a correlated bias leaves on
//! the curve, the model a fit of σ and T_c will use.
//!
//! # Formula
//! IEEE Std 952-1997, annex C (exponentially correlated, Markov, noise), and El-Sheimy, Hou & Niu,
//! "Analysis and modeling of inertial sensors using Allan variance", IEEE Trans. Instrum. Meas.
//! 57(1), 2008: for ḃ = −b/T_c + w with the process's variance σ² (driving noise density
//! q_c² = 2σ²/T_c), at u = τ/T_c
//!
//! σ_A²(τ) = (q_c T_c)²/τ · [1 − (T_c/2τ)(3 − 4e^{−τ/T_c} + e^{−2τ/T_c})]
//!         = (2σ²/u) · [1 − (3 − 4e^{−u} + e^{−2u})/(2u)].
//!
//! It rises as a rate random walk (2σ²/T_c)·τ/3 for τ ≪ T_c, falls as a white noise
//! q_c²/τ for τ ≫ T_c, and peaks at τ = [`PEAK_U`]·T_c with σ_A = [`PEAK_SIGMA`]·σ: the
//! 1.89 T_c and 0.618 σ of the literature.

/// τ/T_c at the peak of σ_A(τ) (the root of dσ_A²/du = 0, found to 10⁻⁶ in the test).
pub const PEAK_U: f64 = 1.892_62;

/// σ_A at the peak over the process's σ.
pub const PEAK_SIGMA: f64 = 0.617_364;

/// The u below which [`unit_avar`] takes the series: both forms within 10⁻¹⁰ there.
pub const SERIES_BELOW: f64 = 0.02;

/// σ_A²(τ)/σ² at u = τ/T_c ([module formula](self)). Below u = [`SERIES_BELOW`] the bracket's
/// Taylor series u²/3 − u³/4 + 7u⁴/60 − u⁵/24 + 31u⁶/2520 (truncation ~10⁻² u⁵ relative): the
/// closed form loses about 7·10⁻¹⁶/u³ of it to cancellation there.
pub fn unit_avar(u: f64) -> f64 {
    if u < SERIES_BELOW {
        let p =
            1.0 / 3.0 + u * (-1.0 / 4.0 + u * (7.0 / 60.0 + u * (-1.0 / 24.0 + u * 31.0 / 2520.0)));
        return 2.0 * u * p;
    }
    let bracket = 1.0 - (3.0 - 4.0 * (-u).exp() + (-2.0 * u).exp()) / (2.0 * u);
    2.0 / u * bracket
}

/// σ_A²(τ) of a Gauss–Markov process of variance `sigma`² and correlation time `tc_s`, at
/// `tau_s`, (unit of the process)².
pub fn avar(tau_s: f64, sigma: f64, tc_s: f64) -> f64 {
    sigma * sigma * unit_avar(tau_s / tc_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Allan variance of an AR(1) sequence x_{k+1} = φx_k + w_k of variance σ² (a
    /// Gauss–Markov process sampled every τ₀, φ = e^{−τ₀/T_c}) at m samples, from its
    /// autocovariance R(j) = σ²φ^|j|: Var(block mean) − Cov(adjacent block means).
    fn ar1_avar(m: usize, sigma: f64, phi: f64) -> f64 {
        let r = |j: i64| sigma * sigma * phi.powi(j.unsigned_abs() as i32);
        let m = m as i64;
        let var: f64 = (-(m - 1)..m).map(|j| (m - j.abs()) as f64 * r(j)).sum();
        let cov: f64 = (1..2 * m).map(|d| (m - (d - m).abs()) as f64 * r(d)).sum();
        (var - cov) / (m * m) as f64
    }

    /// The closed form against the sampled process's exact Allan variance (an independent
    /// computation): they part by O(τ₀²/(τ T_c)), under 10⁻⁴ from m = 100 at T_c = 1000 τ₀ and
    /// 0.5 at m = 1 (a control: the sum can tell them apart).
    #[test]
    fn equals_the_sampled_process_where_the_samples_resolve_it() {
        let (sigma, tc) = (2.0f64, 1000.0f64);
        let phi = (-1.0 / tc).exp();
        for m in [100usize, 1000, 1893, 10_000, 100_000] {
            let (closed, exact) = (avar(m as f64, sigma, tc), ar1_avar(m, sigma, phi));
            assert!(
                (closed / exact - 1.0).abs() < 1e-4,
                "m = {m}: {closed} vs {exact}"
            );
        }
        let (closed, exact) = (avar(1.0, sigma, tc), ar1_avar(1, sigma, phi));
        assert!((closed / exact - 1.0).abs() > 0.3, "{closed} vs {exact}");
    }

    /// The peak: 1.89 T_c and 0.618 σ (IEEE Std 952, El-Sheimy et al.), by golden-section search.
    #[test]
    fn peaks_at_1_89_tc() {
        let (mut a, mut b) = (1.0f64, 3.0f64);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        while b - a > 1e-9 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if unit_avar(c) > unit_avar(d) {
                b = d;
            } else {
                a = c;
            }
        }
        let u = (a + b) / 2.0;
        assert!((u - PEAK_U).abs() < 1e-5, "{u}");
        assert!((unit_avar(u).sqrt() - PEAK_SIGMA).abs() < 1e-6);
        // The series and the closed form meet where one hands over to the other.
        let (below, above) = (
            unit_avar(SERIES_BELOW * (1.0 - 1e-12)),
            unit_avar(SERIES_BELOW),
        );
        assert!((below / above - 1.0).abs() < 1e-9, "{below} vs {above}");
    }
}
