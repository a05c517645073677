//! Static intervals found on the IMU alone: a sliding window's sample variance of all six
//! channels, each against the white noise measured in the log, tested at a stated rate.
//!
//! # Formula
//! For the window of L samples centred on sample k, T_k = Σ_c Σ_i (x_ci − x̄_c)² / σ_c², which
//! is χ²(6(L − 1)) when the IMU is still and its noise white with variances σ_c². Sample k is
//! static when T_k ≤ χ²_{1−α}(6(L − 1)): a still window is called moving at the rate α. A static
//! interval is a run of static samples at least `min_static_s` long.
//!
//! A run is kept only where the IMU can be at rest: its mean specific force within
//! [`MAX_GRAVITY_SHARE`] of gravity's magnitude and its mean angular rate under
//! [`MAX_REST_RATE_RAD_S`] (beyond any MEMS gyro's bias) — so that a log moving throughout, whose
//! quietest windows would otherwise set the noise, finds no pose.
//!
//! The σ_c² are measured in the log by iteration: first from the tenth of the windows whose
//! variances are smallest, then pooled over the windows inside the intervals found, until the
//! intervals no longer change. A channel quantized so coarsely that it is constant is held to a
//! variance of q²/12 (q its least step between samples).

use nalgebra::Vector3;

use super::{IntrinsicsError, SixAxisLog};
use crate::stats::{Tail, chi_squared_quantile};

/// A still IMU's mean specific force is within this share of gravity's magnitude (scale
/// factors of a few %, biases of a few % of g).
pub const MAX_GRAVITY_SHARE: f64 = 0.2;
/// A still IMU's mean angular rate is under this, rad/s (about 11°/s).
pub const MAX_REST_RATE_RAD_S: f64 = 0.2;

/// How the static intervals are found.
#[derive(Clone, Copy, Debug)]
pub struct DetectorSettings {
    /// The window, s.
    pub window_s: f64,
    /// The shortest static interval kept, s.
    pub min_static_s: f64,
    /// Rate at which a still window is called moving.
    pub false_alarm: f64,
}

impl Default for DetectorSettings {
    fn default() -> Self {
        Self {
            window_s: 1.0,
            min_static_s: 2.0,
            false_alarm: 1e-3,
        }
    }
}

/// One static interval: the IMU still in one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticInterval {
    /// Its first sample's index.
    pub first: usize,
    /// Its last sample's index (inclusive).
    pub last: usize,
    /// The mean specific force over it, m/s².
    pub mean_specific_force: Vector3<f64>,
    /// The mean angular rate over it, rad/s.
    pub mean_angular_rate: Vector3<f64>,
}

impl StaticInterval {
    /// Number of samples.
    pub fn samples(&self) -> usize {
        self.last + 1 - self.first
    }
}

/// The intervals found and the noise measured in them.
#[derive(Clone, Debug)]
pub struct Detection {
    /// The static intervals in time order.
    pub intervals: Vec<StaticInterval>,
    /// The white noise's variance per sample of each channel (ax, ay, az, gx, gy, gz), in
    /// (m/s²)² and (rad/s)².
    pub noise_var: [f64; 6],
    /// Degrees of freedom behind each `noise_var`.
    pub noise_dof: usize,
    /// Samples in a window.
    pub window: usize,
    /// The window statistic's threshold, χ²_{1−α}(6(L − 1)).
    pub threshold: f64,
    /// The settings.
    pub settings: DetectorSettings,
    /// The sample period τ₀, s.
    pub sample_period_s: f64,
    /// Samples in the log.
    pub samples: usize,
}

/// Prefix sums of one channel, offset by its first value to keep the squares small.
struct Prefix {
    sum: Vec<f64>,
    squares: Vec<f64>,
}

impl Prefix {
    fn new(x: impl Iterator<Item = f64>) -> Self {
        let mut sum = vec![0.0];
        let mut squares = vec![0.0];
        let mut first = None;
        for v in x {
            let d = v - *first.get_or_insert(v);
            sum.push(sum.last().unwrap() + d);
            squares.push(squares.last().unwrap() + d * d);
        }
        Self { sum, squares }
    }

    /// Σ (x − x̄)² over samples [a, b).
    fn scatter(&self, a: usize, b: usize) -> f64 {
        let n = (b - a) as f64;
        let s = self.sum[b] - self.sum[a];
        (self.squares[b] - self.squares[a] - s * s / n).max(0.0)
    }

    /// Σ x over [a, b), offset.
    fn total(&self, a: usize, b: usize) -> f64 {
        self.sum[b] - self.sum[a]
    }
}

/// The value of channel `c` (0..6) at sample `k`.
fn value(log: &SixAxisLog, c: usize, k: usize) -> f64 {
    if c < 3 {
        log.specific_force[k][c]
    } else {
        log.angular_rate[k][c - 3]
    }
}

