//! The measurement sources beside GNSS that the three-axis ensemble and `calibrate --imu` both
//! run: [`sources`] is the one list a new measurement joins (a source reads the IMU source at
//! hand through [`Context`]: the truth, when the drive is simulated).
//!
//! The driver's list holds GNSS first ([`GNSS`]); the ensemble's sums and `calibrate --imu`'s
//! records are of GNSS fixes, so their observers let another source's update change the filter
//! and judge it through the fixes that follow. `calibrate --imu`'s smoother carries such an
//! update inside the transition between two fixes (not yet as a record of its own).

use super::driver::{Context, Source};
use super::nhc::{Nhc, NhcSource};

/// The GNSS source's place in the driver's list.
pub const GNSS: usize = 0;

/// The aids a run has beside GNSS (none for a free body).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Aids {
    /// A car's non-holonomic constraint.
    pub nhc: Option<Nhc>,
}

/// The sources beside GNSS between `from_s` and `to_s`: the aids asked for.
#[allow(unused_variables, clippy::vec_init_then_push)]
pub fn sources<const N: usize, C: Context + ?Sized>(
    from_s: f64,
    to_s: f64,
    aids: &Aids,
) -> Vec<Box<dyn Source<N, C>>> {
    let mut list: Vec<Box<dyn Source<N, C>>> = Vec::new();
    if let Some(nhc) = aids.nhc {
        list.push(Box::new(NhcSource::between(nhc, from_s, to_s)));
    }
    #[cfg(feature = "throwaway-measurement")]
    list.push(Box::new(super::throwaway::DownVelocity::between(
        from_s, to_s,
    )));
    list
}
