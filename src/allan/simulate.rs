//! Synthetic static logs with known noise terms: white rate noise (velocity random walk N) plus
//! a random walk of the bias (acceleration random walk K) on a constant offset.

use crate::random::Stream;

/// Key of the random streams of synthetic static logs (one stream per seed).
const STREAM_KEY: u64 = 0x616c_6c61_6e00_0001;

/// The terms of a synthetic static log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticLog {
    /// τ₀, s.
    pub sample_period_s: f64,
    /// N, m/s/√s: each sample carries white noise of variance N²/τ₀.
    pub velocity_random_walk_m_s_per_sqrt_s: f64,
    /// K, m/s²/√s: the bias steps by N(0, K²τ₀) between samples.
    pub acceleration_random_walk_m_s2_per_sqrt_s: f64,
    /// The constant part of every sample (gravity on a level axis), m/s².
    pub offset_m_s2: f64,
}

impl StaticLog {
    /// `samples` rate samples, m/s², from the random stream of `seed`.
    ///
    /// # Formula
    /// y_i = offset + b_i + (N/√τ₀)·ξ_i, b_0 = 0, b_{i+1} = b_i + K√τ₀·η_i, ξ, η standard normal.
    pub fn samples(&self, samples: usize, seed: u64) -> Vec<f64> {
        let mut s = Stream::new(STREAM_KEY, seed);
        let white = self.velocity_random_walk_m_s_per_sqrt_s / self.sample_period_s.sqrt();
        let step = self.acceleration_random_walk_m_s2_per_sqrt_s * self.sample_period_s.sqrt();
        let mut bias = 0.0;
        (0..samples)
            .map(|_| {
                let y = self.offset_m_s2 + bias + white * s.normal();
                bias += step * s.normal();
                y
            })
            .collect()
    }
}
