//! Quantiles of the null distributions the checks use: the standard normal and χ².
//!
//! statrs supplies the distributions; χ² quantiles are refined by a safeguarded Newton's method
//! on the tail probability itself, which stays accurate far into either tail and for one or two
//! degrees of freedom.

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

/// Which tail of a distribution a probability refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tail {
    /// P(X ≤ x).
    Lower,
    /// P(X > x).
    Upper,
}

/// The smallest two-sided rate whose normal bound [`normal_bound`] computes accurately.
///
/// The bound is formed from 1 − p/2, which double precision carries to within 2⁻⁵³ ≈ 1.1·10⁻¹⁶:
/// p itself to within 11 % at 10⁻¹⁵, and the bound b, whose relative error is about that of p
/// over b², to within 0.2 %. Below it the error grows quickly and under 2.2·10⁻¹⁶ the bound is
/// infinite. The χ² quantiles stay accurate much further, to any positive normal double.
pub const MIN_ACCURATE_RATE: f64 = 1e-15;

/// Two-sided standard normal bound at rate `p`: the b with P(|Z| > b) = p.
///
/// Accurate for p ≥ [`MIN_ACCURATE_RATE`]. Any input returns: p ≤ 0 (and p below about
/// 2.2·10⁻¹⁶) gives +∞, the limit at which nothing is outside the band; p ≥ 1 gives 0; NaN gives
/// NaN.
///
/// # Formula
/// b = Φ⁻¹(1 − p/2), Φ the standard normal CDF.
///
/// # Examples
/// ```
/// let b = accelcal::stats::normal_bound(0.05);
/// assert!((b - 1.959_963_984_540_054).abs() < 1e-9);
/// ```
pub fn normal_bound(p: f64) -> f64 {
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::INFINITY;
    }
    Normal::standard().inverse_cdf(1.0 - p.min(1.0) / 2.0)
}

/// Two-sided band of χ²(dof)/scale at rate `p`: `p/2` in each tail.
///
/// Returns for any input, as [`chi_squared_quantile`] does: p ≤ 0 gives (0, +∞).
pub fn chi_squared_band(dof: f64, scale: f64, p: f64) -> (f64, f64) {
    (
        chi_squared_quantile(dof, p / 2.0, Tail::Lower) / scale,
        chi_squared_quantile(dof, p / 2.0, Tail::Upper) / scale,
    )
}

/// The χ²(dof) quantile whose `tail` holds probability `p`.
///
/// The Wilson–Hilferty approximation (Johnson, Kotz & Balakrishnan, *Continuous Univariate
/// Distributions*, vol. 1, 2nd ed., eq. 18.24) is the starting point (statrs' inverse CDF where
/// it is not positive); the root of the tail probability is then found by Newton's method in
/// log space, safeguarded by a bracket (a step that leaves it is a bisection of the bracket), to
/// a relative step below 10⁻¹⁵. Every loop is bounded, so any input returns: a `dof` that is not
/// a positive finite number, or a NaN `p`, gives NaN; p ≤ 0 gives the end of the support beyond
/// that tail (0 for the lower, +∞ for the upper), p ≥ 1 the other end. Deep tails stay accurate
/// down to p of about 10⁻³⁰⁰ (the bracket's limits).
pub fn chi_squared_quantile(dof: f64, p: f64, tail: Tail) -> f64 {
    let Some(chi) = ChiSquared::new(dof).ok().filter(|_| dof.is_finite()) else {
        return f64::NAN;
    };
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 || p >= 1.0 {
        let lower_end = (p <= 0.0) == (tail == Tail::Lower);
        return if lower_end { 0.0 } else { f64::INFINITY };
    }
    // ln tail(x) − ln p changes sign once, increasing in x as written; it is near linear in ln x
    // for the exponential tails where tail(x) − p is not. With it, the tail itself.
    let log_p = p.ln();
    let miss = |x: f64| match tail {
        Tail::Lower => {
            let c = chi.cdf(x);
            (c.ln() - log_p, c)
        }
        Tail::Upper => {
            let s = chi.sf(x);
            (log_p - s.ln(), s)
        }
    };
    let start = wilson_hilferty(dof, p, tail)
        .filter(|x| x.is_finite() && *x > 0.0)
        .unwrap_or_else(|| {
            let x = chi.inverse_cdf(match tail {
                Tail::Lower => p,
                Tail::Upper => 1.0 - p,
            });
            // 1 − p rounds to 1 for p below 2⁻⁵³, where the inverse is +∞: the bracket then
            // starts from the mean and grows, since the loops below only end from a finite start.
            if x.is_finite() { x } else { dof }
        })
        .max(f64::MIN_POSITIVE);
    let at_start = miss(start);
    if at_start.0 == 0.0 {
        return start;
    }
    let (mut lo, mut hi) = (start, start);
    if at_start.0 > 0.0 {
        while lo > 1e-300 {
            lo /= 4.0;
            if miss(lo).0 <= 0.0 {
                break;
            }
        }
    } else {
        while hi < 1e300 {
            hi *= 4.0;
            if miss(hi).0 >= 0.0 {
                break;
            }
        }
    }
    // d ln tail / d ln x = ± x f(x) / tail(x), f the χ² density: ln f = (k/2 − 1) ln x − x/2 −
    // (k/2) ln 2 − ln Γ(k/2).
    let half = dof / 2.0;
    let log_norm = half * std::f64::consts::LN_2 + statrs::function::gamma::ln_gamma(half);
    let slope = |x: f64, tail: f64| (half * x.ln() - x / 2.0 - log_norm - tail.ln()).exp();
    let (mut x, (mut m, mut t)) = (start, at_start);
    for _ in 0..200 {
        if m < 0.0 {
            lo = lo.max(x);
        } else {
            hi = hi.min(x);
        }
        let newton = x * (-m / slope(x, t)).exp();
        let next = if newton.is_finite() && newton > lo && newton < hi {
            newton
        } else {
            (lo * hi).sqrt()
        };
        if (next / x - 1.0).abs() < 1e-15 || hi / lo - 1.0 < 1e-14 {
            return next;
        }
        x = next;
        (m, t) = miss(x);
        if m == 0.0 {
            return x;
        }
    }
    (lo * hi).sqrt()
}

