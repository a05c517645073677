//! [`noise_id::identify`](super::noise_id::identify) on block means that arrive one at a time,
//! in memory independent of their number.
//!
//! # Formula
//! Riley & Greenhall (2004), eq. (2), r₁ = Σ_{i<L−1} a_i a_{i+1} / Σ a_i² with a_i = w_i − w̄,
//! is taken from sums a stream can keep, by the identity
//! 2 Σ_{i<L−1} a_i a_{i+1} = 2 Σ a_i² − a_0² − a_{L−1}² − Σ (a_{i+1} − a_i)²:
//! the centred sum of squares by Welford's update (Welford 1962; Knuth, TAOCP vol. 2,
//! § 4.2.2), the first and last values and the sum of squared differences. The three series
//! identified are those of the batch form: the means less their least-squares line (the line's
//! co-moment Σ (i − ī)(u_i − ū) by the same update), their first differences and their second
//! differences (the line's slope is a constant there, which the mean removes). The lag-1 sums
//! differ from the batch form's by rounding only (≈ 10⁻¹³ of r₁ for 10⁷ means): α, rounded to an
//! integer, is the batch form's except where −2δ falls within that of a half-integer.

use super::noise_id::{MAX_DIFFERENCES, MIN_POINTS, NoiseId};

/// Running mean and centred sum of squares of one series, with its first and last values and
/// the sum of its squared first differences.
#[derive(Clone, Copy, Debug, Default)]
struct Lag1Sums {
    count: u64,
    mean: f64,
    /// Σ (w_i − w̄)².
    centred_squares: f64,
    first: f64,
    last: f64,
    /// Σ (w_{i+1} − w_i)².
    step_squares: f64,
}

impl Lag1Sums {
    fn push(&mut self, w: f64) {
        if self.count == 0 {
            self.first = w;
        } else {
            let step = w - self.last;
            self.step_squares += step * step;
        }
        self.count += 1;
        let before = w - self.mean;
        self.mean += before / self.count as f64;
        self.centred_squares += before * (w - self.mean);
        self.last = w;
    }

    /// r₁ of the series, by the identity of the module's formula.
    fn lag1(&self) -> f64 {
        let (a0, a_last) = (self.first - self.mean, self.last - self.mean);
        let num =
            0.5 * (2.0 * self.centred_squares - a0 * a0 - a_last * a_last - self.step_squares);
        num / self.centred_squares
    }
}

/// The sums [`StreamingNoiseId::identify`] needs, for one τ's block means.
#[derive(Clone, Copy, Debug, Default)]
pub struct StreamingNoiseId {
    /// The means themselves (their mean, centred squares, ends and squared steps).
    means: Lag1Sums,
    /// Σ (i − ī)(u_i − ū), Welford's co-moment with the index.
    index_comoment: f64,
    /// The first and second differences.
    first_differences: Lag1Sums,
    second_differences: Lag1Sums,
    /// The last two means, for the differences.
    previous: [f64; 2],
}

impl StreamingNoiseId {
    /// Counts the next block mean.
    pub fn push(&mut self, u: f64) {
        let n = self.means.count;
        // Welford's co-moment: C_n = C_{n−1} + (i − ī_{n−1})(u − ū_n), with i = n.
        let index_mean_before = if n == 0 { 0.0 } else { (n - 1) as f64 / 2.0 };
        self.means.push(u);
        self.index_comoment += (n as f64 - index_mean_before) * (u - self.means.mean);
        if n >= 1 {
            let d1 = u - self.previous[1];
            self.first_differences.push(d1);
            if n >= 2 {
                let d1_before = self.previous[1] - self.previous[0];
                self.second_differences.push(d1 - d1_before);
            }
        }
        self.previous = [self.previous[1], u];
    }

    /// r₁ of the means less their least-squares line.
    fn lag1_without_line(&self) -> f64 {
        let m = &self.means;
        let l = m.count as f64;
        let index_mean = (l - 1.0) / 2.0;
        // Σ (i − ī)² = L (L² − 1) / 12.
        let index_squares = l * (l * l - 1.0) / 12.0;
        let slope = if index_squares > 0.0 {
            self.index_comoment / index_squares
        } else {
            0.0
        };
        let centred_squares = m.centred_squares - slope * self.index_comoment;
        let z0 = m.first - m.mean + slope * index_mean;
        let z_last = m.last - m.mean - slope * (l - 1.0 - index_mean);
        // Σ (Δz)² = Σ (Δu − b)² = Σ (Δu)² − 2b (u_{L−1} − u_0) + (L − 1) b².
        let step_squares =
            m.step_squares - 2.0 * slope * (m.last - m.first) + (l - 1.0) * slope * slope;
        let num = 0.5 * (2.0 * centred_squares - z0 * z0 - z_last * z_last - step_squares);
        num / centred_squares
    }

    /// Block means counted.
    pub fn count(&self) -> u64 {
        self.means.count
    }

    /// The noise of the means counted, as [`super::noise_id::identify`] tells it from the whole
    /// series; `None` with fewer than [`MIN_POINTS`] or a series without variation.
    pub fn identify(&self) -> Option<NoiseId> {
        if self.means.count < MIN_POINTS as u64 {
            return None;
        }
        let mut d = 0u32;
        loop {
            let r1 = match d {
                0 => self.lag1_without_line(),
                1 => self.first_differences.lag1(),
                _ => self.second_differences.lag1(),
            };
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::noise_id::identify;
    use crate::random::Stream;

    fn streamed(u: &[f64]) -> Option<NoiseId> {
        let mut s = StreamingNoiseId::default();
        u.iter().for_each(|&v| s.push(v));
        s.identify()
    }

    /// White, random-walk and white-phase series, each with a line added: the same α, d and δ
    /// to 10⁻⁹ as the batch form; a constant series and too few means give none, as there.
    #[test]
    fn agrees_with_the_batch_identification() {
        let mut s = Stream::new(11, 0);
        let white: Vec<f64> = (0..5000)
            .map(|i| s.normal() + 1e-3 * i as f64 + 9.8)
            .collect();
        let mut acc = 0.0;
        let walk: Vec<f64> = white
            .iter()
            .map(|w| {
                acc += w - 9.8;
                acc
            })
            .collect();
        let phase: Vec<f64> = white.windows(2).map(|w| w[1] - w[0]).collect();
        let mut alphas = Vec::new();
        for u in [&white, &walk, &phase, &white[..40].to_vec()] {
            let (a, b) = (identify(u).unwrap(), streamed(u).unwrap());
            assert_eq!((a.alpha, a.differences), (b.alpha, b.differences));
            assert!((a.delta - b.delta).abs() < 1e-9, "{a:?} vs {b:?}");
            alphas.push(b.alpha);
        }
        // The negative control: the three noises are told apart.
        assert_eq!(&alphas[..3], &[0, -2, 2]);
        assert!(streamed(&white[..29]).is_none());
        assert!(streamed(&[1.0; 100]).is_none());
    }
}
