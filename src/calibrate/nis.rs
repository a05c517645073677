//! The consistency check real data allows: the normalized innovations squared of every fix.

use serde::Serialize;

use crate::state::ErrorState;
use crate::stats::chi_squared_band;

/// Measurement dimension M: each fix measures position and velocity.
const MEASUREMENT_DIM: u64 = ErrorState::MEAS as u64;

/// The NIS test of a whole log.
///
/// A consistent filter's residuals r_i are independent, each N(0, S_i), so each NIS
/// ε_i = r_iᵀ S_i⁻¹ r_i is χ²(2) and their sum over n fixes is χ²(2n). The sum is tested
/// two-sided at the false-alarm rate α (α/2 in each tail); the per-fix band, also α/2 in each
/// tail of χ²(2), is shown for each fix, about α·n of which fall outside it by chance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NisTest {
    /// Number of fixes n.
    pub fixes: usize,
    /// Σ ε_i.
    pub sum: f64,
    /// Σ ε_i / n (2 expected).
    pub mean: f64,
    /// Degrees of freedom of the sum, 2n.
    pub dof: u64,
    /// Lower end of the acceptance band of the sum: the α/2 quantile of χ²(2n).
    pub lower: f64,
    /// Upper end: the 1 − α/2 quantile of χ²(2n).
    pub upper: f64,
    /// The false-alarm rate α (`checks.false_alarm_rate`).
    pub false_alarm_rate: f64,
    /// "pass" when the sum lies in its band, "fail" otherwise.
    pub verdict: &'static str,
    /// Per-fix band of ε_i, lower end: the α/2 quantile of χ²(2).
    pub per_fix_lower: f64,
    /// Per-fix band, upper end: the 1 − α/2 quantile of χ²(2).
    pub per_fix_upper: f64,
    /// Fixes whose ε_i is outside the per-fix band.
    pub outside_per_fix: usize,
    /// α·n: how many fall outside by chance on average.
    pub expected_outside_per_fix: f64,
}

/// Tests the NIS of every fix, `nis`, at the false-alarm rate `false_alarm_rate` (in [1e-6, 0.5] from the configuration).
pub fn nis_test(nis: &[f64], false_alarm_rate: f64) -> NisTest {
    let n = nis.len();
    let dof = MEASUREMENT_DIM * n as u64;
    let sum: f64 = nis.iter().sum();
    let (lower, upper) = if n == 0 {
        (0.0, 0.0)
    } else {
        chi_squared_band(dof as f64, 1.0, false_alarm_rate)
    };
    let (per_fix_lower, per_fix_upper) =
        chi_squared_band(MEASUREMENT_DIM as f64, 1.0, false_alarm_rate);
    NisTest {
        fixes: n,
        sum,
        mean: if n == 0 { f64::NAN } else { sum / n as f64 },
        dof,
        lower,
        upper,
        false_alarm_rate,
        verdict: if n > 0 && (lower..=upper).contains(&sum) {
            "pass"
        } else {
            "fail"
        },
        per_fix_lower,
        per_fix_upper,
        outside_per_fix: nis
            .iter()
            .filter(|&&e| !(per_fix_lower..=per_fix_upper).contains(&e))
            .count(),
        expected_outside_per_fix: false_alarm_rate * n as f64,
    }
}

/// [`nis_test`] of fixes that measure different numbers of components: fix i's NIS is χ²(m_i)
/// with m_i = `rows[i]`, the sum χ²(Σ m_i); each fix is held to the band of its own m_i, and the
/// per-fix band reported is that of the most common m.
pub fn nis_test_rows(nis: &[f64], rows: &[usize], false_alarm_rate: f64) -> NisTest {
    let mut t = nis_test(nis, false_alarm_rate);
    let n = nis.len();
    t.dof = rows.iter().map(|&m| m as u64).sum();
    (t.lower, t.upper) = if n == 0 {
        (0.0, 0.0)
    } else {
        chi_squared_band(t.dof as f64, 1.0, false_alarm_rate)
    };
    t.verdict = if n > 0 && (t.lower..=t.upper).contains(&t.sum) {
        "pass"
    } else {
        "fail"
    };
    let band = |m: usize| chi_squared_band(m as f64, 1.0, false_alarm_rate);
    t.outside_per_fix = nis
        .iter()
        .zip(rows)
        .filter(|&(e, &m)| {
            let (lo, hi) = band(m);
            !(lo..=hi).contains(e)
        })
        .count();
    let modal = (1..=6)
        .max_by_key(|m| rows.iter().filter(|&&r| r == *m).count())
        .unwrap_or(MEASUREMENT_DIM as usize);
    (t.per_fix_lower, t.per_fix_upper) = band(modal);
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_of_the_sum_is_chi_squared_of_twice_the_fixes() {
        // χ²(2) is exponential with mean 2: its α/2 quantile is −2·ln(1 − α/2).
        let t = nis_test(&[2.0; 10], 0.01);
        assert_eq!(t.dof, 20);
        assert_eq!(t.verdict, "pass");
        approx::assert_relative_eq!(
            t.per_fix_lower,
            -2.0 * (1.0 - 0.005f64).ln(),
            max_relative = 1e-9
        );
        approx::assert_relative_eq!(t.per_fix_upper, -2.0 * 0.005f64.ln(), max_relative = 1e-9);
        // χ²(20) quantiles 0.005 and 0.995 (tables: 7.434, 39.997).
        assert!(
            (t.lower - 7.434).abs() < 1e-3 && (t.upper - 39.997).abs() < 1e-3,
            "{t:?}"
        );
        assert_eq!(nis_test(&[20.0; 10], 0.01).verdict, "fail");
        assert_eq!(nis_test(&[0.1; 10], 0.01).verdict, "fail");
    }
}