/// The Wilson–Hilferty approximation of the χ²(dof) quantile whose `tail` holds `p`:
/// k (1 − 2/(9k) + z √(2/(9k)))³ with z the standard normal quantile of the lower tail's
/// probability; `None` where the cube is not positive.
fn wilson_hilferty(dof: f64, p: f64, tail: Tail) -> Option<f64> {
    let lower = match tail {
        Tail::Lower => p,
        Tail::Upper => 1.0 - p,
    };
    let z = Normal::standard().inverse_cdf(lower);
    let c = 2.0 / (9.0 * dof);
    let root = 1.0 - c + z * c.sqrt();
    (root > 0.0).then_some(dof * root * root * root)
}

/// The median of χ²(dof).
pub fn chi_squared_median(dof: f64) -> f64 {
    chi_squared_quantile(dof, 0.5, Tail::Lower)
}

/// One-sided Clopper–Pearson confidence bounds on a binomial probability from `successes` in
/// `trials`: the (lower, upper) bounds, each holding with probability at least `confidence`.
///
/// # Formula
/// lower = B⁻¹(1 − c; k, n − k + 1) (0 when k = 0), upper = B⁻¹(c; k + 1, n − k) (1 when k = n),
/// B⁻¹ the Beta quantile, c the confidence.
///
/// # Panics
/// When `successes > trials`, `trials` is 0 or `confidence` is not in (0, 1).
///
/// # Examples
/// ```
/// // 60 detections in 60 ensembles: the probability is at least 0.951 with 95 % confidence.
/// let (lo, hi) = accelcal::stats::clopper_pearson(60, 60, 0.95);
/// assert!((lo - 0.05f64.powf(1.0 / 60.0)).abs() < 1e-9 && hi == 1.0);
/// ```
pub fn clopper_pearson(successes: u64, trials: u64, confidence: f64) -> (f64, f64) {
    use statrs::distribution::Beta;
    assert!(successes <= trials && trials > 0 && confidence > 0.0 && confidence < 1.0);
    let (k, n) = (successes as f64, trials as f64);
    let lower = if successes == 0 {
        0.0
    } else {
        Beta::new(k, n - k + 1.0)
            .expect("positive shapes")
            .inverse_cdf(1.0 - confidence)
    };
    let upper = if successes == trials {
        1.0
    } else {
        Beta::new(k + 1.0, n - k)
            .expect("positive shapes")
            .inverse_cdf(confidence)
    };
    (lower, upper)
}

