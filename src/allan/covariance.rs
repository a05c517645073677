//! The covariance of overlapping Allan variance estimates at two averaging times, exactly, for
//! Gaussian white phase noise (quantization), white rate noise (velocity random walk) and a
//! random walk of the rate (acceleration random walk).
//!
//! Estimates at neighbouring τ share most of their data, so their errors are strongly
//! correlated; a fit that weighs them as independent understates its uncertainty. Here each
//! estimate is written as σ̂²_a = Σ_k d_k² / (2 M_a m_a²) with d_k = Σ_j u_j g_a(j − k) a linear
//! filter g_a of independent unit innovations u_j, so that for zero-mean Gaussian d
//! (Isserlis' theorem)
//!
//! Cov(σ̂²_a, σ̂²_b) = Σ_h n_ab(h) c_ab(h)² / (2 M_a M_b m_a² m_b²),
//!
//! c_ab(h) = Σ_noises q · Σ_j g_a(j) g_b(j − h), n_ab(h) = #{k < M_a, l < M_b : l − k = h}.
//!
//! The filters, for averaging factor m and rate samples y:
//! - white rate noise of variance s_w: g = −1 on [0, m), +1 on [m, 2m) (difference of means);
//! - random walk of the rate, increments of variance q: the running sum of that filter, a
//!   triangle g(u) = u on [0, m], 2m − u on [m, 2m];
//! - white phase noise y_i = (v_{i+1} − v_i)/τ₀ of variance Q²: g = (1, −2, 1) at 0, m, 2m, with
//!   q = Q²/τ₀².
//!
//! Each filter is a few linear pieces, so c_ab(h) is piecewise polynomial in h with breaks where
//! piece ends meet; the sum over h runs term by term on short stretches and, on long ones, as
//! a four-point Gauss–Legendre integral with the trapezoidal end correction (relative error of
//! order 1/L² on a stretch of L lags).

/// A linear piece of a filter: value a + b·j for integer j in [lo, hi).
#[derive(Clone, Copy, Debug)]
struct Piece {
    lo: f64,
    hi: f64,
    a: f64,
    b: f64,
}

/// The noise levels of the three terms, per sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseLevels {
    /// Variance of a white phase innovation over τ₀², Q²/τ₀², (unit of y)².
    pub white_phase: f64,
    /// Variance of one white rate sample, N²/τ₀, (unit of y)².
    pub white_rate: f64,
    /// Variance of one random-walk increment, K²·τ₀, (unit of y)².
    pub rate_walk: f64,
}

/// The filters of the three noises at averaging factor m, each with its innovation variance.
fn filters(m: f64, levels: &NoiseLevels) -> [(f64, Vec<Piece>); 3] {
    let p = |lo: f64, hi: f64, a: f64, b: f64| Piece { lo, hi, a, b };
    [
        (
            levels.white_phase,
            vec![
                p(0.0, 1.0, 1.0, 0.0),
                p(m, m + 1.0, -2.0, 0.0),
                p(2.0 * m, 2.0 * m + 1.0, 1.0, 0.0),
            ],
        ),
        (
            levels.white_rate,
            vec![p(0.0, m, -1.0, 0.0), p(m, 2.0 * m, 1.0, 0.0)],
        ),
        (
            levels.rate_walk,
            vec![p(0.0, m, 0.0, 1.0), p(m, 2.0 * m, 2.0 * m, -1.0)],
        ),
    ]
}

/// Σ_j over [lo, hi) of (a₁ + b₁ j)(a₂ + b₂ (j − h)), the polynomial extension in lo, hi.
fn piece_product(p: &Piece, q: &Piece, h: f64) -> f64 {
    let lo = p.lo.max(q.lo + h);
    let hi = p.hi.min(q.hi + h);
    if hi <= lo {
        return 0.0;
    }
    let a2 = q.a - q.b * h;
    let s0 = hi - lo;
    let s1 = (hi * (hi - 1.0) - lo * (lo - 1.0)) / 2.0;
    let f2 = |u: f64| (u - 1.0) * u * (2.0 * u - 1.0) / 6.0;
    let s2 = f2(hi) - f2(lo);
    p.a * a2 * s0 + (p.a * q.b + p.b * a2) * s1 + p.b * q.b * s2
}

/// One pair of averaging times: the filters and the counts of terms.
struct Pair {
    a: [(f64, Vec<Piece>); 3],
    b: [(f64, Vec<Piece>); 3],
    terms_a: f64,
    terms_b: f64,
}

impl Pair {
    /// The pair of averaging factors `m_a`, `m_b` over `samples` rate samples with `levels`.
    fn new(samples: usize, m_a: usize, m_b: usize, levels: &NoiseLevels) -> Self {
        Pair {
            a: filters(m_a as f64, levels),
            b: filters(m_b as f64, levels),
            terms_a: (samples + 1 - 2 * m_a) as f64,
            terms_b: (samples + 1 - 2 * m_b) as f64,
        }
    }

    /// c_ab(h): the covariance of d^a_0 and d^b_h.
    fn c(&self, h: f64) -> f64 {
        let mut total = 0.0;
        for ((q, fa), (_, fb)) in self.a.iter().zip(&self.b) {
            if *q == 0.0 {
                continue;
            }
            // In the order of the pieces; a zero here could only change the sign of a zero
            // sum, which the addition to `total` (from +0) does not keep.
            let mut s = -0.0;
            for p in fa {
                for r in fb {
                    s += piece_product(p, r, h);
                }
            }
            total += q * s;
        }
        total
    }

