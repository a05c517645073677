//! Identification of the power-law noise at one averaging time by the lag-1 autocorrelation.
//!
//! Riley & Greenhall, "Power law noise identification using the lag 1 autocorrelation",
//! Proc. 18th EFTF (2004), as implemented by allantools' `autocorr_noise_id` for frequency data:
//! the rate samples are averaged in non-overlapping blocks of m, a straight line is removed, and
//! the series is differenced until the lag-1 autocorrelation r₁ gives δ = r₁/(1 + r₁) < 0.25
//! (at most twice). Then α = −2(δ + d) for S_y(f) ∝ f^α, rounded to the nearest integer:
//! +2 white phase (quantization), 0 white rate (velocity random walk), −1 flicker (bias
//! instability), −2 random walk of the rate (acceleration random walk).

mod lag;

use lag::{Consecutive, Held, IOTA, Line, PIECE, Series, Strided, lag1_of};

/// Fewest block means the identification accepts (Riley & Greenhall's recommended minimum).
pub const MIN_POINTS: usize = 30;
/// Most differences taken (2 for the Allan variance).
pub const MAX_DIFFERENCES: u32 = 2;

/// The noise identified at one τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseId {
    /// α rounded to an integer (ties to even, as numpy's `round`).
    pub alpha: i32,
    /// α before rounding: −2(δ + d).
    pub alpha_estimate: f64,
    /// Differences taken, d.
    pub differences: u32,
    /// δ = r₁/(1 + r₁) of the last series.
    pub delta: f64,
}

/// Identifies the noise of the block means `means` (rate data averaged over τ); `None` with
/// fewer than [`MIN_POINTS`] means or a series without variation.
pub fn identify(means: &[f64]) -> Option<NoiseId> {
    identify_with(means.len(), Held(means))
}

/// [`identify`] of the block means of m samples of the rate data whose phase (in samples) is
/// `x` ([`block_means`]), taken from the phase as they are needed: nothing is allocated.
pub fn identify_phase(x: &[f64], m: usize) -> Option<NoiseId> {
    identify_phase_vectorized(x, m)
}

/// [`identify_phase`]'s arithmetic, inlined into each variant of [`identify_phase_vectorized`].
#[inline(always)]
fn identify_phase_plain(x: &[f64], m: usize) -> Option<NoiseId> {
    let scale = 1.0 / m as f64;
    let len = (x.len() - 1) / m;
    if m == 1 {
        return identify_with(len, Consecutive { points: x, scale });
    }
    if m < GATHERED_FROM {
        return identify_with(len, Strided { x, m, scale });
    }
    // Far apart, each point is a cache line of its own: gathered once for the passes.
    let points: Vec<f64> = x.iter().step_by(m).take(len + 1).copied().collect();
    identify_with(
        len,
        Consecutive {
            points: &points,
            scale,
        },
    )
}

/// The averaging factor from which [`identify_phase`] gathers the phase points of its block
/// means before its passes (each point then on a cache line of its own).
const GATHERED_FROM: usize = 8;

crate::lanes::vectorized! {
    /// [`identify_phase_plain`], compiled for AVX2 when the processor has it (the same bits:
    /// the same operations in the same order, no product and sum contracted).
    fn identify_phase_vectorized(x: &[f64], m: usize) -> Option<NoiseId> => identify_phase_plain
}