/// The two-sided band of the number of successes among `n` trials of probability `p` at
/// false-alarm rate `alpha`: the counts with at most alpha/2 probability below the lower end
/// and at most alpha/2 above the upper end.
pub fn binomial_band(n: u64, p: f64, alpha: f64) -> (u64, u64) {
    use statrs::distribution::{Binomial, DiscreteCDF};
    let b = Binomial::new(p, n).expect("p in [0, 1]");
    let lower = (0..=n).find(|&k| b.cdf(k) > alpha / 2.0).unwrap_or(0);
    let upper = (0..=n)
        .rev()
        .find(|&k| k == 0 || b.cdf(k - 1) < 1.0 - alpha / 2.0)
        .unwrap_or(n);
    (lower, upper)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clopper_pearson_matches_the_tabulated_interval() {
        // 5 of 10: the two-sided 90 % Clopper–Pearson interval is [0.2224, 0.7776].
        let (lo, hi) = clopper_pearson(5, 10, 0.95);
        assert!(
            (lo - 0.222_441).abs() < 1e-5 && (hi - 0.777_559).abs() < 1e-5,
            "{lo} {hi}"
        );
        assert_eq!(clopper_pearson(0, 7, 0.95).0, 0.0);
        assert!((clopper_pearson(0, 7, 0.95).1 - (1.0 - 0.05f64.powf(1.0 / 7.0))).abs() < 1e-9);
    }

    #[test]
    fn normal_bound_is_the_two_sided_quantile() {
        // Pinned from an independent source (scipy.stats.norm.ppf(1 - 0.5e-6)).
        approx::assert_relative_eq!(
            normal_bound(1e-6),
            4.891_638_475_714_78,
            max_relative = 1e-9
        );
        approx::assert_relative_eq!(
            normal_bound(0.05),
            1.959_963_984_540_054,
            max_relative = 1e-9
        );
    }

    #[test]
    fn chi_squared_quantiles_are_exact_for_one_and_two_degrees_of_freedom() {
        let p = 5.5e-6;
        // χ²(1) is the square of a standard normal: its p-quantile is Φ⁻¹((1 + p)/2)².
        let exact = Normal::standard().inverse_cdf(0.5 + p / 2.0).powi(2);
        approx::assert_relative_eq!(
            chi_squared_quantile(1.0, p, Tail::Lower),
            exact,
            max_relative = 1e-6
        );
        // χ²(2) is exponential with mean 2.
        approx::assert_relative_eq!(
            chi_squared_quantile(2.0, p, Tail::Lower),
            -2.0 * (-p).ln_1p(),
            max_relative = 1e-9
        );
        approx::assert_relative_eq!(
            chi_squared_quantile(2.0, p, Tail::Upper),
            -2.0 * p.ln(),
            max_relative = 1e-9
        );
    }

    #[test]
    fn chi_squared_band_matches_wilson_hilferty_for_large_dof() {
        let k = 30_000.0;
        let (lo, hi) = chi_squared_band(k, k, 1e-6);
        let z = normal_bound(1e-6);
        let wh = |z: f64| (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3);
        approx::assert_relative_eq!(lo, wh(-z), max_relative = 1e-4);
        approx::assert_relative_eq!(hi, wh(z), max_relative = 1e-4);
    }

    #[test]
    fn chi_squared_band_holds_its_rate_in_each_tail() {
        // Pinned from an independent source (scipy.stats.chi2.ppf(0.005, 10) and ppf(0.995, 10)).
        let (lo, hi) = chi_squared_band(10.0, 1.0, 0.01);
        approx::assert_relative_eq!(lo, 2.155_856_481_304_639, max_relative = 1e-9);
        approx::assert_relative_eq!(hi, 25.188_179_571_971_17, max_relative = 1e-9);
    }

    use crate::test_support::within_10_s;

    #[test]
    fn quantiles_return_for_any_input_without_panic() {
        let rates = [
            5e-324,
            1e-300,
            1e-17,
            1e-16,
            0.0,
            -1.0,
            1.0,
            1.5,
            f64::NAN,
            f64::INFINITY,
        ];
        let dofs = [0.5, 1.0, 2.0, 12.0, 3e4, 0.0, -1.0, f64::NAN, f64::INFINITY];
        for p in rates {
            let b = within_10_s(move || normal_bound(p));
            assert!(
                b.is_nan() == p.is_nan() && (b >= 0.0 || b.is_nan()),
                "{p}: {b}"
            );
            for dof in dofs {
                for tail in [Tail::Lower, Tail::Upper] {
                    let q = within_10_s(move || chi_squared_quantile(dof, p, tail));
                    let defined = dof > 0.0 && dof.is_finite() && !p.is_nan();
                    assert_eq!(q.is_nan(), !defined, "χ²({dof}) {tail:?} at {p}: {q}");
                    assert!(q.is_nan() || q >= 0.0, "χ²({dof}) {tail:?} at {p}: {q}");
                }
                within_10_s(move || chi_squared_band(dof, 1.0, p));
            }
        }
    }

    #[test]
    fn chi_squared_quantiles_stay_exact_deep_in_the_upper_tail() {
        // χ²(2) is exponential with mean 2: its upper p-quantile is −2 ln p, for p far below the
        // 2⁻⁵³ at which 1 − p rounds to 1.
        for p in [1e-16, 1e-17, 1e-100, 1e-300] {
            let q = within_10_s(move || chi_squared_quantile(2.0, p, Tail::Upper));
            approx::assert_relative_eq!(q, -2.0 * p.ln(), max_relative = 1e-9);
        }
        assert_eq!(normal_bound(0.0), f64::INFINITY);
        // At the smallest accurate rate the bound is still within 0.2 % of the exact one,
        // 8.0268588825 (scipy.stats.norm.isf(0.5e-15)).
        approx::assert_relative_eq!(
            normal_bound(MIN_ACCURATE_RATE),
            8.026_858_882_5,
            max_relative = 2e-3
        );
    }
}
