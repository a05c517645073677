//! The CSV text of every log, and the one-axis logs read with it.
//!
//! A log is UTF-8 text: a header row naming the columns, then one row per sample, fields
//! separated by commas — comma-separated values as RFC 4180 describes them, without quoted
//! fields (every field is a number); the columns are this project's, named with their units
//! (`docs/guide/logs.md`: the rules, the table below and the three-axis logs). The header must
//! hold each required column once; other columns are ignored.
//!
//! | file | columns |
//! |---|---|
//! | accelerometer | `t_s,accel_m_s2`: every output a_c(t_j) |
//! | GPS | `t_s,position_m,velocity_m_s`: every fix z_p, z_v |
//!
//! [`read`] streams a log row by row and refuses bad input with a [`LogError`](super::LogError)
//! naming the file, the line and what was expected; [`block`] is its fast core; [`steps`] finds
//! the median time step of a log in bounded memory; [`text`] writes every number so that it
//! reads back bit for bit; [`arrays`] holds an accelerometer log as two arrays; [`static_log`]
//! reads a static log's column whole (`allan --accel`); [`piped`] keeps a log that can be read
//! only once (a pipe) so that it can be read again.

pub mod arrays;
pub mod block;
pub mod piped;
pub mod read;
pub mod static_log;
pub mod steps;
pub mod text;

/// Columns of the accelerometer log.
pub const ACCEL_COLUMNS: [&str; 2] = ["t_s", "accel_m_s2"];
/// Columns of the GPS log.
pub const GPS_COLUMNS: [&str; 3] = ["t_s", "position_m", "velocity_m_s"];
/// One row of an accelerometer log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelSample {
    /// Line in the file.
    pub line: u64,
    /// Time stamp t_j, s.
    pub t_s: f64,
    /// Output a_c(t_j), m/s².
    pub accel_m_s2: f64,
}

/// One row of a GPS log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsFix {
    /// Line in the file.
    pub line: u64,
    /// Time of the fix t_i, s.
    pub t_s: f64,
    /// Measured position z_p, m.
    pub position_m: f64,
    /// Measured velocity z_v, m/s.
    pub velocity_m_s: f64,
}
