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

/// Key of the random streams of the features beyond [`StaticLog`] (one stream per seed).
const FEATURE_KEY: u64 = 0x616c_6c61_6e00_0002;

/// Correlation times of the flicker generator's Gauss–Markov processes: two per decade from
/// 10⁻² s to 10⁵ s.
const FLICKER_DECADES: (i32, i32) = (-2, 5);

/// A synthetic static log with the features the Allan model lacks or barely has: flicker noise
/// (bias instability B), a sinusoid and a linear trend of the bias, on top of a [`StaticLog`]
/// (whose samples they add to, unchanged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureLog {
    /// White noise, random walk and offset.
    pub base: StaticLog,
    /// B, m/s²: flicker noise whose Allan deviation is flat at √(2 ln 2/π)·B ≈ 0.664·B.
    pub bias_instability_m_s2: f64,
    /// Amplitude A of a sinusoid, m/s².
    pub sinusoid_amplitude_m_s2: f64,
    /// Its frequency f₀, Hz.
    pub sinusoid_frequency_hz: f64,
    /// R, m/s³: the bias grows by R per second (σ² = R²τ²/2).
    pub rate_ramp_m_s3: f64,
}

impl FeatureLog {
    /// `samples` rate samples, m/s², of seed `seed`: the base log's samples plus the features
    /// from a second stream.
    ///
    /// # Formula
    /// Flicker as a sum of first-order Gauss–Markov processes with correlation times T_k spaced
    /// Δ = ½ decade (Keshner, "1/f noise", Proc. IEEE 70 (1982); each a Lorentzian 4σ²T/(1 +
    /// (2πfT)²)): the one-sided PSD is σ²/(Δ ln 10 · f) between 1/(2πT_max) and 1/(2πT_min), so
    /// σ_k² = B²·Δ·ln 10/π gives h₋₁ = B²/π and σ²(τ) = 2 ln 2·h₋₁ = (2 ln 2/π)B² (IEEE Std 952,
    /// annex C). Each process: x_{i+1} = φx_i + σ_k√(1 − φ²)·ξ, φ = e^{−τ₀/T_k}, x₀ ~ N(0, σ_k²).
    /// The sinusoid A·sin(2πf₀t + φ₀) with φ₀ uniform; the trend R·t.
    pub fn samples(&self, samples: usize, seed: u64) -> Vec<f64> {
        let mut y = self.base.samples(samples, seed);
        let mut s = Stream::new(FEATURE_KEY, seed);
        let tau0 = self.base.sample_period_s;
        let spacing = 0.5;
        let var_k = self.bias_instability_m_s2.powi(2) * spacing * std::f64::consts::LN_10
            / std::f64::consts::PI;
        if var_k > 0.0 {
            let (lo, hi) = FLICKER_DECADES;
            let mut gm: Vec<(f64, f64, f64)> = (2 * lo..=2 * hi)
                .map(|k| {
                    let phi = (-tau0 / 10f64.powf(k as f64 * spacing)).exp();
                    (
                        phi,
                        (var_k * (1.0 - phi * phi)).sqrt(),
                        var_k.sqrt() * s.normal(),
                    )
                })
                .collect();
            for v in y.iter_mut() {
                for (phi, drive, x) in gm.iter_mut() {
                    *v += *x;
                    *x = *phi * *x + *drive * s.normal();
                }
            }
        }
        let phase = 2.0 * std::f64::consts::PI * (s.next_u64() as f64 / u64::MAX as f64);
        let omega = 2.0 * std::f64::consts::PI * self.sinusoid_frequency_hz;
        for (i, v) in y.iter_mut().enumerate() {
            let t = i as f64 * tau0;
            *v +=
                self.sinusoid_amplitude_m_s2 * (omega * t + phase).sin() + self.rate_ramp_m_s3 * t;
        }
        y
    }
}

/// Key of the random streams of the Gauss–Markov bias (one stream per seed).
const GAUSS_MARKOV_KEY: u64 = 0x616c_6c61_6e00_0003;

/// A synthetic static log whose bias is a first-order Gauss–Markov process, on top of a
/// [`StaticLog`] (whose samples it adds to, unchanged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussMarkovLog {
    /// White noise, random walk and offset.
    pub base: StaticLog,
    /// σ, the process's stationary standard deviation (unit of the samples).
    pub sigma: f64,
    /// T_c, its correlation time, s.
    pub correlation_time_s: f64,
}

impl GaussMarkovLog {
    /// `samples` rate samples of seed `seed`: the base log's samples plus the process from a
    /// second stream.
    ///
    /// # Formula
    /// The exact discretization of ḃ = −b/T_c + w (an AR(1) sequence; Gelb, *Applied Optimal
    /// Estimation*, 1974, §3.8; Maybeck, *Stochastic Models, Estimation and Control* 1, 1979,
    /// §4.9): b_{i+1} = φb_i + σ√(1 − φ²)·ξ_i, φ = e^{−τ₀/T_c}, b₀ ~ N(0, σ²) (stationary from the
    /// first sample).
    pub fn samples(&self, samples: usize, seed: u64) -> Vec<f64> {
        let mut y = self.base.samples(samples, seed);
        let mut s = Stream::new(GAUSS_MARKOV_KEY, seed);
        let phi = (-self.base.sample_period_s / self.correlation_time_s).exp();
        let drive = self.sigma * (1.0 - phi * phi).sqrt();
        let mut b = self.sigma * s.normal();
        for v in y.iter_mut() {
            *v += b;
            b = phi * b + drive * s.normal();
        }
        y
    }
}
