//! The overlapping Allan deviation of rate samples, from their cumulative sums.
//!
//! # Formula
//! NIST SP 1065 (Riley 2008), eq. (11): with the phase x_0 = 0, x_{i+1} = x_i + (y_i − ȳ)·τ₀ of
//! n rate samples y_i, at τ = m·τ₀
//!
//! σ²(τ) = Σ_{k=0}^{M−1} (x_{k+2m} − 2x_{k+m} + x_k)² / (2 M τ²),  M = n + 1 − 2m,
//!
//! which is allantools' `oadev(y, rate = 1/τ₀, data_type = "freq")`. The mean is subtracted
//! before summing, as allantools does, so that a 1 g offset does not swamp the differences.
//! Each τ costs O(n); the sum of squares runs in blocks of [`BLOCK`] terms (four running sums
//! each), so its rounding error stays near that of a pairwise sum.

use crate::progress::{Cancel, Cancelled};

/// Terms summed per block before the block's sum joins the total.
pub const BLOCK: usize = 4096;

/// Averaging factors m of the octave grid for `samples` rate samples: m = 1, 2, 4, … while the
/// estimator keeps at least two terms (n + 1 − 2m ≥ 2), as allantools' `taus = "octave"`.
pub fn octave_factors(samples: usize) -> Vec<usize> {
    let mut m = 1usize;
    let mut out = Vec::new();
    while samples >= 1 && 2 * m < samples {
        out.push(m);
        m *= 2;
    }
    out
}

/// The mean of `y`, summed in blocks (pairwise-like accuracy) on all threads, the blocks added
/// in order.
pub fn mean(y: &[f64]) -> f64 {
    use rayon::prelude::*;
    let sums: Vec<f64> = y.par_chunks(BLOCK).map(|c| c.iter().sum::<f64>()).collect();
    sums.iter().sum::<f64>() / y.len() as f64
}

/// Samples per stretch of the cumulative sum in [`phase`].
const PHASE_STRETCH: usize = 1 << 16;

/// The phase of rate samples `y` in units of samples: x_0 = 0, x_{i+1} = x_i + (y_i − ȳ) (the
/// factor τ₀ is applied by [`overlapping_avar`]).
///
/// The running sum is taken in stretches of 65 536 samples on all threads: each stretch's total
/// first, then each stretch from the sum of those before it (fixed stretches: the same bits on
/// any thread count).
pub fn phase(y: &[f64]) -> Vec<f64> {
    use rayon::prelude::*;
    let ybar = mean(y);
    let totals: Vec<f64> = y
        .par_chunks(PHASE_STRETCH)
        .map(|c| c.iter().map(|v| v - ybar).sum::<f64>())
        .collect();
    let mut starts = Vec::with_capacity(totals.len());
    let mut s = 0.0;
    for t in &totals {
        starts.push(s);
        s += t;
    }
    let mut x = vec![0.0; y.len() + 1];
    x[1..]
        .par_chunks_mut(PHASE_STRETCH)
        .zip(y.par_chunks(PHASE_STRETCH))
        .zip(starts)
        .for_each(|((out, chunk), start)| {
            let mut s = start;
            for (o, v) in out.iter_mut().zip(chunk) {
                s += v - ybar;
                *o = s;
            }
        });
    x
}

/// [`phase`] where the samples are: `held` is [_, y_0, …, y_{n−1}] on entry and the phase
/// x_0 … x_n on return, the same bits as [`phase`] of y (the same sums in the same order).
pub fn phase_in_place(held: &mut [f64]) {
    use rayon::prelude::*;
    let Some((first, y)) = held.split_first_mut() else {
        return;
    };
    let ybar = mean(y);
    let totals: Vec<f64> = y
        .par_chunks(PHASE_STRETCH)
        .map(|c| c.iter().map(|v| v - ybar).sum::<f64>())
        .collect();
    let mut starts = Vec::with_capacity(totals.len());
    let mut s = 0.0;
    for t in &totals {
        starts.push(s);
        s += t;
    }
    *first = 0.0;
    y.par_chunks_mut(PHASE_STRETCH)
        .zip(starts)
        .for_each(|(chunk, start)| {
            let mut s = start;
            for o in chunk.iter_mut() {
                s += *o - ybar;
                *o = s;
            }
        });
}

