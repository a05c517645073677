//! The whole IMU's noise from one static recording (`accelcal allan --imu`): each of the six
//! channels of a three-axis log analysed as the one-column form analyses its column
//! ([`super::analyse`], unchanged), and per sensor the largest term across its axes — what
//! Kalibr, OpenVINS and VINS-Mono take, one number for the three axes.
//!
//! The gyro terms are the same model in angle: σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)B² + K²τ/3 +
//! R²τ²/2 with N the angle random walk (rad/√s), B the bias instability (rad/s), K the rate
//! random walk (rad/s/√s) (IEEE Std 952-1997, annex C; the accelerometer's names are those of
//! IEEE Std 1293-2018).
//!
//! [`read`] reads a CSV log, [`bag`] an MCAP file or a ROS 2 bag; [`export`] writes the files.

pub mod bag;
pub mod export;
pub mod mcap_stream;
pub mod piped;
pub mod read;
pub mod rosbag1;
pub mod rosbag1_stream;
pub mod stream;

use thiserror::Error;

use super::{AllanError, Analysis, Reading, Term, TermEstimate, analyse};

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

    /// The sensor's word in `allan.json` and `imu.yaml`.
    pub fn key(self) -> &'static str {
        match self {
            Sensor::Accelerometer => "accelerometer",
            Sensor::Gyroscope => "gyroscope",
        }
    }

    /// The name of `term` for this sensor with its SI unit, as a JSON key.
    pub fn term_key(self, term: Term) -> &'static str {
        match (self, term) {
            (Sensor::Accelerometer, Term::Quantization) => "quantization_m_s",
            (Sensor::Accelerometer, Term::VelocityRandomWalk) => {
                "velocity_random_walk_m_s_per_sqrt_s"
            }
            (Sensor::Accelerometer, Term::BiasInstability) => "bias_instability_m_s2",
            (Sensor::Accelerometer, Term::AccelerationRandomWalk) => {
                "acceleration_random_walk_m_s2_per_sqrt_s"
            }
            (Sensor::Accelerometer, Term::RateRamp) => "rate_ramp_m_s3",
            (Sensor::Gyroscope, Term::Quantization) => "quantization_rad",
            (Sensor::Gyroscope, Term::VelocityRandomWalk) => "angle_random_walk_rad_per_sqrt_s",
            (Sensor::Gyroscope, Term::BiasInstability) => "bias_instability_rad_s",
            (Sensor::Gyroscope, Term::AccelerationRandomWalk) => {
                "rate_random_walk_rad_s_per_sqrt_s"
            }
            (Sensor::Gyroscope, Term::RateRamp) => "rate_ramp_rad_s2",
        }
    }

    /// The SI unit of `term` for this sensor, as people read it.
    pub fn term_unit(self, term: Term) -> &'static str {
        match (self, term) {
            (Sensor::Accelerometer, Term::Quantization) => "m/s",
            (Sensor::Accelerometer, Term::VelocityRandomWalk) => "m/s/√s",
            (Sensor::Accelerometer, Term::BiasInstability) => "m/s²",
            (Sensor::Accelerometer, Term::AccelerationRandomWalk) => "m/s²/√s",
            (Sensor::Accelerometer, Term::RateRamp) => "m/s³",
            (Sensor::Gyroscope, Term::Quantization) => "rad",
            (Sensor::Gyroscope, Term::VelocityRandomWalk) => "rad/√s",
            (Sensor::Gyroscope, Term::BiasInstability) => "rad/s",
            (Sensor::Gyroscope, Term::AccelerationRandomWalk) => "rad/s/√s",
            (Sensor::Gyroscope, Term::RateRamp) => "rad/s²",
        }
    }

    /// The name of `term` for this sensor, in words.
    pub fn term_name(self, term: Term) -> &'static str {
        match (self, term) {
            (_, Term::Quantization) => "quantization Q",
            (Sensor::Accelerometer, Term::VelocityRandomWalk) => "velocity random walk N",
            (Sensor::Gyroscope, Term::VelocityRandomWalk) => "angle random walk N",
            (_, Term::BiasInstability) => "bias instability B",
            (Sensor::Accelerometer, Term::AccelerationRandomWalk) => "acceleration random walk K",
            (Sensor::Gyroscope, Term::AccelerationRandomWalk) => "rate random walk K",
            (_, Term::RateRamp) => "rate ramp R",
        }
    }

    /// The unit of the rate samples (σ(τ) is in it).
    pub fn rate_unit(self) -> &'static str {
        match self {
            Sensor::Accelerometer => "m/s²",
            Sensor::Gyroscope => "rad/s",
        }
    }
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

    /// The column of the three-axis log (`ins::logs`' imu.csv).
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

