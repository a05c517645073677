//! Noise statistics from a drive: the maximum of the GPS innovations' Gaussian log-likelihood
//! over named `[filter]` statistics, with profile-likelihood intervals.
//!
//! The innovations of a correctly tuned filter are white with covariance S, so the statistics
//! that maximise ℓ(θ) = −½ Σᵢ (ln det(2π Sᵢ) + rᵢᵀ Sᵢ⁻¹ rᵢ) are those the drive supports. The
//! drive enters only through one [`Interval`] per fix, reduced from the log once; each
//! evaluation of ℓ runs the filter's recursion over them (O(fixes)).
//!
//! The search runs over the statistics' logarithms, within a box around the configured values
//! (×10^±3 for a σ or K, ×10^±6 for the variance W). An interval end that reaches the box is
//! open: the data bound the statistic there no more than the search does, and the statistic is
//! reported as not identifiable.

pub mod evaluate;
pub mod profile;
mod search;

use rayon::prelude::*;
use serde::Serialize;

pub use evaluate::{Drive, Interval};
pub use profile::ProfilePoint;
use search::Objective;

use crate::config::statistics::{Kind, Scales};
use crate::config::{STATISTICS, Statistic};
use crate::state::NoiseStats;
use crate::stats::{Tail, chi_squared_quantile};

/// A statistic the search can estimate: a searchable row of [`STATISTICS`] (a variance, σ or K
/// of the process or measurement noise), named by its `[filter]` key.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Key(pub &'static Statistic);

/// The number of searchable statistics.
const SEARCHABLE: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < STATISTICS.len() {
        n += STATISTICS[i].searchable() as usize;
        i += 1;
    }
    n
};

#[allow(non_upper_case_globals)]
impl Key {
    /// Every key, in the order of `summary.json`: the measurement noise's, then the process
    /// noise's, each in the table's order.
    pub const ALL: [Key; SEARCHABLE] = {
        let mut all = [Key(&STATISTICS[0]); SEARCHABLE];
        let mut n = 0;
        let mut pass = 0;
        while pass < 2 {
            let mut i = 0;
            while i < STATISTICS.len() {
                let s = &STATISTICS[i];
                let measured = matches!(s.scales, Scales::MeasurementNoise);
                if s.searchable() && measured == (pass == 0) {
                    all[n] = Key(s);
                    n += 1;
                }
                i += 1;
            }
            pass += 1;
        }
        all
    };

    /// `gps_position_sigma_m`, σ_p.
    pub const GpsPosition: Key = Key(&Statistic::GPS_POSITION_SIGMA);
    /// `gps_velocity_sigma_m_s`, σ_v.
    pub const GpsVelocity: Key = Key(&Statistic::GPS_VELOCITY_SIGMA);
    /// `accel_noise_var_m2_s4`, W.
    pub const AccelNoiseVar: Key = Key(&Statistic::ACCEL_NOISE_VAR);
    /// `bias_random_walk_m_s2_per_sqrt_s`, K.
    pub const BiasRandomWalk: Key = Key(&Statistic::BIAS_RANDOM_WALK);

    /// The `[filter]` key.
    pub fn name(self) -> &'static str {
        self.0.key()
    }

    /// The symbol in the report's notation.
    pub fn symbol(self) -> &'static str {
        self.0.symbol
    }

    /// The SI unit.
    pub fn unit(self) -> &'static str {
        self.0.unit
    }

    /// The key of a `[filter]` name.
    pub fn parse(name: &str) -> Option<Key> {
        Key::ALL.into_iter().find(|k| k.name() == name.trim())
    }

    /// The search's half-width in decades around the configured value (by the statistic's
    /// kind): 3 for a σ or K, 6 for a variance (3 decades of its σ).
    pub fn decades(self) -> f64 {
        self.0.kind.decades()
    }

    /// The statistic's value in `stats` (K: 0 unless the bias is a random walk).
    pub fn get(self, stats: &NoiseStats) -> f64 {
        self.0.stats_value(stats).unwrap_or(0.0)
    }

    /// `stats` with the statistic set to `value` (K makes the bias a random walk).
    pub fn set(self, stats: &mut NoiseStats, value: f64) {
        (self.0.set_stats)(stats, value);
    }

    /// The keys estimated when none are named: the measurement noise's σ's (the two GPS σ's),
    /// and the parameter of the filter's bias model when it is searchable (K of a random walk).
    pub fn defaults(stats: &NoiseStats) -> Vec<Key> {
        Key::ALL
            .into_iter()
            .filter(|k| matches!(k.0.scales, Scales::MeasurementNoise) || k.0.bias_model.is_some())
            .filter(|k| k.0.stats_value(stats).is_some())
            .collect()
    }

    /// The position in [`Key::ALL`].
    fn rank(self) -> usize {
        Key::ALL
            .iter()
            .position(|k| *k == self)
            .unwrap_or(usize::MAX)
    }
}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    /// In [`Key::ALL`]'s order.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.rank().cmp(&other.rank())
    }
}

