//! The bias's path: its smoothed range in units of its σ, and how far each filtered estimate
//! strays from the smoothed one against what their covariances allow.

use crate::state::BiasModel;
use crate::stats::normal_bound;

use super::{BiasDiagnostics, Series, each};

/// A fix enters the bias steadiness test when the smoother has removed at least this fraction of
/// its filtered variance: near the end of the log the difference of the two estimates and of
/// their variances is rounding.
const MIN_VARIANCE_GAIN: f64 = 1e-6;

/// d = (b̂ − b̂^s) / √(P_bb − P^s_bb) of a fix's `filtered` and `smoothed` (estimate, variance)
/// of the bias ([`BiasDiagnostics`]); none where the smoother removed less than 10⁻⁶ of the
/// filtered variance.
pub fn bias_departure(filtered: [f64; 2], smoothed: [f64; 2]) -> Option<f64> {
    let gain = filtered[1] - smoothed[1];
    (gain > MIN_VARIANCE_GAIN * filtered[1]).then(|| (filtered[0] - smoothed[0]) / gain.sqrt())
}

/// The bias's path through `series` for a filter assuming `model`, tested at α.
pub(super) fn bias<S: Series + ?Sized>(
    series: &S,
    model: BiasModel,
    alpha: f64,
) -> BiasDiagnostics {
    // A constant bias's smoothed estimate is one number, the last fix's: the others differ from
    // it by rounding alone, which is no range.
    let path: Vec<f64> = match model {
        BiasModel::Constant => (series.len().checked_sub(1))
            .map(|last| series.at(last).bias_smoothed[0])
            .into_iter()
            .collect(),
        _ => each(series).map(|f| f.bias_smoothed[0]).collect(),
    };
    let lo = path.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = path.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut sigmas: Vec<f64> = each(series).map(|f| f.bias_smoothed[1].sqrt()).collect();
    sigmas.sort_by(f64::total_cmp);
    let median_sigma = sigmas.get(sigmas.len() / 2).copied().unwrap_or(f64::NAN);
    let departures: Vec<(f64, f64)> = each(series)
        .filter_map(|f| Some((f.t_s, bias_departure(f.bias_filtered, f.bias_smoothed)?)))
        .collect();
    let (t_s, worst) = departures
        .iter()
        .fold((f64::NAN, 0.0f64), |(t, m), &(ti, d)| {
            if d.abs() > m { (ti, d.abs()) } else { (t, m) }
        });
    let n_d = departures.len();
    let bound = normal_bound(alpha / n_d.max(1) as f64);
    let range = if series.is_empty() { 0.0 } else { hi - lo };
    BiasDiagnostics {
        bias_model: model.name(),
        smoothed_min_m_s2: if series.is_empty() { 0.0 } else { lo },
        smoothed_max_m_s2: if series.is_empty() { 0.0 } else { hi },
        smoothed_range_sigmas: if median_sigma > 0.0 {
            range / median_sigma
        } else {
            0.0
        },
        departure_max_sigmas: worst,
        departure_t_s: if n_d == 0 { 0.0 } else { t_s },
        departure_fixes: n_d,
        departure_bound_sigmas: bound,
        verdict: match n_d {
            0 => "untestable",
            _ if worst > bound => "fail",
            _ => "pass",
        },
    }
}