/// [`identify`] of the series u_0 … u_{L−1} that `fill(start, out)` writes from u_start on:
/// the line removed by its least-squares fit over the index (numpy's `polyfit(t, u, 1)`), then
/// differenced while δ ≥ 0.25, each series taken from `fill` piece by piece as it is needed.
#[inline(always)]
fn identify_with(len: usize, fill: impl Series) -> Option<NoiseId> {
    if len < MIN_POINTS {
        return None;
    }
    let l = len as f64;
    let t_mean = (l - 1.0) / 2.0;
    // u_i in lane i mod 4.
    let (mut sum, mut moment) = ([0.0f64; 4], [0.0f64; 4]);
    let mut u = [0.0; PIECE];
    let mut start = 0;
    while start < len {
        let n = PIECE.min(len - start);
        let u = &mut u[..n];
        fill.fill(start, u);
        let t0 = start as f64;
        let whole = n / 4 * 4;
        for (g, t) in u[..whole].chunks_exact(4).zip(IOTA.chunks_exact(4)) {
            for j in 0..4 {
                sum[j] += g[j];
                moment[j] += ((t0 + t[j]) - t_mean) * g[j];
            }
        }
        for (i, &v) in u.iter().enumerate().skip(whole) {
            sum[i % 4] += v;
            moment[i % 4] += ((start + i) as f64 - t_mean) * v;
        }
        start += n;
    }
    let total = |a: [f64; 4]| (a[0] + a[1]) + (a[2] + a[3]);
    let (sum, moment) = (total(sum), total(moment));
    let u_mean = sum / l;
    // Σ (i − ī)² = L (L² − 1) / 12; Σ (i − ī)(u_i − ū) = Σ (i − ī) u_i.
    let slope = moment / (l * (l * l - 1.0) / 12.0);
    let line = Line {
        fill,
        u_mean,
        slope,
        t_mean,
    };
    let mut d = 0u32;
    loop {
        // The series differenced d times, d ≤ MAX_DIFFERENCES = 2.
        const _: () = assert!(
            MAX_DIFFERENCES == 2,
            "identify_with differences at most twice"
        );
        let r1 = lag1_of(len - d as usize, d as usize, &line);
        if !r1.is_finite() {
            return None;
        }
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || d >= MAX_DIFFERENCES {
            return Some(NoiseId {
                alpha: (-(2.0 * delta).round_ties_even() - 2.0 * d as f64) as i32,
                alpha_estimate: -2.0 * (delta + d as f64),
                differences: d,
                delta,
            });
        }
        d += 1;
    }
}

/// The non-overlapping block means of m samples of the rate data whose phase (in samples) is
/// `x`: (x_{(k+1)m} − x_{km}) / m for k < ⌊n/m⌋. They differ from the raw samples' means by the
/// subtracted mean only, which the line removal takes out.
pub fn block_means(x: &[f64], m: usize) -> Vec<f64> {
    let blocks = (x.len() - 1) / m;
    (0..blocks)
        .map(|k| (x[(k + 1) * m] - x[k * m]) / m as f64)
        .collect()
}

