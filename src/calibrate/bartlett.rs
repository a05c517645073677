//! The Bartlett-kernel sum of a sequence's autocovariances in one pass: O(n) for any bandwidth,
//! where the sum of the lags' products one by one is O(n·S) (O(n²) at a bandwidth that is a
//! share of the sequence).

/// The fewest steps the running window sums take before they are summed afresh (at least L
/// steps, so that the fresh sums cost O(n) in all).
const REFRESH: usize = 64;

/// Σ_{|j| < S} (1 − |j|/S)·γ(j) of `x`, γ(j) = Σ_i x_i·x_{i+j} (about the known mean 0, not
/// divided by n), S = `bandwidth`, the lags j < n: the Bartlett kernel of Newey & West (1987,
/// Econometrica 55(3): 703–708) before its normalization. With γ(0) as the second value.
///
/// # Formula
/// Σ_{1 ≤ j ≤ L} (1 − j/S)·γ(j) = Σ_k x_k·(W_k − V_k/S), L the lags below S, with the window
/// sums over the L values before k, W_k = Σ_{i=k−L}^{k−1} x_i and V_k = Σ_{i=k−L}^{k−1} (k−i)·x_i,
/// carried from k to k + 1 by W_{k+1} = W_k + x_k − x_{k−L} and
/// V_{k+1} = V_k − L·x_{k−L} + W_{k+1} (a term outside the sequence is 0), and summed afresh
/// every max([`REFRESH`], L) steps. The same sum as the lags' products taken lag by lag, to the
/// rounding of the order of the additions: within 10⁻¹² of its bound (2L + 1)·γ(0)
/// (|γ(j)| ≤ γ(0)); 10⁻¹⁴ relative on the drives' bias terms.
pub fn weighted_autocovariance(x: &[f64], bandwidth: f64) -> (f64, f64) {
    let n = x.len();
    let gamma0: f64 = x.iter().map(|a| a * a).sum();
    let lags = (1..n).take_while(|&j| (j as f64) < bandwidth).count();
    if lags == 0 {
        return (gamma0, gamma0);
    }
    let at = |i: isize| if i >= 0 { x[i as usize] } else { 0.0 };
    let l = lags as isize;
    let refresh = REFRESH.max(lags);
    let (mut w, mut v) = (0.0, 0.0);
    let mut cross = 0.0;
    for (k, &xk) in x.iter().enumerate() {
        let k = k as isize;
        if k > 0 && (k as usize).is_multiple_of(refresh) {
            (w, v) = (0.0, 0.0);
            for i in (k - l).max(0)..k {
                w += x[i as usize];
                v += (k - i) as f64 * x[i as usize];
            }
        }
        cross += xk * (w - v / bandwidth);
        let out = at(k - l);
        w += xk - out;
        v += w - l as f64 * out;
    }
    (gamma0 + 2.0 * cross, gamma0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Stream;

    /// The sum lag by lag, as the estimators took it before the one-pass form.
    fn lag_by_lag(x: &[f64], bandwidth: f64) -> f64 {
        let gamma = |j: usize| x.iter().zip(&x[j..]).map(|(a, b)| a * b).sum::<f64>();
        let lags = (1..x.len()).take_while(|&j| (j as f64) < bandwidth);
        gamma(0)
            + 2.0
                * lags
                    .map(|j| (1.0 - j as f64 / bandwidth) * gamma(j))
                    .sum::<f64>()
    }

    #[test]
    fn the_one_pass_sum_is_the_lag_by_lag_sum() {
        let mut s = Stream::new(7, 0);
        for n in [0_usize, 1, 2, 3, 10, 577, 5000, 9000] {
            // White, correlated and offset sequences; bandwidths below 1, fractional, integer,
            // a fifth of n and beyond n.
            let white: Vec<f64> = (0..n).map(|_| s.normal()).collect();
            let mut y = 0.0;
            let ar: Vec<f64> = white
                .iter()
                .map(|e| {
                    y = 0.95 * y + e;
                    y
                })
                .collect();
            let offset: Vec<f64> = white.iter().map(|e| 3.0 + 1e-3 * e).collect();
            for x in [&white, &ar, &offset] {
                for b in [0.5, 1.0, 2.5, 7.0, 0.2 * n as f64, 1.5 * n as f64 + 2.0] {
                    let (got, gamma0) = weighted_autocovariance(x, b);
                    let want = lag_by_lag(x, b);
                    // |γ(j)| ≤ γ(0): the sum's bound.
                    let lags = (b.ceil() - 1.0).clamp(0.0, n.saturating_sub(1) as f64);
                    let scale = (gamma0 * (2.0 * lags + 1.0)).max(f64::MIN_POSITIVE);
                    assert!(
                        (got - want).abs() <= 1e-12 * scale,
                        "n {n}, S {b}: {got} vs {want}"
                    );
                }
            }
        }
    }
}
