//! An IMU's intrinsics from a few static poses turned by hand (`accelcal intrinsics`): the
//! accelerometers' bias, scale factors and non-orthogonality, the gyros' bias, each with its
//! interval, which of them the poses determine, and a goodness-of-fit test.
//!
//! The method is the multi-position calibration of Tedaldi, Pretto & Menegatti (ICRA 2014,
//! imu_tk's): static intervals found on the IMU alone ([`detect`]), the accelerometer's model
//! fitted so that every interval's mean specific force has the magnitude of local gravity
//! ([`accel`]), the gyros' bias from the same intervals with the Earth's rate allowed for
//! ([`gyro`]), and the gyros' matrix from the turns between them ([`gyro_matrix`]). Unlike imu_tk, every weight is the noise measured in the log, the fit's covariance
//! gives the intervals, and a parameter the poses leave free is named, never given as a number.
//!
//! # Convention
//! corrected = matrix · (measured − bias). The accelerometer's matrix is lower triangular: the
//! corrected frame's x axis is the sensor's x axis and its y axis lies in the plane of the
//! sensor's x and y axes (the frame a magnitude fit can fix; a rotation of it is not seen by
//! magnitudes). The derived `scale_ppm` and `misalignment_rad` are frame-free: the sensing axes'
//! gains |row i of matrix⁻¹| − 1 and each pair of axes' departure from 90°.

pub mod accel;
pub mod detect;
pub mod export;
pub mod gyro;
pub mod gyro_matrix;
pub mod simulate;

use nalgebra::Vector3;

use crate::input::records::{Channel, ImuSamples};

/// A six-axis log held whole: specific force (m/s²) and angular rate (rad/s) at each sample.
#[derive(Clone, Debug)]
pub struct SixAxisLog {
    /// The median sample period τ₀, s.
    pub sample_period_s: f64,
    /// Specific force at each sample, m/s², in the sensor's axes.
    pub specific_force: Vec<Vector3<f64>>,
    /// Angular rate at each sample, rad/s, in the sensor's axes.
    pub angular_rate: Vec<Vector3<f64>>,
}

impl SixAxisLog {
    /// The log's six channels, or the channels it lacks.
    ///
    /// # Errors
    /// [`IntrinsicsError::MissingChannels`] when a channel of the six is absent.
    pub fn from_samples(samples: &ImuSamples) -> Result<Self, IntrinsicsError> {
        let of = |c: Channel| samples.channels.iter().find(|(x, _)| *x == c);
        let missing: Vec<&'static str> = Channel::ALL
            .into_iter()
            .filter(|c| of(*c).is_none())
            .map(Channel::column)
            .collect();
        if !missing.is_empty() {
            return Err(IntrinsicsError::MissingChannels(missing.join(", ")));
        }
        let column = |c: Channel| &of(c).expect("checked above").1;
        let [ax, ay, az, gx, gy, gz] = Channel::ALL.map(column);
        let n = ax.len();
        Ok(Self {
            sample_period_s: samples.sample_period_s,
            specific_force: (0..n).map(|k| Vector3::new(ax[k], ay[k], az[k])).collect(),
            angular_rate: (0..n).map(|k| Vector3::new(gx[k], gy[k], gz[k])).collect(),
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.specific_force.len()
    }

    /// Whether the log holds no sample.
    pub fn is_empty(&self) -> bool {
        self.specific_force.is_empty()
    }
}

/// What the calibration needs besides the log.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Local gravity's magnitude, m/s².
    pub gravity_m_s2: f64,
    /// Geodetic latitude, rad, when known: the Earth's rate at rest is then split into its known
    /// vertical part and a horizontal part of known size and unknown direction.
    pub latitude_rad: Option<f64>,
    /// The static detector's settings.
    pub detector: detect::DetectorSettings,
    /// Confidence of the two-sided intervals, in (0, 1).
    pub confidence: f64,
    /// Rate at which the goodness-of-fit tests reject a log drawn from the model.
    pub alpha: f64,
}

impl Settings {
    /// Checks every setting against its accepted range.
    ///
    /// # Errors
    /// [`IntrinsicsError::Setting`] naming the first setting outside its range.
    pub fn validate(&self) -> Result<(), IntrinsicsError> {
        let d = &self.detector;
        let open_unit = |x: f64| x > 0.0 && x < 1.0;
        let checks: [(&'static str, f64, bool, &'static str); 6] = [
            (
                "--gravity",
                self.gravity_m_s2,
                (9.7..=9.9).contains(&self.gravity_m_s2),
                "9.7 ≤ g ≤ 9.9 m/s² (the Earth's surface)",
            ),
            (
                "--window",
                d.window_s,
                d.window_s > 0.0 && d.window_s <= 60.0,
                "0 < window ≤ 60 s",
            ),
            (
                "--min-static",
                d.min_static_s,
                d.min_static_s >= d.window_s && d.min_static_s <= 3600.0,
                "window ≤ min-static ≤ 3600 s",
            ),
            (
                "--false-alarm",
                d.false_alarm,
                open_unit(d.false_alarm),
                "0 < p < 1",
            ),
            (
                "--confidence",
                self.confidence,
                open_unit(self.confidence),
                "0 < c < 1",
            ),
            ("--alpha", self.alpha, open_unit(self.alpha), "0 < p < 1"),
        ];
        match checks.into_iter().find(|c| !c.2) {
            Some((name, value, _, expected)) => Err(IntrinsicsError::Setting {
                name,
                value,
                expected,
            }),
            None => Ok(()),
        }
    }

