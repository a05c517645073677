//! The three-axis INS/GNSS study's configuration (`--model ins`): the drive, the IMU and the GNSS
//! receiver as they really are, the filter's prior, the statistics the filter assumes (each
//! missing `[filter]` key takes the truth's), and the ensemble.
//!
//! Parsing rejects unknown fields; a missing field takes its default; [`InsConfig::validate`]
//! names the field and its accepted range.

use serde::{Deserialize, Serialize};

use super::BiasModelKind;
use crate::error::{ConfigError, Position};

#[cfg(test)]
mod tests;
mod validate;
mod vehicle;

pub use vehicle::VehicleConfig;

/// The annotated default file (`accelcal config --model ins`).
pub const DEFAULT_INS_TOML: &str = include_str!("default.toml");

/// The annotated default file of a car (`accelcal config --model car`): the three-axis file
/// with `model = "car"` and its `[vehicle]` section.
pub fn default_car_toml() -> String {
    let body = &DEFAULT_INS_TOML[DEFAULT_INS_TOML.find("model = ").unwrap_or(0)..];
    let body = body.replacen("model = \"ins\"", "model = \"car\"", 1);
    let head = "# accelcal's three-axis study of an IMU in a car (`accelcal config --model car`): \
                a strapdown IMU\n# mounted in a vehicle (the [vehicle] section at the end) and \
                a GNSS receiver on a simulated\n# drive, an error-state Kalman filter of 18 \
                states (the mounting angles too), a Monte Carlo ensemble.\n# Every key is \
                optional: a missing key takes the value written here. Units are in the \
                names.\n";
    format!("{head}{body}{}", include_str!("vehicle.toml"))
}

/// The longest drive: the default drive's length, s.
pub const LONGEST_DRIVE_S: f64 = 600.0;

/// The body axes of an IMU log's columns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axes {
    /// Forward-right-down, the navigation convention.
    #[default]
    Frd,
    /// Forward-left-up, common in ROS (REP 103): y and z of FRD reversed.
    Flu,
}

/// Every parameter of the three-axis study.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InsConfig {
    /// "ins", or "car" for an IMU in a vehicle, when present (the file says which model it
    /// configures).
    pub model: Option<String>,
    /// The drive.
    pub drive: DriveConfig,
    /// The IMU as it really is.
    pub imu: ImuConfig,
    /// The GNSS receiver as it really is.
    pub gnss: GnssConfig,
    /// The filter's prior of the initial errors.
    pub initial: InsInitialConfig,
    /// The statistics the filter assumes: any key of `[imu]` or `[gnss]` but the rates.
    pub filter: InsFilterConfig,
    /// The Monte Carlo ensemble.
    pub ensemble: InsEnsembleConfig,
    /// The statistical verdicts on it.
    pub checks: InsChecksConfig,
    /// A car's vehicle (`model = "car"`; its defaults when the section is left out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vehicle: Option<VehicleConfig>,
}

/// The drive: the default drive's first `duration_s` seconds from a start on the ellipsoid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveConfig {
    /// Length, s, in (0, 600].
    pub duration_s: f64,
    /// Start latitude, degrees, in [−80, 80].
    pub start_lat_deg: f64,
    /// Start longitude, degrees, in [−180, 180].
    pub start_lon_deg: f64,
    /// Start height above the ellipsoid, m, in [−500, 10 000].
    pub start_height_m: f64,
}

impl Default for DriveConfig {
    fn default() -> Self {
        DriveConfig {
            duration_s: LONGEST_DRIVE_S,
            start_lat_deg: 37.4,
            start_lon_deg: -122.1,
            start_height_m: 30.0,
        }
    }
}

/// The IMU's rate, white noise and biases.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImuConfig {
    /// Sample rate, Hz.
    pub imu_rate_hz: f64,
    /// Gyro angle random walk, rad/√s.
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// Accelerometer velocity random walk, m/s/√s.
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// The gyro biases' model.
    pub gyro_bias_model: BiasModelKind,
    /// The gyro biases' σ (a constant's draw, a Gauss–Markov's stationary σ), rad/s.
    pub gyro_bias_sigma_rad_s: f64,
    /// A Gauss–Markov gyro bias's correlation time, s.
    pub gyro_bias_correlation_time_s: f64,
    /// A random-walk gyro bias's K, rad/s per √s.
    pub gyro_bias_random_walk_rad_s_per_sqrt_s: f64,
    /// The accelerometer biases' model.
    pub accel_bias_model: BiasModelKind,
    /// The accelerometer biases' σ, m/s².
    pub accel_bias_sigma_m_s2: f64,
    /// A Gauss–Markov accelerometer bias's correlation time, s.
    pub accel_bias_correlation_time_s: f64,
    /// A random-walk accelerometer bias's K, m/s² per √s.
    pub accel_bias_random_walk_m_s2_per_sqrt_s: f64,
    /// The gyro scale factors' σ (each axis a constant drawn once), ppm.
    pub gyro_scale_factor_sigma_ppm: f64,
    /// The accelerometer scale factors' σ, ppm.
    pub accel_scale_factor_sigma_ppm: f64,
}