/// The least variance channel `c` may be given: its least nonzero step's q²/12.
fn quantum_floor(log: &SixAxisLog, c: usize) -> f64 {
    let q = (1..log.len())
        .map(|k| (value(log, c, k) - value(log, c, k - 1)).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if q.is_finite() {
        q * q / 12.0
    } else {
        f64::MIN_POSITIVE
    }
}

/// Finds the static intervals of `log`.
///
/// # Errors
/// [`IntrinsicsError::TooShort`] for a log under two windows, [`IntrinsicsError::NoStaticInterval`]
/// when no interval is long enough.
pub fn detect(
    log: &SixAxisLog,
    settings: &DetectorSettings,
    gravity_m_s2: f64,
) -> Result<Detection, IntrinsicsError> {
    let tau = log.sample_period_s;
    let window = ((settings.window_s / tau).round() as usize).max(8);
    let n = log.len();
    if n < 2 * window {
        return Err(IntrinsicsError::TooShort {
            samples: n,
            window,
            window_s: settings.window_s,
        });
    }
    let prefix: Vec<Prefix> = (0..6)
        .map(|c| Prefix::new((0..n).map(|k| value(log, c, k))))
        .collect();
    let floor: Vec<f64> = (0..6).map(|c| quantum_floor(log, c)).collect();
    let dof = 6 * (window - 1);
    let threshold = chi_squared_quantile(dof as f64, settings.false_alarm, Tail::Upper);
    let min_len = ((settings.min_static_s / tau).round() as usize).max(window);

    let mut noise_var = first_guess(&prefix, &floor, n, window);
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for _ in 0..20 {
        let mut found = static_runs(&prefix, &noise_var, window, threshold, min_len, n);
        found.retain(|&(a, b)| {
            let i = interval(log, &prefix, a, b);
            let f = i.mean_specific_force.norm();
            (f - gravity_m_s2).abs() <= MAX_GRAVITY_SHARE * gravity_m_s2
                && i.mean_angular_rate.norm() < MAX_REST_RATE_RAD_S
        });
        let inside: Vec<usize> = found
            .iter()
            .flat_map(|&(a, b)| (0..(b + 1 - a) / window).map(move |i| a + i * window))
            .collect();
        let same = found == runs;
        runs = found;
        if same || inside.is_empty() {
            break;
        }
        noise_var = pooled(&prefix, &floor, &inside, window);
    }
    if runs.is_empty() {
        return Err(IntrinsicsError::NoStaticInterval {
            min_static_s: settings.min_static_s,
        });
    }
    let noise_dof = runs
        .iter()
        .map(|&(a, b)| (b + 1 - a) / window)
        .sum::<usize>()
        * (window - 1);
    let intervals = runs
        .iter()
        .map(|&(first, last)| interval(log, &prefix, first, last))
        .collect();
    Ok(Detection {
        intervals,
        noise_var,
        noise_dof,
        window,
        threshold,
        settings: *settings,
        sample_period_s: tau,
        samples: n,
    })
}

/// The interval of samples `first..=last` with its means.
fn interval(log: &SixAxisLog, prefix: &[Prefix], first: usize, last: usize) -> StaticInterval {
    let m = (last + 1 - first) as f64;
    let mean = |c: usize| value(log, c, 0) + prefix[c].total(first, last + 1) / m;
    StaticInterval {
        first,
        last,
        mean_specific_force: Vector3::new(mean(0), mean(1), mean(2)),
        mean_angular_rate: Vector3::new(mean(3), mean(4), mean(5)),
    }
}

/// The first guess of the noise: pooled over the tenth of the tiled windows whose variances,
/// all channels together, are smallest.
fn first_guess(prefix: &[Prefix], floor: &[f64], n: usize, window: usize) -> [f64; 6] {
    let mut scored: Vec<(f64, usize)> = (0..n / window)
        .map(|i| {
            let a = i * window;
            let score = (0..6)
                .map(|c| (prefix[c].scatter(a, a + window) + floor[c]).ln())
                .sum();
            (score, a)
        })
        .collect();
    scored.sort_by(|x, y| x.0.total_cmp(&y.0));
    let quiet: Vec<usize> = scored[..(scored.len() / 10).max(1)]
        .iter()
        .map(|s| s.1)
        .collect();
    pooled(prefix, floor, &quiet, window)
}

/// Each channel's variance pooled over the windows starting at `starts`, held to its floor.
fn pooled(prefix: &[Prefix], floor: &[f64], starts: &[usize], window: usize) -> [f64; 6] {
    let dof = (starts.len() * (window - 1)) as f64;
    std::array::from_fn(|c| {
        let s: f64 = starts
            .iter()
            .map(|&a| prefix[c].scatter(a, a + window))
            .sum();
        (s / dof).max(floor[c])
    })
}

/// The runs of static samples at least `min_len` long, as (first, last) inclusive.
fn static_runs(
    prefix: &[Prefix],
    noise_var: &[f64; 6],
    window: usize,
    threshold: f64,
    min_len: usize,
    n: usize,
) -> Vec<(usize, usize)> {
    let half = window / 2;
    let still = |k: usize| {
        if k < half || k + window - half > n {
            return false;
        }
        let a = k - half;
        let t: f64 = (0..6)
            .map(|c| prefix[c].scatter(a, a + window) / noise_var[c])
            .sum();
        t <= threshold
    };
    let mut runs = Vec::new();
    let mut start = None;
    for k in 0..=n {
        match (k < n && still(k), start) {
            (true, None) => start = Some(k),
            (false, Some(a)) => {
                if k - a >= min_len {
                    runs.push((a, k - 1));
                }
                start = None;
            }
            _ => {}
        }
    }
    runs
}
