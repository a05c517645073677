//! The measurement sources beside GNSS that the three-axis ensemble and `calibrate --imu` both
//! run: [`sources`] is the one list a new measurement joins, and [`Context`] what a source may
//! read of the IMU source at hand (the truth, when the drive is simulated).
//!
//! The driver's list holds GNSS first ([`GNSS`]); the ensemble's sums and `calibrate --imu`'s
//! records are of GNSS fixes, so their observers let another source's update change the filter
//! and judge it through the fixes that follow. `calibrate --imu`'s smoother carries such an
//! update inside the transition between two fixes (not yet as a record of its own).

use super::driver::Source;
use super::mech::Pva;

/// The GNSS source's place in the driver's list.
pub const GNSS: usize = 0;

/// What a measurement source may read of the IMU source it runs beside.
pub trait Context {
    /// The true navigation state at the last step, when the drive is simulated.
    fn truth(&self) -> Option<&Pva>;
}

/// The sources beside GNSS between `from_s` and `to_s` (none in a default build).
#[allow(unused_variables)]
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