/// A channel the analysis cannot use.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("column {column}: {source}")]
pub struct ImuError {
    /// The channel's column.
    pub column: &'static str,
    /// Why.
    #[source]
    pub source: AllanError,
}

/// One channel's analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelAnalysis {
    /// The channel.
    pub channel: Channel,
    /// Its analysis, exactly as `allan --accel FILE --column COLUMN` makes it.
    pub analysis: Analysis,
}

/// The largest value of one term across a sensor's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Largest {
    /// The term.
    pub term: Term,
    /// The largest estimate, or upper bound where an axis leaves the term unresolved.
    pub value: f64,
    /// The channel it comes from.
    pub channel: Channel,
    /// Whether `value` is an upper bound (that axis does not resolve the term).
    pub upper_bound: bool,
    /// Which reading that axis's terms come from.
    pub reading: Reading,
}

/// Every channel's analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuAnalysis {
    /// Samples per channel n.
    pub samples: usize,
    /// τ₀, s.
    pub sample_period_s: f64,
    /// The intervals' confidence.
    pub confidence: f64,
    /// Each channel present, in [`Channel::ALL`]'s order.
    pub channels: Vec<ChannelAnalysis>,
}

/// A term's value for a file another tool reads: the estimate, else the upper bound (`true`).
pub fn value_or_bound(t: &TermEstimate) -> (f64, bool) {
    t.value.map_or((t.upper, true), |v| (v, false))
}

impl ImuAnalysis {
    /// The channels of `sensor`.
    pub fn of(&self, sensor: Sensor) -> impl Iterator<Item = &ChannelAnalysis> {
        self.channels
            .iter()
            .filter(move |c| c.channel.sensor() == sensor)
    }

    /// The largest value of `term` across `sensor`'s axes (estimates and upper bounds alike:
    /// the largest is what those tools' users are told to take), `None` without such a channel.
    pub fn largest(&self, sensor: Sensor, term: Term) -> Option<Largest> {
        self.of(sensor)
            .filter_map(|c| {
                c.analysis.term(term).map(|t| {
                    let (value, upper_bound) = value_or_bound(t);
                    Largest {
                        term,
                        value,
                        channel: c.channel,
                        upper_bound,
                        reading: c.analysis.reading,
                    }
                })
            })
            .max_by(|a, b| a.value.total_cmp(&b.value))
    }
}

/// The Gauss–Markov correlation time of an axis's bias, s: the fitted T_c where the log resolves
/// the term, else the rule of thumb τ_min/1.89 (the Allan minimum taken for the hump's peak,
/// IEEE Std 952, annex C), which the log does not determine ([`fitted_correlation_time`] tells
/// which).
pub fn correlation_time_s(a: &Analysis) -> f64 {
    a.gauss_markov
        .correlation_time_s
        .filter(|_| a.gauss_markov.resolved)
        .unwrap_or_else(|| a.tau_at_minimum_s() / 1.89)
}

/// Whether [`correlation_time_s`] of the axis is the fitted T_c (not the rule of thumb).
pub fn fitted_correlation_time(a: &Analysis) -> bool {
    a.gauss_markov.resolved && a.gauss_markov.correlation_time_s.is_some()
}

/// Analyses every channel of `log` as [`analyse`] does one column, at `confidence`.
///
/// # Errors
/// [`ImuError`] naming the first channel the analysis cannot use.
pub fn analyse_imu(log: &ImuSamples, confidence: f64) -> Result<ImuAnalysis, ImuError> {
    let channels = log
        .channels
        .iter()
        .map(|(channel, y)| {
            analyse(y, log.sample_period_s, confidence)
                .map(|analysis| ChannelAnalysis {
                    channel: *channel,
                    analysis,
                })
                .map_err(|source| ImuError {
                    column: channel.column(),
                    source,
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ImuAnalysis {
        samples: log.channels.first().map_or(0, |c| c.1.len()),
        sample_period_s: log.sample_period_s,
        confidence,
        channels,
    })
}
