//! `--estimate-noise`: the drive reduced for the likelihood, the estimate, and its record in
//! `summary.json`.

use serde::ser::{Serialize, SerializeMap, Serializer};

use crate::likelihood::{self, Drive, Interval, Key, NoiseEstimate, Request};
use crate::state::{BiasModel, ErrorState, NoiseStats};

use super::chunked::Chunked;
use super::forward::FilteredFix;
use super::pass::FixAt;

/// The statistics `request` searches, made ready for the pass: a K searched with a filter whose
/// bias is constant turns its bias into a random walk (the pass then keeps the random walk's
/// unit noise; K itself is set from the drive's duration once it is known).
pub fn prepare_stats(stats: &NoiseStats, request: &Request) -> NoiseStats {
    let mut s = *stats;
    if request.keys.contains(&Key::BiasRandomWalk) && s.bias_model == BiasModel::Constant {
        s.bias_model = BiasModel::RandomWalk {
            k_m_s2_per_sqrt_s: 0.0,
        };
    }
    s
}

/// The starting K of a search when none was configured: the centre of its box,
/// √(σ_b²/duration) (see [`likelihood::search_bounds`]).
pub fn start_stats(stats: &NoiseStats, duration_s: f64) -> NoiseStats {
    let mut s = *stats;
    if let BiasModel::RandomWalk { k_m_s2_per_sqrt_s } = s.bias_model
        && k_m_s2_per_sqrt_s <= 0.0
    {
        let (lo, hi) = likelihood::search_bounds(Key::BiasRandomWalk, &s, duration_s);
        Key::BiasRandomWalk.set(&mut s, (lo * hi).sqrt());
    }
    s
}

/// The drive as the likelihood sees it: per fix, the filter's Φ from the previous fix, the
/// interval's unit noise from the pass, and the measured δz = z − (p_c, v_c).
pub fn drive(
    filtered: &[FilteredFix],
    reduced: &Chunked<FixAt>,
    prior_from_first_fix: bool,
) -> Drive {
    let rows = likelihood::evaluate::rows;
    let intervals = filtered
        .iter()
        .zip(reduced.iter())
        .map(|(f, r)| {
            let dz = f.z - f.integrated;
            Interval {
                phi: rows(&f.phi_from_previous),
                white: r.units.white(),
                bias: rows(&r.units.bias()),
                dz: [dz[ErrorState::GPS_POSITION], dz[ErrorState::GPS_VELOCITY]],
            }
        })
        .collect();
    Drive {
        intervals,
        prior_from_first_fix,
    }
}

/// The filter's Gaussian log-likelihood of its own innovations, −½ Σᵢ (ln det(2π Sᵢ) + NISᵢ).
pub fn log_likelihood(fixes: &[FilteredFix]) -> f64 {
    let ln_2pi = (2.0 * std::f64::consts::PI).ln();
    -0.5 * fixes
        .iter()
        .map(|f| ErrorState::MEAS as f64 * ln_2pi + f.s.determinant().ln() + f.nis)
        .sum::<f64>()
}

/// `summary.json`'s `noise_estimate`: `method`, `log_likelihood`, `evaluations`, `confidence`,
/// then one object per statistic searched, named by its `[filter]` key:
/// `{value, lower, upper, identifiable, search_bounds}`.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseRecord(pub NoiseEstimate);

impl Serialize for NoiseRecord {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let e = &self.0;
        let mut map = serializer.serialize_map(Some(4 + e.keys.len()))?;
        map.serialize_entry("method", "maximum_likelihood")?;
        map.serialize_entry("log_likelihood", &e.log_likelihood)?;
        map.serialize_entry("evaluations", &e.evaluations)?;
        map.serialize_entry("confidence", &e.confidence)?;
        for k in &e.keys {
            map.serialize_entry(k.key.name(), k)?;
        }
        map.end()
    }
}

/// The estimate of `request`'s statistics from the filtered drive; `None` when the likelihood
/// is not finite at the configured statistics.
pub fn estimate(
    filtered: &[FilteredFix],
    reduced: &Chunked<FixAt>,
    stats: &NoiseStats,
    (request, prior_from_first_fix, duration_s): (&Request, bool, f64),
) -> Option<NoiseEstimate> {
    let drive = drive(filtered, reduced, prior_from_first_fix);
    likelihood::estimate(&drive, stats, request, duration_s)
}
