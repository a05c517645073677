//! The input layer: every reader of what the sensors recorded, and the few types they hand on.
//!
//! - [`csv`]: the CSV text every log is written in (a header row naming the columns, one row per
//!   sample), its streaming reader, and the one-axis logs read with it: the accelerometer and
//!   GPS logs of `calibrate --accel --gps`, the static log of `allan --accel`;
//! - [`imu_csv`] and [`gnss_csv`]: a drive's six-axis IMU log and its GNSS fixes as CSV
//!   (`calibrate --imu --gnss`), or their columns held in memory;
//! - [`imu_channels_csv`]: a static six-axis IMU log as CSV (`allan --imu`);
//! - the containers of ROS recordings, [`mcap`] (an MCAP file), [`rosbag2`] (a ROS 2 bag
//!   directory of MCAP files) and [`rosbag1`] (a ROS 1 bag), their messages decoded by
//!   [`messages`] (`sensor_msgs/Imu`), the chosen topic read by [`recording`];
//! - [`container`]: what a log is, told by its first bytes, and where a recording's bytes are
//!   read from (a file, or a stream's copy);
//! - [`records`]: what the readers hand on, whatever the format.
//!
//! Every reader refuses bad input with a [`LogError`] naming the file, the line (or the message)
//! and what was expected; none knows what its numbers are used for. The layer imports nothing of
//! the analyses above it.

pub mod container;
pub mod csv;
pub mod gnss_csv;
pub mod imu_channels_csv;
pub mod imu_csv;
pub mod mcap;
mod mcap_chunks;
pub mod mcap_records;
mod mcap_summary;
pub mod messages;
pub mod read_ahead;
pub mod recording;
pub mod records;
pub mod rosbag1;
pub mod rosbag2;

use thiserror::Error;

/// A log that cannot be accepted: the file, the line (when one is to blame) and the problem.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{file}{}: {problem}", line_words(.line))]
pub struct LogError {
    /// The file as the user named it.
    pub file: String,
    /// The line, counting the header as line 1.
    pub line: Option<u64>,
    /// What is wrong and what was expected.
    pub problem: LogProblem,
}

fn line_words(line: &Option<u64>) -> String {
    line.map(|l| format!(", line {l}")).unwrap_or_default()
}

/// The most characters of a log's text a message quotes.
pub const MAX_ECHO_CHARS: usize = 200;

/// `text` as a message quotes it: whole up to [`MAX_ECHO_CHARS`] characters, else its first
/// ones followed by how long it is, so that a hostile header does not flood the terminal.
pub fn echo(text: &str) -> String {
    match text.char_indices().nth(MAX_ECHO_CHARS) {
        None => text.to_string(),
        Some((end, _)) => format!(
            "{}… ({} characters in all)",
            &text[..end],
            text.chars().count()
        ),
    }
}

