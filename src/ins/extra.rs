//! The measurement sources beside GNSS that the three-axis ensemble and `calibrate --imu` both
//! run: [`sources`] is the one list a new measurement joins (a source reads the IMU source at
//! hand through [`Context`]: the truth, when the drive is simulated).
//!
//! The driver's list holds GNSS first ([`GNSS`]); the ensemble's sums and `calibrate --imu`'s
//! records are of GNSS fixes, so their observers let another source's update change the filter
//! and judge it through the fixes that follow. `calibrate --imu`'s smoother carries such an
//! update inside the transition between two fixes (not yet as a record of its own).

use super::driver::{Context, Source};

/// The GNSS source's place in the driver's list.
pub const GNSS: usize = 0;

/// The sources beside GNSS between `from_s` and `to_s` (none in a default build).
#[allow(unused_variables, clippy::vec_init_then_push)]
pub fn sources<const N: usize, C: Context + ?Sized>(
    from_s: f64,
    to_s: f64,
) -> Vec<Box<dyn Source<N, C>>> {
    #[allow(unused_mut)]
    let mut list: Vec<Box<dyn Source<N, C>>> = Vec::new();
    #[cfg(feature = "throwaway-measurement")]
    list.push(Box::new(super::throwaway::DownVelocity::between(
        from_s, to_s,
    )));
    list
}