    /// The defaults around `gravity_m_s2`: 95 % intervals, goodness tested at α = 0.01.
    pub fn new(gravity_m_s2: f64) -> Self {
        Self {
            gravity_m_s2,
            latitude_rad: None,
            detector: detect::DetectorSettings::default(),
            confidence: 0.95,
            alpha: 0.01,
        }
    }
}

/// The whole calibration of one log.
#[derive(Clone, Debug)]
pub struct Intrinsics {
    /// The static intervals and the noise measured in them.
    pub detection: detect::Detection,
    /// The accelerometers' model.
    pub accel: accel::AccelFit,
    /// The gyros' bias from the static poses.
    pub gyro: gyro::GyroBias,
    /// The gyros' matrix and bias from the turns between the poses; `None` with one pose.
    pub gyro_matrix: Option<gyro_matrix::GyroFit>,
    /// The settings it was computed with.
    pub settings: Settings,
}

/// Why a log gives no calibration.
#[derive(Debug, thiserror::Error)]
pub enum IntrinsicsError {
    /// A channel of the six is absent.
    #[error("the log has no column {0}: the intrinsics need all six channels")]
    MissingChannels(String),
    /// The log is shorter than two detector windows.
    #[error(
        "the log holds {samples} samples, fewer than two detector windows ({window} samples of \
         {window_s} s): record each pose for several seconds"
    )]
    TooShort {
        /// Samples in the log.
        samples: usize,
        /// Samples in a window.
        window: usize,
        /// The window, s.
        window_s: f64,
    },
    /// No static interval long enough was found.
    #[error(
        "no static interval of at least {min_static_s} s was found: hold the IMU still in each \
         pose (on a table, not in the hand) for several seconds"
    )]
    NoStaticInterval {
        /// The shortest interval accepted, s.
        min_static_s: f64,
    },
    /// A setting outside its accepted range.
    #[error("{name} = {value} is outside its accepted range: expected {expected}")]
    Setting {
        /// The setting's flag.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// A value of the log is not finite.
    #[error("sample {index} of the log is not finite")]
    NotFinite {
        /// The sample's index, from 0.
        index: usize,
    },
}

/// Calibrates the IMU of `log`: static intervals, the accelerometers' fit, the gyros' bias.
///
/// # Errors
/// [`IntrinsicsError`] for a log too short, with a value that is not finite, or without a
/// static interval.
pub fn calibrate(log: &SixAxisLog, settings: &Settings) -> Result<Intrinsics, IntrinsicsError> {
    if let Some(index) = (0..log.len()).find(|&k| {
        !(log.specific_force[k].iter().all(|v| v.is_finite())
            && log.angular_rate[k].iter().all(|v| v.is_finite()))
    }) {
        return Err(IntrinsicsError::NotFinite { index });
    }
    let detection = detect::detect(log, &settings.detector, settings.gravity_m_s2)?;
    let accel = accel::fit(&detection, settings);
    let gyro = gyro::bias(&detection, &accel, settings);
    let gyro_matrix = gyro_matrix::fit(log, &detection, &accel, &gyro, settings);
    Ok(Intrinsics {
        detection,
        accel,
        gyro,
        gyro_matrix,
        settings: *settings,
    })
}

#[cfg(test)]
mod tests;