/// Σ_{k=0}^{M−1} (x_{k+2m} − 2x_{k+m} + x_k)² over the phase `x`, M = len(x) − 2m (zero if
/// M ≤ 0).
pub fn second_difference_sum(x: &[f64], m: usize) -> f64 {
    if x.len() <= 2 * m {
        return 0.0;
    }
    let terms = x.len() - 2 * m;
    let (x0, x1, x2) = (&x[..terms], &x[m..m + terms], &x[2 * m..2 * m + terms]);
    let mut total = 0.0;
    for start in (0..terms).step_by(BLOCK) {
        let end = (start + BLOCK).min(terms);
        let mut lanes = [0.0f64; 4];
        let (a, b, c) = (&x0[start..end], &x1[start..end], &x2[start..end]);
        let whole = a.len() / 4 * 4;
        for i in (0..whole).step_by(4) {
            for l in 0..4 {
                let d = c[i + l] - 2.0 * b[i + l] + a[i + l];
                lanes[l] += d * d;
            }
        }
        for i in whole..a.len() {
            let d = c[i] - 2.0 * b[i] + a[i];
            lanes[0] += d * d;
        }
        total += (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
    }
    total
}

/// The overlapping Allan variance at τ = m·τ₀ from the phase `x` of [`phase`] (in samples),
/// (unit of y)².
///
/// # Formula
/// σ²(mτ₀) = S / (2 M m²) with S = [`second_difference_sum`] and M = len(x) − 2m; the phase
/// in samples makes τ₀ cancel.
pub fn overlapping_avar(x: &[f64], m: usize) -> f64 {
    let terms = x.len().saturating_sub(2 * m);
    if terms == 0 {
        return f64::NAN;
    }
    second_difference_sum(x, m) / (2.0 * terms as f64 * (m * m) as f64)
}

/// Phase points k per stretch of [`overlapping_avars`]: the unit of work of one thread.
pub const STRETCH: usize = 1 << 16;

/// Σ (c_i − 2b_i + a_i)² over one block of equal-length slices (the phase at k, k + m and
/// k + 2m), with eight running sums.
#[inline(always)]
pub(crate) fn block_sum_of(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    let len = a.len();
    let mut lanes = [0.0f64; 8];
    let whole = len / 8 * 8;
    for ((a8, b8), c8) in a[..whole]
        .chunks_exact(8)
        .zip(b[..whole].chunks_exact(8))
        .zip(c[..whole].chunks_exact(8))
    {
        for l in 0..8 {
            let d = c8[l] - 2.0 * b8[l] + a8[l];
            lanes[l] += d * d;
        }
    }
    for i in whole..len {
        let d = c[i] - 2.0 * b[i] + a[i];
        lanes[0] += d * d;
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]))
        + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]))
}

/// The sums of one stretch [from, to) of k at every factor, block by block, each block's by
/// `block` (the arithmetic of [`block_sum_of`]).
#[inline(always)]
fn stretch_sums_plain(
    x: &[f64],
    factors: &[usize],
    terms: &[usize],
    (from, to): (usize, usize),
    block: impl Fn(&[f64], &[f64], &[f64]) -> f64,
) -> Vec<f64> {
    let mut sums = vec![0.0; factors.len()];
    for start in (from..to).step_by(BLOCK) {
        for (j, &m) in factors.iter().enumerate() {
            let end = (start + BLOCK).min(to).min(terms[j]);
            if start < end {
                sums[j] += block(
                    &x[start..end],
                    &x[start + m..end + m],
                    &x[start + 2 * m..end + 2 * m],
                );
            }
        }
    }
    sums
}

