//! The records the readers hand on, whatever the format they read: no format is defined here.
//!
//! - A static IMU log's six channels ([`Channel`], each of a [`Sensor`]), held whole
//!   ([`ImuSamples`]) or read record by record from disk as often as an analysis needs
//!   ([`Record`]s through [`ImuRecords`]).
//! - A drive's IMU steps ([`ImuStep`]: an [`Increment`] each, in body axes forward-right-down)
//!   and its GNSS fixes ([`GnssRow`]: a [`Geodetic`] position on WGS-84), as a calibration reads
//!   them; the navigation layer (`ins`) takes the two as its own.

use nalgebra::Vector3;

use super::{LogError, LogProblem};

/// The two sensors of an IMU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensor {
    /// The accelerometers, m/s².
    Accelerometer,
    /// The gyros, rad/s.
    Gyroscope,
}

impl Sensor {
    /// Both, in the log's order.
    pub const ALL: [Sensor; 2] = [Sensor::Accelerometer, Sensor::Gyroscope];
}

/// The six channels of a three-axis IMU log: a closed set, each with its column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Specific force along x, m/s².
    Ax,
    /// Specific force along y, m/s².
    Ay,
    /// Specific force along z, m/s².
    Az,
    /// Angular rate about x, rad/s.
    Gx,
    /// Angular rate about y, rad/s.
    Gy,
    /// Angular rate about z, rad/s.
    Gz,
}

impl Channel {
    /// Every channel, in the order of the three-axis log's columns.
    pub const ALL: [Channel; 6] = [
        Channel::Ax,
        Channel::Ay,
        Channel::Az,
        Channel::Gx,
        Channel::Gy,
        Channel::Gz,
    ];

    /// The column of the three-axis log (`ins::simulated_logs`' imu.csv).
    pub fn column(self) -> &'static str {
        match self {
            Channel::Ax => "ax_m_s2",
            Channel::Ay => "ay_m_s2",
            Channel::Az => "az_m_s2",
            Channel::Gx => "gx_rad_s",
            Channel::Gy => "gy_rad_s",
            Channel::Gz => "gz_rad_s",
        }
    }

    /// The sensor the channel belongs to.
    pub fn sensor(self) -> Sensor {
        match self {
            Channel::Ax | Channel::Ay | Channel::Az => Sensor::Accelerometer,
            Channel::Gx | Channel::Gy | Channel::Gz => Sensor::Gyroscope,
        }
    }

    /// The axis, x, y or z.
    pub fn axis(self) -> &'static str {
        match self {
            Channel::Ax | Channel::Gx => "x",
            Channel::Ay | Channel::Gy => "y",
            Channel::Az | Channel::Gz => "z",
        }
    }
}

/// The samples of every channel a log holds, on one time base.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuSamples {
    /// Each channel present and its samples, in [`Channel::ALL`]'s order.
    pub channels: Vec<(Channel, Vec<f64>)>,
    /// The median step τ₀, s.
    pub sample_period_s: f64,
}

/// One sample of every channel present, and where it is (for messages).
#[derive(Clone, Copy, Debug)]
pub struct Record {
    /// Time stamp, s.
    pub t_s: f64,
    /// The channels' values, in the order of [`ImuRecords::channels`].
    pub values: [f64; 6],
    /// Its line in a CSV file, or its message's index in a recording.
    pub at: u64,
}

/// Consecutive records of a log, column by column: what [`ImuRecords::read_blocks`] hands on.
/// Record i of the block is `at + i` in the log (its line or its message's index).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecordBlock {
    /// Each record's time stamp, s.
    pub t_s: Vec<f64>,
    /// Each record's values, in the order of [`ImuRecords::channels`].
    pub values: Vec<[f64; 6]>,
    /// The first record's line or message index.
    pub at: u64,
}

impl RecordBlock {
    /// Records in the block.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether it holds no record.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Empties it, its buffers kept.
    pub fn clear(&mut self) {
        self.t_s.clear();
        self.values.clear();
    }

    /// Adds `r`, which must follow the block's last record (`r.at` one past it) unless the
    /// block is empty.
    pub fn push(&mut self, r: &Record) {
        if self.is_empty() {
            self.at = r.at;
        }
        self.t_s.push(r.t_s);
        self.values.push(r.values);
    }
}

/// Records [`ImuRecords::read_blocks`] gathers per block at most by default.
const DEFAULT_BLOCK: usize = 4096;