/// What to estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// The statistics searched, each once, in [`Key::ALL`]'s order.
    pub keys: Vec<Key>,
    /// The intervals' confidence, in (0, 1).
    pub confidence: f64,
}

/// A search that cannot be asked of the filter's model.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RequestError {
    /// K named while the filter's bias is Gauss–Markov, which has no random walk.
    #[error(
        "--estimate {key}: K is the random walk's statistic, and the filter's bias model is \
         gauss_markov; estimate it with bias_model = \"random_walk\" or \"constant\" in [filter]"
    )]
    RandomWalkOfGaussMarkov {
        /// The key named.
        key: &'static str,
    },
}

impl Request {
    /// The search `--estimate-noise [--estimate KEY,…]` asks for: the `named` keys in
    /// [`Key::ALL`]'s order, or [`Key::defaults`] of the filter's `stats` when none is named.
    ///
    /// # Errors
    /// [`RequestError`] when a key does not belong to the filter's bias model.
    pub fn new(named: &[Key], confidence: f64, stats: &NoiseStats) -> Result<Self, RequestError> {
        let keys: Vec<Key> = if named.is_empty() {
            Key::defaults(stats)
        } else {
            Key::ALL.into_iter().filter(|k| named.contains(k)).collect()
        };
        if keys.contains(&Key::BiasRandomWalk)
            && matches!(
                stats.bias_model,
                crate::state::BiasModel::GaussMarkov { .. }
            )
        {
            return Err(RequestError::RandomWalkOfGaussMarkov {
                key: Key::BiasRandomWalk.name(),
            });
        }
        Ok(Request { keys, confidence })
    }
}

/// The search's box for one statistic: the configured value (for K with no random walk
/// configured, √(σ_b²/duration), the drift that would move the bias by its prior σ over the
/// drive) times 10^±decades.
pub fn search_bounds(key: Key, stats: &NoiseStats, duration_s: f64) -> (f64, f64) {
    let mut center = key.get(stats);
    if key.0.kind == Kind::RandomWalk && center <= 0.0 {
        center = (stats.bias_var_m2_s4 / duration_s.max(f64::MIN_POSITIVE)).sqrt();
    }
    let f = 10f64.powf(key.decades());
    (center / f, center * f)
}

/// One statistic's estimate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyEstimate {
    /// The maximum-likelihood value, which the calibration uses (at a bound of the search when
    /// the data do not determine it: see `identifiable`).
    pub value: f64,
    /// The interval's lower end; 0 when it reached the search's lower bound (only an upper
    /// bound is known).
    pub lower: f64,
    /// The upper end; `null` when it reached the search's upper bound.
    pub upper: Option<f64>,
    /// Whether both ends lie strictly inside the search's bounds: only then does the drive
    /// measure the statistic.
    pub identifiable: bool,
    /// The search's bounds.
    pub search_bounds: [f64; 2],
    /// The likelihood profile: the statistic's values and −2·Δℓ there, in increasing order.
    #[serde(skip)]
    pub profile: Vec<(f64, f64)>,
    /// The statistic.
    #[serde(skip)]
    pub key: Key,
}

/// The maximum-likelihood estimate of the requested statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseEstimate {
    /// ℓ at the maximum.
    pub log_likelihood: f64,
    /// Evaluations of ℓ in all (search and intervals).
    pub evaluations: u64,
    /// The intervals' confidence.
    pub confidence: f64,
    /// −2·Δℓ at an interval's ends: the χ²₁ quantile at `confidence`.
    pub deviance_threshold: f64,
    /// Each statistic, in the request's order.
    pub keys: Vec<KeyEstimate>,
    /// The filter's statistics with the estimates in place.
    pub stats: NoiseStats,
}