impl Default for ImuConfig {
    /// An ADIS16465-class MEMS IMU at 200 Hz: ARW 0.1°/√h, VRW 0.1 m/s/√h, gyro bias 50°/h and
    /// accelerometer bias 0.25 mg, both Gauss–Markov with τ = 1 h.
    fn default() -> Self {
        ImuConfig {
            imu_rate_hz: 200.0,
            gyro_arw_rad_per_sqrt_s: 2.908_882_086_657_216e-5,
            accel_vrw_m_s_per_sqrt_s: 1.666_666_666_666_666_8e-3,
            gyro_bias_model: BiasModelKind::GaussMarkov,
            gyro_bias_sigma_rad_s: 2.424_068_405_547_679_8e-4,
            gyro_bias_correlation_time_s: 3600.0,
            gyro_bias_random_walk_rad_s_per_sqrt_s: 0.0,
            accel_bias_model: BiasModelKind::GaussMarkov,
            accel_bias_sigma_m_s2: 2.451_662_5e-3,
            accel_bias_correlation_time_s: 3600.0,
            accel_bias_random_walk_m_s2_per_sqrt_s: 0.0,
            gyro_scale_factor_sigma_ppm: 0.0,
            accel_scale_factor_sigma_ppm: 0.0,
        }
    }
}

/// The GNSS receiver: rate, antenna and noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GnssConfig {
    /// Fix rate, Hz.
    pub gnss_rate_hz: f64,
    /// The antenna's position from the IMU in body axes (forward, right, down), m.
    pub gnss_lever_arm_m: [f64; 3],
    /// Position noise σ, north, east, down, m.
    pub gnss_position_sigma_m: [f64; 3],
    /// Velocity noise σ per component, m/s.
    pub gnss_velocity_sigma_m_s: f64,
}

impl Default for GnssConfig {
    fn default() -> Self {
        GnssConfig {
            gnss_rate_hz: 1.0,
            gnss_lever_arm_m: [0.4, -0.2, -0.9],
            gnss_position_sigma_m: [1.0, 1.0, 2.0],
            gnss_velocity_sigma_m_s: 0.05,
        }
    }
}

/// The prior of the initial navigation errors (the biases' prior is their σ).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InsInitialConfig {
    /// Position σ per axis, m.
    pub position_sigma_m: f64,
    /// Velocity σ per axis, m/s.
    pub velocity_sigma_m_s: f64,
    /// Roll and pitch σ, degrees.
    pub tilt_sigma_deg: f64,
    /// Heading σ, degrees.
    pub yaw_sigma_deg: f64,
}

impl Default for InsInitialConfig {
    fn default() -> Self {
        InsInitialConfig {
            position_sigma_m: 1.0,
            velocity_sigma_m_s: 0.1,
            tilt_sigma_deg: 0.5,
            yaw_sigma_deg: 2.0,
        }
    }
}

/// What the filter assumes where it differs from the truth: every key optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[allow(missing_docs)]
pub struct InsFilterConfig {
    pub gyro_arw_rad_per_sqrt_s: Option<f64>,
    pub accel_vrw_m_s_per_sqrt_s: Option<f64>,
    pub gyro_bias_model: Option<BiasModelKind>,
    pub gyro_bias_sigma_rad_s: Option<f64>,
    pub gyro_bias_correlation_time_s: Option<f64>,
    pub gyro_bias_random_walk_rad_s_per_sqrt_s: Option<f64>,
    pub accel_bias_model: Option<BiasModelKind>,
    pub accel_bias_sigma_m_s2: Option<f64>,
    pub accel_bias_correlation_time_s: Option<f64>,
    pub accel_bias_random_walk_m_s2_per_sqrt_s: Option<f64>,
    pub gyro_scale_factor_sigma_ppm: Option<f64>,
    pub accel_scale_factor_sigma_ppm: Option<f64>,
    pub gnss_lever_arm_m: Option<[f64; 3]>,
    pub gnss_position_sigma_m: Option<[f64; 3]>,
    pub gnss_velocity_sigma_m_s: Option<f64>,
    /// The filter's error states: 15, 21 with the six scale factors, or a car's 18 with the
    /// mounting angles.
    pub error_states: Option<u32>,
    /// The mounting a car's filter assumes (`vehicle.mounting_rpy_deg`'s meaning).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mounting_rpy_deg: Option<[f64; 3]>,
    /// The slip σ a car's filter assumes, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nhc_sigma_m_s: Option<f64>,
}

