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
//! The log is read by [`crate::input`] (a CSV log by [`crate::input::imu_channels_csv`], an MCAP
//! file or a ROS bag by [`crate::input::recording`]), into the channels' samples or as records
//! read again from disk; [`stream`] analyses the records; [`export`] writes the files.

pub mod export;
mod held;
pub mod stream;

use thiserror::Error;

use super::{AllanError, Analysis, Reading, Term, TermEstimate, analyse, analyse_in_place};
use crate::input::records::{Channel, ImuSamples, Sensor};

/// The words of the sensors' terms in the files and on the page.
impl Sensor {
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

/// A channel the analysis cannot use.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("column {column}: {reason}")]
pub struct ImuError {
    /// The channel's column.
    pub column: &'static str,
    /// Why (in the message itself, not again as its source: the reason is printed once).
    pub reason: AllanError,
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
    use rayon::prelude::*;
    // Every channel on the pool, the first error in the channels' order.
    let analysed: Vec<_> = log
        .channels
        .par_iter()
        .map(|(channel, y)| {
            analyse(y, log.sample_period_s, confidence)
                .map(|analysis| ChannelAnalysis {
                    channel: *channel,
                    analysis,
                })
                .map_err(|reason| ImuError {
                    column: channel.column(),
                    reason,
                })
        })
        .collect();
    let channels = analysed.into_iter().collect::<Result<Vec<_>, _>>()?;
    Ok(ImuAnalysis {
        samples: log.channels.first().map_or(0, |c| c.1.len()),
        sample_period_s: log.sample_period_s,
        confidence,
        channels,
    })
}

/// [`analyse_imu`] of channels held one place in (`(channel, [_, y_0, …, y_{n−1}])`, the first
/// place free): each channel's phase summed where its values are, the same analysis.
///
/// # Errors
/// As [`analyse_imu`].
pub(crate) fn analyse_held(
    channels: Vec<(Channel, Vec<f64>)>,
    sample_period_s: f64,
    confidence: f64,
) -> Result<ImuAnalysis, ImuError> {
    use rayon::prelude::*;
    let samples = channels.first().map_or(0, |c| c.1.len() - 1);
    let analysed: Vec<_> = channels
        .into_par_iter()
        .map(|(channel, held)| {
            analyse_in_place(held, sample_period_s, confidence)
                .map(|analysis| ChannelAnalysis { channel, analysis })
                .map_err(|reason| ImuError {
                    column: channel.column(),
                    reason,
                })
        })
        .collect();
    let channels = analysed.into_iter().collect::<Result<Vec<_>, _>>()?;
    Ok(ImuAnalysis {
        samples,
        sample_period_s,
        confidence,
        channels,
    })
}