/// Maximises the likelihood of `drive` over `request`'s statistics, the others held at their
/// values in `start` (also the search's starting point and the centre of its box), and
/// computes each statistic's profile-likelihood interval. `duration_s` sets K's box when no
/// random walk is configured.
///
/// Returns `None` when ℓ is not finite at the start (a covariance not positive definite).
pub fn estimate(
    drive: &Drive,
    start: &NoiseStats,
    request: &Request,
    duration_s: f64,
) -> Option<NoiseEstimate> {
    let keys = &request.keys;
    let bounds: Vec<(f64, f64)> = keys
        .iter()
        .map(|&k| search_bounds(k, start, duration_s))
        .collect();
    let stats_at = |u: &[f64]| {
        let mut s = *start;
        for (k, x) in keys.iter().zip(u) {
            k.set(&mut s, x.exp());
        }
        s
    };
    let f = |u: &[f64]| drive.log_likelihood(&stats_at(u));
    let lo: Vec<f64> = bounds.iter().map(|b| b.0.ln()).collect();
    let hi: Vec<f64> = bounds.iter().map(|b| b.1.ln()).collect();
    let u0: Vec<f64> = keys
        .iter()
        .zip(&bounds)
        .map(|(k, b)| match k.get(start) {
            v if v > 0.0 => v.ln(),
            _ => (b.0 * b.1).sqrt().ln(),
        })
        .collect();
    let fit = maximize(&f, (&lo, &hi), &u0, request.confidence)?;
    let estimates = keys
        .iter()
        .enumerate()
        .map(|(j, &key)| key_estimate(key, (fit.u[j], lo[j], hi[j]), &fit.ends[2 * j..2 * j + 2]))
        .collect();
    Some(NoiseEstimate {
        log_likelihood: fit.value,
        evaluations: fit.evaluations,
        confidence: request.confidence,
        deviance_threshold: fit.deviance_threshold,
        keys: estimates,
        stats: stats_at(&fit.u),
    })
}

/// The maximum of a log-likelihood and its variables' profile-likelihood intervals.
#[derive(Clone, Debug)]
pub struct Fit {
    /// Where ℓ is largest.
    pub u: Vec<f64>,
    /// ℓ there.
    pub value: f64,
    /// Each variable's interval ends, lower then upper (`End::at` is `None` where the
    /// deviance stays below the quantile up to the box).
    pub ends: Vec<profile::End>,
    /// −2·Δℓ at the ends: the χ²₁ quantile at the confidence.
    pub deviance_threshold: f64,
    /// Evaluations of ℓ in all.
    pub evaluations: u64,
}

/// The maximum of `f` over the box [lo, hi] from `u0` (Newton with finite differences, an
/// active set at the bounds), and each variable's profile-likelihood interval at `confidence`
/// (the interval ends computed in parallel). `None` when `f` is not finite at `u0`.
pub fn maximize(
    f: &(dyn Fn(&[f64]) -> f64 + Sync),
    (lo, hi): (&[f64], &[f64]),
    u0: &[f64],
    confidence: f64,
) -> Option<Fit> {
    let objective = Objective::new(f, lo.to_vec(), hi.to_vec());
    if !objective.value(u0).is_finite() {
        return None;
    }
    let free: Vec<usize> = (0..u0.len()).collect();
    let best = objective.maximize(u0, &free);
    let q = chi_squared_quantile(1.0, confidence, Tail::Lower);
    let ends: Vec<profile::End> = (0..2 * u0.len())
        .into_par_iter()
        .map(|e| {
            let side = if e % 2 == 0 { -1.0 } else { 1.0 };
            profile::interval_end(f, (lo, hi), &best, &free, (e / 2, side, q))
        })
        .collect();
    let evaluations = objective.evaluations() + ends.iter().map(|e| e.evaluations).sum::<u64>();
    Some(Fit {
        u: best.u,
        value: best.value,
        ends,
        deviance_threshold: q,
        evaluations,
    })
}

/// The maximum of `f` over the box [lo, hi] from `u0` without intervals (the search of
/// [`maximize`]): where, the value there and the evaluations it took. `None` when `f` is not
/// finite at `u0`.
pub fn climb(
    f: &(dyn Fn(&[f64]) -> f64 + Sync),
    (lo, hi): (&[f64], &[f64]),
    u0: &[f64],
) -> Option<(Vec<f64>, f64, u64)> {
    let objective = Objective::new(f, lo.to_vec(), hi.to_vec());
    if !objective.value(u0).is_finite() {
        return None;
    }
    let free: Vec<usize> = (0..u0.len()).collect();
    let best = objective.climb(u0, &free);
    Some((best.u, best.value, objective.evaluations()))
}

/// One statistic's estimate from its maximum `u` (a logarithm) within [lo, hi] and its two
/// interval ends.
fn key_estimate(key: Key, (u, lo, hi): (f64, f64, f64), ends: &[profile::End]) -> KeyEstimate {
    let (lower, upper) = (ends[0].at, ends[1].at);
    let inside = |x: Option<f64>| x.is_some_and(|x| x > lo && x < hi);
    let mut profile: Vec<(f64, f64)> = ends
        .iter()
        .flat_map(|e| e.points.iter().map(|p| (p.u.exp(), p.deviance)))
        .chain([(u.exp(), 0.0)])
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    KeyEstimate {
        value: u.exp(),
        lower: lower.filter(|&x| x > lo).map_or(0.0, f64::exp),
        upper: upper.filter(|&x| x < hi).map(f64::exp),
        identifiable: inside(lower) && inside(upper),
        search_bounds: [lo.exp(), hi.exp()],
        profile,
        key,
    }
}
