//! What an ensemble holds in memory, by its error state's size.

use super::{CHUNK, MEASURED, layout};
use crate::ensemble::normalized::NormalizedFix;
use crate::ins::setup::Scenario;

/// The memory an ensemble of `scenario` holds, bytes: a chunk of realizations' normalized fixes,
/// and twice the sums per fix and the residual products (a block's and the total).
pub fn memory_bytes(scenario: &Scenario) -> f64 {
    crate::with_layout!(scenario.layout(), N => memory_bytes_of::<N>(scenario))
}

/// [`memory_bytes`] for an error state of `N`.
fn memory_bytes_of<const N: usize>(scenario: &Scenario) -> f64 {
    let fixes =
        (scenario.duration_s * scenario.imu_rate_hz / scenario.imu_steps_per_fix as f64).floor();
    let record = std::mem::size_of::<NormalizedFix<N, MEASURED>>() as f64;
    let per_fix =
        std::mem::size_of::<crate::ensemble::FixSums<N>>() as f64 + 2.0 * (N * N * 8) as f64;
    let products = layout(fixes as usize, scenario.residual_max_lag).len() as f64 * 8.0;
    CHUNK as f64 * fixes * record + 2.0 * (fixes * per_fix + products)
}