/// [`ImuRecords::read_blocks`] made from [`ImuRecords::read`]: the records gathered in blocks of
/// consecutive `at`, each handed on before the reading's next error.
pub fn blocks_of_records(
    records: &(impl ImuRecords + ?Sized),
    visit: &mut dyn FnMut(&RecordBlock) -> Result<(), LogError>,
) -> Result<(), LogError> {
    let mut block = RecordBlock::default();
    // Whether `visit` itself stopped the reading (its error is then the reading's).
    let mut stopped = false;
    let read = records.read(&mut |r| {
        let follows = block.at.checked_add(block.len() as u64) == Some(r.at);
        if !block.is_empty() && (block.len() == DEFAULT_BLOCK || !follows) {
            let handed = visit(&block);
            stopped = handed.is_err();
            handed?;
            block.clear();
        }
        block.push(r);
        Ok(())
    });
    match read {
        Err(e) if stopped => Err(e),
        read => {
            // The records before the reading's error come first, as record by record.
            if !block.is_empty() {
                visit(&block)?;
            }
            read
        }
    }
}

/// A log that can be read from its start more than once, record by record.
pub trait ImuRecords {
    /// The channels present, in [`Channel::ALL`]'s order.
    fn channels(&self) -> &[Channel];

    /// Hands every record to `visit` in order, stopping at its first error.
    ///
    /// # Errors
    /// [`LogError`] of the reading (a malformed row or message) or of `visit`.
    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError>;

    /// [`ImuRecords::read`] in blocks of consecutive records: the same records in the same
    /// order, each block handed on before the error of the reading that follows it.
    ///
    /// # Errors
    /// As [`ImuRecords::read`].
    fn read_blocks(
        &self,
        visit: &mut dyn FnMut(&RecordBlock) -> Result<(), LogError>,
    ) -> Result<(), LogError> {
        blocks_of_records(self, visit)
    }

    /// How many records a read hands on, when the log says so before it is read (a
    /// recording's summary); a hint for the buffers, not a promise.
    fn count_hint(&self) -> Option<u64> {
        None
    }

    /// The error of `problem` at the record `at` (its line or its message).
    fn error_at(&self, at: u64, problem: LogProblem) -> LogError;

    /// The error of `problem` for the whole log.
    fn error(&self, problem: LogProblem) -> LogError;

    /// What a whole read found amiss but read past (a recording's summary that counts other
    /// messages than were read), in words; none before a read.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// One step of the IMU log: the increments over (`t_s − dt_s`, `t_s`], in body axes
/// forward-right-down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuStep {
    /// Line of the row that ends the step.
    pub line: u64,
    /// The step's end, s.
    pub t_s: f64,
    /// Δθ, Δv and the step's length.
    pub increment: Increment,
}

/// What the IMU measured over one step ending at t_k: the integrals of its angular rate and of
/// its specific force in body axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Increment {
    /// Δθ = ∫ω_ib^b dt, rad.
    pub dtheta_rad: Vector3<f64>,
    /// Δv = ∫f^b dt, m/s.
    pub dvel_m_s: Vector3<f64>,
    /// t_k − t_{k−1}, s.
    pub dt_s: f64,
}

/// One row of the GNSS log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssRow {
    /// Line in the file.
    pub line: u64,
    /// Time of validity, s.
    pub t_s: f64,
    /// The antenna's position.
    pub position: Geodetic,
    /// Velocity north, east, down (m/s); `None` where not measured.
    pub velocity_ned_m_s: [Option<f64>; 3],
    /// The position's σ north, east, down (m), where the log gives it.
    pub position_sigma_m: [Option<f64>; 3],
    /// The velocity's σ per component (m/s), where the log gives it.
    pub velocity_sigma_m_s: [Option<f64>; 3],
}

impl GnssRow {
    /// The horizontal velocity, when both components are measured.
    pub fn horizontal_velocity(&self) -> Option<(f64, f64)> {
        Some((self.velocity_ned_m_s[0]?, self.velocity_ned_m_s[1]?))
    }
}

/// A longitude wrapped into (−π, π], rad: a longitude past the antimeridian (or written in
/// [0, 2π)) is the same meridian.
pub fn wrap_longitude(lon_rad: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if lon_rad > -PI && lon_rad <= PI {
        return lon_rad;
    }
    let w = lon_rad.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// A position on the ellipsoid: geodetic latitude and longitude, ellipsoidal height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geodetic {
    /// Geodetic latitude L, rad, in [−π/2, π/2].
    pub lat_rad: f64,
    /// Longitude λ, rad, east positive, in (−π, π] ([`wrap_longitude`]).
    pub lon_rad: f64,
    /// Height above the ellipsoid h, m.
    pub height_m: f64,
}