/// The non-increasing sequence nearest `values` in weighted least squares (pool adjacent
/// violators; Barlow, Bartholomew, Bremner & Brunk, *Statistical Inference under Order
/// Restrictions*, 1972): a run that rises is replaced by its weighted mean.
pub fn non_increasing(values: &[f64], weights: &[f64]) -> Vec<f64> {
    // Blocks of (weighted mean, weight, length), each mean below the one before.
    let mut blocks: Vec<(f64, f64, usize)> = Vec::with_capacity(values.len());
    for (&v, &w) in values.iter().zip(weights) {
        let mut block = (v, w, 1);
        while let Some(&(m, wm, l)) = blocks.last() {
            if m >= block.0 {
                break;
            }
            blocks.pop();
            let weight = wm + block.1;
            block = ((m * wm + block.0 * block.1) / weight, weight, l + block.2);
        }
        blocks.push(block);
    }
    blocks
        .into_iter()
        .flat_map(|(m, _, l)| std::iter::repeat_n(m, l))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Stream;

    // The two-pass reference: the line removed into a new series, r₁ from its mean.
    /// The lag-1 autocorrelation of `z`.
    ///
    /// # Formula
    /// Riley & Greenhall (2004), eq. (2): r₁ = Σ_{n=0}^{L−2} (z_n − z̄)(z_{n+1} − z̄) / Σ (z_n − z̄)².
    fn lag1_autocorrelation(z: &[f64]) -> f64 {
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let num: f64 = z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
        let den: f64 = z.iter().map(|v| (v - mean) * (v - mean)).sum();
        num / den
    }

    /// `z` less its least-squares straight line over the index 0, 1, …, L − 1 (numpy's
    /// `polyfit(t, z, 1)`).
    fn remove_line(z: &[f64]) -> Vec<f64> {
        let l = z.len() as f64;
        let t_mean = (l - 1.0) / 2.0;
        let z_mean = z.iter().sum::<f64>() / l;
        let (mut stz, mut stt) = (0.0, 0.0);
        for (i, v) in z.iter().enumerate() {
            let dt = i as f64 - t_mean;
            stz += dt * (v - z_mean);
            stt += dt * dt;
        }
        let slope = if stt > 0.0 { stz / stt } else { 0.0 };
        z.iter()
            .enumerate()
            .map(|(i, v)| v - z_mean - slope * (i as f64 - t_mean))
            .collect()
    }

    /// The running sums of `v`: a random walk of white steps.
    fn cumulative(v: &[f64]) -> Vec<f64> {
        v.iter()
            .scan(0.0, |acc, w| {
                *acc += w;
                Some(*acc)
            })
            .collect()
    }

    /// [`identify`] as Riley & Greenhall state it, one series after another.
    fn identify_reference(means: &[f64]) -> (u32, f64) {
        let mut z = remove_line(means);
        let mut d = 0;
        loop {
            let r1 = lag1_autocorrelation(&z);
            let delta = r1 / (1.0 + r1);
            if delta < 0.25 || d >= MAX_DIFFERENCES {
                return (d, delta);
            }
            z = z.windows(2).map(|w| w[1] - w[0]).collect();
            d += 1;
        }
    }

    #[test]
    fn one_pass_agrees_with_the_two_pass_reference() {
        let mut s = Stream::new(11, 0);
        let white: Vec<f64> = (0..5000).map(|_| 3.0 + s.normal()).collect();
        let walk = cumulative(&white);
        let walk2 = cumulative(&walk);
        let phase: Vec<f64> = white.windows(2).map(|w| w[1] - w[0]).collect();
        for (name, series) in [
            ("white", &white),
            ("walk", &walk),
            ("walk2", &walk2),
            ("phase", &phase),
        ] {
            let got = identify(series).unwrap();
            let (d, delta) = identify_reference(series);
            assert_eq!(got.differences, d, "{name}");
            assert!(
                (got.delta - delta).abs() < 1e-9,
                "{name}: {} against {delta}",
                got.delta
            );
        }
        // The control: without the line removed a trend is a different series.
        let trend: Vec<f64> = white
            .iter()
            .enumerate()
            .map(|(i, w)| w + 0.01 * i as f64)
            .collect();
        let r_plain = lag1_autocorrelation(&trend);
        assert!((identify(&trend).unwrap().delta - r_plain / (1.0 + r_plain)).abs() > 0.1);
    }

    #[test]
    fn tells_white_from_random_walk_and_white_phase() {
        let mut s = Stream::new(7, 0);
        let white: Vec<f64> = (0..4000).map(|_| s.normal()).collect();
        let walk = cumulative(&white);
        let phase: Vec<f64> = white.windows(2).map(|w| w[1] - w[0]).collect();
        assert_eq!(identify(&white).unwrap().alpha, 0);
        assert_eq!(identify(&walk).unwrap().alpha, -2);
        assert_eq!(identify(&phase).unwrap().alpha, 2);
        assert!(identify(&white[..29]).is_none());
    }

    #[test]
    fn a_rise_is_pooled_and_a_fall_kept() {
        assert_eq!(
            non_increasing(&[2.0, 0.0, -1.0], &[1.0; 3]),
            [2.0, 0.0, -1.0]
        );
        // 0 then a chance 1 with a third of the weight: both become 0.25.
        assert_eq!(
            non_increasing(&[0.0, 1.0, -2.0], &[3.0, 1.0, 1.0]),
            [0.25, 0.25, -2.0]
        );
        // A late rise pools back over every run it breaks: (0 − 1 + 0 + 2)/4.
        let v = non_increasing(&[0.0, -1.0, 0.0, 2.0], &[1.0; 4]);
        assert_eq!(v, [0.25; 4]);
    }
}
