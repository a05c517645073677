//! The logs of a simulated run written as CSV files (`simulate --logs`): the accelerometer log,
//! the GPS log, and the truth. Their format and their readers are [`crate::input::csv`]'s.
//!
//! | file | columns |
//! |---|---|
//! | accelerometer | `t_s,accel_m_s2`: every output a_c(t_j) |
//! | GPS | `t_s,position_m,velocity_m_s`: every fix z_p, z_v |
//! | truth | `t_s,position_m,velocity_m_s,bias_m_s2`: p, v, b at every sample |
//!
//! [`write`](mod@write) writes them while the run goes, every number in the form that reads back
//! bit for bit.

pub mod write;

/// Columns of the truth of a simulated run.
pub const TRUTH_COLUMNS: [&str; 4] = ["t_s", "position_m", "velocity_m_s", "bias_m_s2"];

/// File name of the accelerometer log that `simulate --logs` writes.
pub const ACCEL_FILE: &str = "accelerometer.csv";
/// File name of the GPS log that `simulate --logs` writes.
pub const GPS_FILE: &str = "gps.csv";
/// File name of the truth that `simulate --logs` writes.
pub const TRUTH_FILE: &str = "truth.csv";