/// The Monte Carlo ensemble.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InsEnsembleConfig {
    /// Number of realizations N.
    pub realizations: u64,
    /// Seed of the random streams.
    pub seed: u64,
}

impl Default for InsEnsembleConfig {
    fn default() -> Self {
        InsEnsembleConfig {
            realizations: 1000,
            seed: 2017,
        }
    }
}

/// The statistical verdicts on the ensemble (the linear study's `[checks]` keys that apply).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InsChecksConfig {
    /// Study-wide false-alarm rate: the probability that a consistent filter fails any check,
    /// split evenly over the checks and their members (Bonferroni).
    pub false_alarm_rate: f64,
    /// Largest lag, in fixes, of the residual whiteness check. Left out, 30; a lag of the
    /// drive's fix count or more tests every pair.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_max_lag: Option<u32>,
}

impl Default for InsChecksConfig {
    fn default() -> Self {
        InsChecksConfig {
            false_alarm_rate: 0.01,
            // ins::ensemble::DEFAULT_MAX_LAG, which a file without the key gets too.
            residual_max_lag: Some(30),
        }
    }
}

/// The IMU and GNSS the filter assumes: the truth's with `[filter]`'s keys over them.
#[derive(Clone, Debug, PartialEq)]
pub struct AssumedSensors {
    /// The IMU (its rate is the truth's).
    pub imu: ImuConfig,
    /// The GNSS receiver (its rate is the truth's).
    pub gnss: GnssConfig,
}

impl InsConfig {
    /// Parses a TOML document. Missing fields take their defaults; unknown fields are an error.
    ///
    /// # Errors
    /// [`ConfigError::Parse`] with the line, column and field.
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        toml::from_str(text).map_err(|e| {
            let span = e.span();
            ConfigError::Parse {
                file: None,
                position: span.clone().map(|s| Box::new(Position::of(text, s))),
                field: span.and_then(|s| super::source::field_at(text, s.start)),
                message: e.message().trim_end().to_string(),
            }
        })
    }

    /// The sensors the filter assumes: each `[filter]` key set, else the truth's.
    pub fn assumed(&self) -> AssumedSensors {
        /// `$ty` with each key from `$filter` where set, else from `$truth`, and the `truth:`
        /// keys (the rates) from `$truth` alone; every field is named, so the compiler sees a
        /// new one left out.
        macro_rules! over_truth {
            ($filter:expr, $truth:expr, $ty:ident { truth: $($own:ident),*; $($key:ident),* $(,)? }) => {
                $ty {
                    $($own: $truth.$own,)*
                    $($key: $filter.$key.unwrap_or($truth.$key),)*
                }
            };
        }
        let f = &self.filter;
        let imu = over_truth!(
            f,
            self.imu,
            ImuConfig {
                truth: imu_rate_hz;
                gyro_arw_rad_per_sqrt_s,
                accel_vrw_m_s_per_sqrt_s,
                gyro_bias_model,
                gyro_bias_sigma_rad_s,
                gyro_bias_correlation_time_s,
                gyro_bias_random_walk_rad_s_per_sqrt_s,
                accel_bias_model,
                accel_bias_sigma_m_s2,
                accel_bias_correlation_time_s,
                accel_bias_random_walk_m_s2_per_sqrt_s,
                gyro_scale_factor_sigma_ppm,
                accel_scale_factor_sigma_ppm,
            }
        );
        let gnss = over_truth!(
            f,
            self.gnss,
            GnssConfig {
                truth: gnss_rate_hz;
                gnss_lever_arm_m,
                gnss_position_sigma_m,
                gnss_velocity_sigma_m_s,
            }
        );
        AssumedSensors { imu, gnss }
    }
}