/// [`stretch_sums_plain`], with the AVX2 form of the blocks when the processor has it (the
/// same bits: the same operations lane by lane, in the same order).
pub(crate) fn stretch_sums(
    x: &[f64],
    factors: &[usize],
    terms: &[usize],
    from: usize,
    to: usize,
) -> Vec<f64> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { stretch_sums_avx2(x, factors, terms, (from, to)) };
    }
    stretch_sums_plain(x, factors, terms, (from, to), block_sum_of)
}

/// [`stretch_sums_plain`] with [`block_sum_avx2`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn stretch_sums_avx2(
    x: &[f64],
    factors: &[usize],
    terms: &[usize],
    stretch: (usize, usize),
) -> Vec<f64> {
    stretch_sums_plain(x, factors, terms, stretch, |a, b, c| {
        block_sum_avx2(a, b, c)
    })
}

/// [`block_sum_of`] in 256-bit operations: its eight running sums as two vectors of four,
/// each lane's d = (c − 2b) + a and sum + d·d exactly as there (no fused multiply-add).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_sum_avx2(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd,
        _mm256_storeu_pd, _mm256_sub_pd,
    };
    let len = a.len();
    let (b, c) = (&b[..len], &c[..len]);
    let whole = len / 8 * 8;
    let two = _mm256_set1_pd(2.0);
    let (mut low, mut high) = (_mm256_setzero_pd(), _mm256_setzero_pd());
    let mut i = 0;
    while i < whole {
        // SAFETY: i + 8 <= whole <= len, the length of a, b and c: every load is within them.
        let (a0, b0, c0, a1, b1, c1) = unsafe {
            (
                _mm256_loadu_pd(a.as_ptr().add(i)),
                _mm256_loadu_pd(b.as_ptr().add(i)),
                _mm256_loadu_pd(c.as_ptr().add(i)),
                _mm256_loadu_pd(a.as_ptr().add(i + 4)),
                _mm256_loadu_pd(b.as_ptr().add(i + 4)),
                _mm256_loadu_pd(c.as_ptr().add(i + 4)),
            )
        };
        let d0 = _mm256_add_pd(_mm256_sub_pd(c0, _mm256_mul_pd(two, b0)), a0);
        let d1 = _mm256_add_pd(_mm256_sub_pd(c1, _mm256_mul_pd(two, b1)), a1);
        low = _mm256_add_pd(low, _mm256_mul_pd(d0, d0));
        high = _mm256_add_pd(high, _mm256_mul_pd(d1, d1));
        i += 8;
    }
    let mut lanes = [0.0f64; 8];
    // SAFETY: `lanes` holds eight f64: two stores of four.
    unsafe {
        _mm256_storeu_pd(lanes.as_mut_ptr(), low);
        _mm256_storeu_pd(lanes.as_mut_ptr().add(4), high);
    }
    for i in whole..len {
        let d = c[i] - 2.0 * b[i] + a[i];
        lanes[0] += d * d;
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]))
        + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]))
}

/// The overlapping Allan variance at every factor of `factors` from the phase `x` (in
/// samples), in one pass over the phase.
///
/// The phase is cut into stretches of [`STRETCH`] points k, summed on all threads and added in
/// stretch order (the same bits on any thread count). Within a stretch every τ runs block by
/// block, so that x_{k+m} and x_{k+2m} of short τ come from the cache and the long τ share
/// their streams (x_{k+2m} at m is x_{k+m′} at m′ = 2m): one pass over memory instead of three
/// per τ.
pub fn overlapping_avars(x: &[f64], factors: &[usize]) -> Vec<f64> {
    match overlapping_avars_polled(x, factors, &Cancel::new()) {
        Ok(avars) => avars,
        Err(Cancelled) => unreachable!("a flag nobody holds is never raised"),
    }
}

