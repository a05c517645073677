//! Three estimates in body axes (a sensor triad's biases or scale factors) with their σ's and
//! intervals, and whether the drive determined each: the rows `summary.json` and the scale
//! factors' warnings share.

use serde::Serialize;

/// The confidence of the intervals.
pub const CONFIDENCE: f64 = 0.95;

/// A quantity is determined by the drive when its σ at the end is at most this fraction of the
/// σ it would have from its prior and its process noise alone: the data then carry at least
/// three times the prior's information about it.
pub const IDENTIFIABLE_SIGMA_RATIO: f64 = 0.5;

/// Three estimates in body axes (x, y, z) with their σ's and intervals.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Triad {
    /// The estimates.
    pub value: [f64; 3],
    /// Their σ's.
    pub sigma: [f64; 3],
    /// The intervals' lower ends (`CONFIDENCE`).
    pub lower: [f64; 3],
    /// Their upper ends.
    pub upper: [f64; 3],
    /// Whether the drive determined each ([`IDENTIFIABLE_SIGMA_RATIO`]).
    pub identifiable: [bool; 3],
}

/// The triad of `value` with σ's `sigma`, its intervals at [`CONFIDENCE`] and whether each σ
/// is at most [`IDENTIFIABLE_SIGMA_RATIO`] of the σ `prior` alone would give.
pub(super) fn triad(value: [f64; 3], sigma: [f64; 3], prior: [f64; 3]) -> Triad {
    let z = crate::stats::normal_bound(1.0 - CONFIDENCE);
    Triad {
        value,
        sigma,
        lower: [0, 1, 2].map(|i| value[i] - z * sigma[i]),
        upper: [0, 1, 2].map(|i| value[i] + z * sigma[i]),
        identifiable: [0, 1, 2].map(|i| sigma[i] <= IDENTIFIABLE_SIGMA_RATIO * prior[i]),
    }
}