/// What is wrong with a log, with what was expected.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LogProblem {
    /// The operating system could not open or read the file.
    #[error("cannot read the file: {message}")]
    Unreadable {
        /// The operating system's words.
        message: String,
    },
    /// A line longer than the reader accepts.
    #[error(
        "the line is longer than {} KiB: expected rows of a few comma-separated numbers (is \
         this a CSV log?)",
        .limit_bytes / 1024
    )]
    LineTooLong {
        /// The longest line accepted, bytes.
        limit_bytes: usize,
    },
    /// A line is not UTF-8 text.
    #[error("not text: expected comma-separated numbers in UTF-8")]
    NotText,
    /// The file holds nothing.
    #[error("the file is empty: expected the header `{header}` and data rows")]
    Empty {
        /// The expected header.
        header: String,
    },
    /// A required column is not in the header.
    #[error("the header has no column `{column}`: found `{found}`, expected `{header}`")]
    MissingColumn {
        /// The missing column.
        column: &'static str,
        /// The header as found.
        found: String,
        /// The expected header.
        header: String,
    },
    /// A column appears twice in the header.
    #[error("the header names the column `{column}` twice")]
    DuplicateColumn {
        /// The repeated column.
        column: String,
    },
    /// Too few data rows.
    #[error("found {found} data row(s) after the header; a log needs at least {needed}")]
    TooFewRows {
        /// Rows found.
        found: u64,
        /// Rows needed.
        needed: u64,
    },
    /// A row with another number of fields than the header.
    #[error("{found} comma-separated fields, expected {expected} as in the header `{header}`")]
    FieldCount {
        /// Fields in the header.
        expected: usize,
        /// Fields in the row.
        found: usize,
        /// The header.
        header: String,
    },
    /// A field that is not a number.
    #[error("`{column}` = `{text}` is not a number")]
    NotANumber {
        /// The column.
        column: &'static str,
        /// The field as written.
        text: String,
    },
    /// A field that is NaN or infinite.
    #[error("`{column}` = `{text}` is not a finite number")]
    NotFinite {
        /// The column.
        column: &'static str,
        /// The field as written.
        text: String,
    },
    /// A row whose values take the calibration beyond double precision.
    #[error("the calibration overflows double precision: {what}")]
    Overflow {
        /// What overflowed, and which values of the row are to blame.
        what: String,
    },
    /// A time stamp not after the one before it.
    #[error(
        "time stamp {t_s} s is not after the previous one, {previous_s} s: time stamps must be \
         strictly increasing"
    )]
    NotIncreasing {
        /// The time stamp, s.
        t_s: f64,
        /// The previous time stamp, s.
        previous_s: f64,
    },
    /// A step far from the median step: samples lost or repeated.
    #[error(
        "the step from {previous_s} s to {t_s} s is {} s, {ratio:.3} times the median step {} s: \
         accepted steps lie between {low} and {high} times the median (a longer step is a gap, a \
         shorter one an extra sample)",
        crate::format::short(*.step_s),
        crate::format::short(*.median_s),
        low = crate::input::csv::steps::ACCEPTED_STEP_RATIO.0,
        high = crate::input::csv::steps::ACCEPTED_STEP_RATIO.1
    )]
    Gap {
        /// Time stamp of the previous sample, s.
        previous_s: f64,
        /// Time stamp of this sample, s.
        t_s: f64,
        /// The step, s.
        step_s: f64,
        /// The step over the median step.
        ratio: f64,
        /// The median step, s.
        median_s: f64,
    },
    /// A GPS fix before the first or after the last accelerometer sample.
    #[error(
        "the fix at {t_s} s is outside the accelerometer log, whose samples run from {first_s} s \
         to {last_s} s: a fix must lie within half the median step ({} s) of a sample",
        crate::format::short(*.tolerance_s)
    )]
    FixOutsideSpan {
        /// Time of the fix, s.
        t_s: f64,
        /// First accelerometer time stamp, s.
        first_s: f64,
        /// Last accelerometer time stamp, s.
        last_s: f64,
        /// Half the median step, s.
        tolerance_s: f64,
    },
    /// A GPS fix that falls between two accelerometer samples.
    #[error(
        "the fix at {t_s} s falls between the accelerometer samples at {before_s} s and {after_s} \
         s: a fix must lie within half the median step ({} s) of a sample",
        crate::format::short(*.tolerance_s)
    )]
    FixBetweenSamples {
        /// Time of the fix, s.
        t_s: f64,
        /// The sample before it, s.
        before_s: f64,
        /// The sample after it, s.
        after_s: f64,
        /// Half the median step, s.
        tolerance_s: f64,
    },
    /// Two GPS fixes on one accelerometer sample.
    #[error(
        "the fix at {t_s} s falls on the accelerometer sample at {sample_s} s, which the fix on \
         line {other_line} already takes: at most one fix per sample"
    )]
    FixOnTakenSample {
        /// Time of the fix, s.
        t_s: f64,
        /// The sample, s.
        sample_s: f64,
        /// Line of the fix that took the sample.
        other_line: u64,
    },
    /// The header names columns of two layouts that exclude each other.
    #[error(
        "the header names `{first}` and `{second}`, columns of two layouts that exclude each \
         other: expected {expected}"
    )]
    ConflictingColumns {
        /// A column of the first layout.
        first: &'static str,
        /// A column of the second.
        second: &'static str,
        /// What the header may hold.
        expected: String,
    },
    /// A value outside the range its column accepts.
    #[error(
        "`{column}` = {} is outside its accepted range: expected {range}",
        crate::format::short(*.value)
    )]
    OutOfRange {
        /// The column.
        column: &'static str,
        /// The value.
        value: f64,
        /// The accepted range in words.
        range: String,
    },
    /// A second reading of the file differs from the first.
    #[error("the file changed while it was being read: its second reading differs from the first")]
    Changed,
}

impl LogError {
    /// An error of `file` at `line`.
    pub fn at(file: &str, line: u64, problem: LogProblem) -> Self {
        Self {
            file: file.to_string(),
            line: Some(line),
            problem,
        }
    }

    /// An error of `file` as a whole.
    pub fn of_file(file: &str, problem: LogProblem) -> Self {
        Self {
            file: file.to_string(),
            line: None,
            problem,
        }
    }
}

/// The error of the file (or the message) `file` that cannot be read as expected, in
/// `message`'s words.
fn unreadable(file: &str, message: String) -> LogError {
    LogError::of_file(file, LogProblem::Unreadable { message })
}