/// [`overlapping_avars`] that polls `cancel` before each stretch: a raised flag stops the pass
/// within one stretch per thread (65 536 phase points, well under a millisecond).
///
/// # Errors
/// [`Cancelled`] when `cancel` was raised before the last stretch.
pub fn overlapping_avars_polled(
    x: &[f64],
    factors: &[usize],
    cancel: &Cancel,
) -> Result<Vec<f64>, Cancelled> {
    use rayon::prelude::*;
    let terms: Vec<usize> = factors
        .iter()
        .map(|&m| x.len().saturating_sub(2 * m))
        .collect();
    let longest = terms.iter().copied().max().unwrap_or(0);
    let partial: Vec<Vec<f64>> = (0..longest.div_ceil(STRETCH))
        .into_par_iter()
        .map(|s| {
            cancel.check()?;
            let (from, to) = (s * STRETCH, ((s + 1) * STRETCH).min(longest));
            Ok(stretch_sums(x, factors, &terms, from, to))
        })
        .collect::<Result<_, Cancelled>>()?;
    Ok(factors
        .iter()
        .enumerate()
        .map(|(j, &m)| {
            if terms[j] == 0 {
                return f64::NAN;
            }
            let total: f64 = partial.iter().map(|p| p[j]).sum();
            total / (2.0 * terms[j] as f64 * (m * m) as f64)
        })
        .collect())
}

/// The overlapping Allan deviation of rate samples `y` at each averaging factor of `factors`,
/// (unit of y).
pub fn oadev(y: &[f64], factors: &[usize]) -> Vec<f64> {
    let x = phase(y);
    overlapping_avars(&x, factors)
        .into_iter()
        .map(f64::sqrt)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook double loop, block means and all.
    fn literal_avar(y: &[f64], m: usize) -> f64 {
        let n = y.len();
        let mean = |k: usize| y[k..k + m].iter().sum::<f64>() / m as f64;
        let terms = n + 1 - 2 * m;
        (0..terms)
            .map(|k| (mean(k + m) - mean(k)).powi(2))
            .sum::<f64>()
            / (2.0 * terms as f64)
    }

    #[test]
    fn equals_the_literal_definition() {
        let y: Vec<f64> = (0..257)
            .map(|i| ((i * 7919) % 101) as f64 * 0.01 + 9.81)
            .collect();
        let x = phase(&y);
        for m in octave_factors(y.len()) {
            let want = literal_avar(&y, m);
            let got = overlapping_avar(&x, m);
            assert!((got / want - 1.0).abs() < 1e-9, "m = {m}: {got} vs {want}");
            let fused = overlapping_avars(&x, &[m])[0];
            assert!(
                (fused / want - 1.0).abs() < 1e-9,
                "m = {m}: {fused} vs {want}"
            );
        }
    }

    #[test]
    fn octave_grid_keeps_two_terms() {
        assert_eq!(octave_factors(10), vec![1, 2, 4]);
        assert_eq!(octave_factors(9), vec![1, 2, 4]);
        assert_eq!(octave_factors(8), vec![1, 2]);
        assert!(octave_factors(2).is_empty());
    }

    /// A raised flag stops the pass and the analysis with `Cancelled`; a flag never raised gives
    /// the numbers of the calls without one (the control).
    #[test]
    fn a_raised_flag_stops_the_pass() {
        let y: Vec<f64> = (0..3 * STRETCH)
            .map(|i| ((i * 7919) % 101) as f64 * 0.01)
            .collect();
        let x = phase(&y);
        let factors = octave_factors(y.len());
        let raised = Cancel::new();
        raised.cancel();
        assert_eq!(
            overlapping_avars_polled(&x, &factors, &raised),
            Err(Cancelled)
        );
        assert_eq!(
            overlapping_avars_polled(&x, &factors, &Cancel::new()),
            Ok(overlapping_avars(&x, &factors))
        );
        assert_eq!(
            crate::allan::analyse_cancellable(&y, 0.01, 0.683, &raised),
            Err(crate::allan::AllanError::Cancelled(Cancelled))
        );
        // Debug text: the analysis holds NaN (undetermined terms' σ), which == never equals.
        assert_eq!(
            format!(
                "{:?}",
                crate::allan::analyse_cancellable(&y, 0.01, 0.683, &Cancel::new())
            ),
            format!("{:?}", crate::allan::analyse(&y, 0.01, 0.683))
        );
    }
}
