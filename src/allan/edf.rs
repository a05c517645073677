//! Equivalent degrees of freedom of the Allan variance and the χ² interval they give.
//!
//! Greenhall & Riley, "Uncertainty of stability variances based on finite differences", Proc.
//! 35th PTTI (2003), and Greenhall, "Spectral ambiguity of Allan variance" (2004): the EDF of
//! an unmodified variance of difference order d (2 for Allan) at averaging factor m for
//! power-law noise S_y ∝ f^α, overlapping (stride 1) or not, from N phase points. The cases and
//! tables follow the paper as allantools' `edf_greenhall` implements them; the interval is NIST
//! SP 1065, eq. (45).

use crate::stats::{Tail, chi_squared_quantile};

/// Largest J summed term by term (the paper's J_max).
const J_MAX: f64 = 100.0;

/// s_w(t), the paper's eq. (7), for α in −4…2.
fn sw(t: f64, alpha: i32) -> f64 {
    let log_term = |p: i32| {
        if t == 0.0 {
            0.0
        } else {
            t.powi(p) * t.abs().ln()
        }
    };
    match alpha {
        2 => -t.abs(),
        1 => log_term(2),
        0 => t.abs().powi(3),
        -1 => log_term(4),
        -2 => t.abs().powi(5),
        -3 => log_term(6),
        _ => t.abs().powi(7),
    }
}

/// s_x(t), eq. (8); `f = None` stands for F = ∞.
fn sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
    }
}

fn binomial(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// s_z(t), eq. (9): the d-th difference of s_x, Σ_{k=−d}^{d} (−1)^k C(2d, d+k) s_x(t + k).
fn sz(t: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let d_i = d as i32;
    (-d_i..=d_i)
        .map(|k| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sign * binomial(2 * d, (d_i + k) as u32) * sx(t + k as f64, f, alpha)
        })
        .sum()
}

/// The basic sum, eq. (10).
fn basic_sum(j: f64, m_big: f64, s: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let first = sz(0.0, f, alpha, d).powi(2);
    let second = (1.0 - j / m_big) * sz(j / s, f, alpha, d).powi(2);
    let third: f64 = (1..j as u64)
        .map(|i| {
            let i = i as f64;
            2.0 * (1.0 - i / m_big) * sz(i / s, f, alpha, d).powi(2)
        })
        .sum();
    first + second + third
}

/// Table 2 of the paper: (a₀, a₁) for unmodified variances, rows α = 2…−4, columns d = 1…3.
fn table2(alpha: i32, d: u32) -> (f64, f64) {
    const T: [[(f64, f64); 3]; 7] = [
        [(1.5, 0.5), (35.0 / 18.0, 1.0), (231.0 / 100.0, 1.5)],
        [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
        [
            (2.0 / 3.0, 1.0 / 6.0),
            (2.0 / 3.0, 1.0 / 3.0),
            (7.0 / 9.0, 0.5),
        ],
        [(-1.0, -1.0), (0.852, 0.375), (0.997, 0.617)],
        [(-1.0, -1.0), (1.079, 0.368), (1.033, 0.607)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.053, 0.553)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.302, 0.535)],
    ];
    T[(2 - alpha) as usize][(d - 1) as usize]
}

/// Table 3 of the paper: (b₀, b₁) for α = 1, columns d = 1…3.
fn table3(d: u32) -> (f64, f64) {
    [(6.0, 4.0), (15.23, 12.0), (47.8, 40.0)][(d - 1) as usize]
}

/// The EDF of an unmodified variance of difference order `d` at averaging factor `m` for
/// power-law noise α, from `n_phase` phase points (n + 1 for n rate samples); `overlapping`
/// for the overlapping estimator. `None` where the paper gives no formula here (α + 2d ≤ 1, or
/// white phase noise with fewer than d + 1 strides).
///
/// # Formula
/// Greenhall & Riley (2003), eq. (13) and cases 2–4: with F = m, S = m (overlapping) or 1,
/// L = m/F + m·d, M = 1 + ⌊S(N − L)/m⌋, J = min(M, (d+1)S), r = M/S,
/// 1/edf = Σ_J / (s_z(0)² M) while J ≤ 100, else (a₀ − a₁/r)/r from Table 2 (α ≤ 0; with
/// (b₀ + b₁ ln m)² from Table 3 for α = 1), and (a₀ − a₁/r)/M for α = 2.
pub fn greenhall_edf(alpha: i32, d: u32, m: f64, n_phase: f64, overlapping: bool) -> Option<f64> {
    if alpha + 2 * d as i32 <= 1 || alpha > 2 || !(1..=3).contains(&d) {
        return None;
    }
    let f = m;
    let s = if overlapping { m } else { 1.0 };
    let l = m / f + m * d as f64;
    let m_big = 1.0 + (s * (n_phase - l) / m).floor();
    if m_big < 1.0 {
        return None;
    }
    let j = m_big.min((d as f64 + 1.0) * s);
    let r = m_big / s;
    let inv = match alpha {
        a if a <= 0 => {
            if j <= J_MAX {
                let fp = (m * (d as f64 + 1.0) <= J_MAX).then_some(m);
                basic_sum(j, m_big, s, fp, a, d) / (sz(0.0, fp, a, d).powi(2) * m_big)
            } else if r > d as f64 + 1.0 {
                let (a0, a1) = table2(a, d);
                (a0 - a1 / r) / r
            } else {
                let mp = J_MAX / r;
                basic_sum(J_MAX, J_MAX, mp, None, a, d) / (sz(0.0, None, a, d).powi(2) * J_MAX)
            }
        }
        1 => {
            let (b0, b1) = table3(d);
            if j <= J_MAX {
                basic_sum(j, m_big, s, Some(m), 1, d) / (sz(0.0, Some(m), 1, d).powi(2) * m_big)
            } else if r > d as f64 + 1.0 {
                let (a0, a1) = table2(1, d);
                (a0 - a1 / r) / ((b0 + b1 * m.ln()).powi(2) * r)
            } else {
                let mp = J_MAX / r;
                basic_sum(J_MAX, J_MAX, mp, Some(mp), 1, d) / ((b0 + b1 * m.ln()).powi(2) * J_MAX)
            }
        }
        _ => {
            if r.ceil() <= d as f64 {
                return None;
            }
            let a0 = binomial(4 * d, 2 * d) / binomial(2 * d, d).powi(2);
            (a0 - d as f64 / 2.0 / r) / m_big
        }
    };
    (inv > 0.0).then_some(1.0 / inv)
}

/// The two-sided interval of a deviation `dev` with `edf` degrees of freedom at `confidence`.
///
/// # Formula
/// NIST SP 1065, eq. (45): σ² · edf / χ²_{1−p/2}(edf) ≤ σ² ≤ σ² · edf / χ²_{p/2}(edf), with
/// p = 1 − confidence; the deviation's bounds are the square roots.
pub fn chi_squared_interval(dev: f64, edf: f64, confidence: f64) -> (f64, f64) {
    let p = (1.0 - confidence) / 2.0;
    let hi = chi_squared_quantile(edf, p, Tail::Upper);
    let lo = chi_squared_quantile(edf, p, Tail::Lower);
    (dev * (edf / hi).sqrt(), dev * (edf / lo).sqrt())
}