    /// n_ab(h) c_ab(h)².
    fn term(&self, h: f64) -> f64 {
        let n = self.terms_a.min(self.terms_b - h) - (-h).max(0.0);
        if n <= 0.0 {
            return 0.0;
        }
        n * self.c(h).powi(2)
    }

    /// The lags where the summand changes polynomial, sorted.
    fn breaks(&self) -> Vec<f64> {
        let mut out = vec![0.0, self.terms_b - self.terms_a];
        for ((_, fa), (_, fb)) in self.a.iter().zip(&self.b) {
            for p in fa {
                for r in fb {
                    for ea in [p.lo, p.hi] {
                        for eb in [r.lo, r.hi] {
                            out.push(ea - eb);
                        }
                    }
                }
            }
        }
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }
}

/// Stretches of at most this many lags are summed term by term.
const DIRECT_LAGS: f64 = 64.0;

/// Σ_{h=lo}^{hi−1} of `pair.term(h)` for a stretch where it is one polynomial.
fn stretch_sum(pair: &Pair, lo: f64, hi: f64) -> f64 {
    if hi - lo <= DIRECT_LAGS {
        let mut s = 0.0;
        let mut h = lo;
        while h < hi {
            s += pair.term(h);
            h += 1.0;
        }
        return s;
    }
    // Four-point Gauss–Legendre on [lo, hi], exact for the degree-7 summand, then the
    // trapezoidal correction from the integral to the sum over lo, …, hi − 1.
    const NODES: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    let (mid, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    let integral: f64 = NODES
        .iter()
        .map(|(x, w)| w * pair.term(mid + half * x))
        .sum::<f64>()
        * half;
    // Euler–Maclaurin: Σ_{lo}^{hi−1} f = ∫ f + (f(lo) − f(hi))/2 + (f′(hi) − f′(lo))/12 + …,
    // the slopes taken one lag inside the stretch.
    let (f_lo, f_hi) = (pair.term(lo), pair.term(hi));
    let slope_lo = pair.term(lo + 1.0) - f_lo;
    let slope_hi = f_hi - pair.term(hi - 1.0);
    integral + (f_lo - f_hi) / 2.0 + (slope_hi - slope_lo) / 12.0
}

/// Cov(σ̂²(m_a τ₀), σ̂²(m_b τ₀)) of the overlapping estimator over `samples` rate samples with
/// the noise `levels`, (unit of y)⁴.
pub fn avar_covariance(samples: usize, m_a: usize, m_b: usize, levels: &NoiseLevels) -> f64 {
    let (ma, mb) = (m_a as f64, m_b as f64);
    let pair = Pair::new(samples, m_a, m_b, levels);
    let (first, last) = (-2.0 * mb - 1.0, 2.0 * ma + 2.0);
    let mut cuts: Vec<f64> = pair
        .breaks()
        .into_iter()
        .filter(|&h| h > first && h < last)
        .collect();
    cuts.insert(0, first);
    cuts.push(last);
    let sum: f64 = cuts
        .windows(2)
        .map(|w| stretch_sum(&pair, w[0], w[1]))
        .sum();
    sum / (2.0 * pair.terms_a * pair.terms_b * ma * ma * mb * mb)
}

/// The covariance matrix of the estimates at every factor of `factors`.
pub fn avar_covariance_matrix(
    samples: usize,
    factors: &[usize],
    levels: &NoiseLevels,
) -> Vec<Vec<f64>> {
    let k = factors.len();
    let mut c = vec![vec![0.0; k]; k];
    for i in 0..k {
        for j in i..k {
            let v = avar_covariance(samples, factors[i], factors[j], levels);
            c[i][j] = v;
            c[j][i] = v;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same sum over every lag, term by term.
    fn brute(samples: usize, m_a: usize, m_b: usize, levels: &NoiseLevels) -> f64 {
        let (ma, mb) = (m_a as f64, m_b as f64);
        let pair = Pair::new(samples, m_a, m_b, levels);
        let mut s = 0.0;
        let mut h = -2.0 * mb - 2.0;
        while h < 2.0 * ma + 3.0 {
            s += pair.term(h);
            h += 1.0;
        }
        s / (2.0 * pair.terms_a * pair.terms_b * ma * ma * mb * mb)
    }

    #[test]
    fn quadrature_matches_the_term_by_term_sum() {
        let levels = NoiseLevels {
            white_phase: 0.3,
            white_rate: 1.0,
            rate_walk: 1e-4,
        };
        for (a, b) in [(1, 1), (4, 64), (256, 512), (1024, 1024), (512, 2048)] {
            let got = avar_covariance(20_000, a, b, &levels);
            let want = brute(20_000, a, b, &levels);
            assert!((got / want - 1.0).abs() < 1e-7, "{a},{b}: {got} vs {want}");
        }
    }

    #[test]
    fn white_rate_noise_variance_at_m_1() {
        // For white y of unit variance at m = 1, d_k = y_{k+1} − y_k: c(0) = 2, c(±1) = −1, so
        // Var(σ̂²) = (M·4 + 2(M−1)·1) / (2M²) for M = n − 1 terms.
        let levels = NoiseLevels {
            white_rate: 1.0,
            ..Default::default()
        };
        let n = 1000usize;
        let m_terms = (n - 1) as f64;
        let want = (4.0 * m_terms + 2.0 * (m_terms - 1.0)) / (2.0 * m_terms * m_terms);
        let got = avar_covariance(n, 1, 1, &levels);
        assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
    }
}
