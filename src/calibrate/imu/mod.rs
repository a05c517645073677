//! `calibrate --imu FILE --gnss FILE`: a whole IMU calibrated from a raw recording — six
//! channels and geodetic GNSS fixes — through the three-axis error-state filter (`crate::ins`).
//!
//! 1. The logs read by `crate::input`: the GNSS log held (one row per fix, `input::gnss_csv`),
//!    the IMU log streamed once as increments (`input::imu_csv`).
//! 2. `align`: with no attitude given, the filter starts at the first fix fast enough for the
//!    course to give the heading; roll and pitch come from the mean specific force over the
//!    window before it, and the prior covariance carries the alignment's errors.
//! 3. `run`: the filter from that fix on through the driver (`drive`: the logs as its sources),
//!    each fix at its own time between IMU samples (the step cut there), tested by the χ² gate
//!    when `[filter] innovation_gate = true`, one record per fix.
//! 4. `smoother`: the Rauch–Tung–Striebel pass backwards over the fixes.
//! 5. `summary`: the six biases and the attitude at the end with σ's, intervals and whether the
//!    drive determined them (each sensor's three a `triad`); the NIS test and the innovations'
//!    whiteness per component; the gate's rejections (`gate`); every assumption made.

pub mod align;
pub mod config;
mod drive;
pub mod gate;
pub mod linearized;
pub mod noise;
pub mod run;
pub mod scale;
pub mod smoother;
mod step;
pub mod summary;
pub mod triad;

use nalgebra::Vector3;
use serde::Serialize;

use crate::config::ins::Axes;

/// The statistics of a consumer-grade MEMS IMU in a road vehicle and of a consumer GNSS
/// receiver, which a calibration assumes where the configuration is silent.
///
/// - Gyros: an uncompensated zero-rate offset of a few °/s (σ 0.1 rad/s = 5.7 °/s: the
///   phone-class parts' datasheets give ±1–5 °/s, the shipped comma2k19 phone's z axis is
///   0.068 rad/s), a random walk of 5·10⁻⁵ rad/s/√s, and white noise of 10⁻³ rad/√s (3.4 °/√h:
///   a datasheet's 0.007–0.01 °/s/√Hz raised for the vibration of a car).
/// - Accelerometers: offset σ 0.2 m/s² (≈ 20 mg; datasheets ±40–80 mg at the limit), a random
///   walk of 10⁻³ m/s²/√s, white noise 0.05 m/s/√s (vibration in a car: the comma2k19 phone's
///   forward axis scatters by 0.9 m/s² at 104 Hz).
/// - GNSS: 2 m horizontal and 4 m vertical σ per fix, 0.1 m/s per velocity component, the
///   antenna at the IMU; a missing vertical velocity is taken as 0 with σ 0.5 m/s at the start.
/// - Heading: the IMU's forward axis along the course within 2° (σ).
/// - Scale factors (estimated only with `error_states = 21`): σ 1 % per axis (10 000 ppm:
///   phone-class datasheets give a sensitivity tolerance of ±1–3 %).
pub const CONSUMER: Settings = Settings {
    axes: Axes::Frd,
    gyro_arw_rad_per_sqrt_s: 1e-3,
    accel_vrw_m_s_per_sqrt_s: 0.05,
    gyro_bias_sigma_rad_s: 0.1,
    gyro_bias_random_walk_rad_s_per_sqrt_s: 5e-5,
    gyro_bias_correlation_time_s: None,
    accel_bias_sigma_m_s2: 0.2,
    accel_bias_random_walk_m_s2_per_sqrt_s: 1e-3,
    accel_bias_correlation_time_s: None,
    gnss_position_sigma_m: [2.0, 2.0, 4.0],
    gnss_velocity_sigma_m_s: 0.1,
    gnss_lever_arm_m: [0.0; 3],
    gnss_time_offset_s: 0.0,
    vertical_velocity_sigma_m_s: 0.5,
    heading_speed_m_s: 5.0,
    alignment_window_s: 2.0,
    heading_offset_sigma_deg: 2.0,
    false_alarm_rate: 0.01,
    error_states: 15,
    innovation_gate: false,
    gyro_scale_factor_sigma_ppm: 10_000.0,
    accel_scale_factor_sigma_ppm: 10_000.0,
};

/// What a calibration assumes: the IMU's axes and statistics, the receiver's, the alignment's
/// thresholds and the tests' false-alarm rate. Every field appears in `summary.json`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// The IMU log's body axes.
    pub axes: Axes,
    /// Gyro angle random walk, rad/√s.
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// Accelerometer velocity random walk, m/s/√s.
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// The gyro biases' prior σ, rad/s.
    pub gyro_bias_sigma_rad_s: f64,
    /// Their random walk, rad/s/√s (with a correlation time: the σ of the Gauss–Markov).
    pub gyro_bias_random_walk_rad_s_per_sqrt_s: f64,
    /// The gyro biases' correlation time, s (`None`: a random walk).
    pub gyro_bias_correlation_time_s: Option<f64>,
    /// The accelerometer biases' prior σ, m/s².
    pub accel_bias_sigma_m_s2: f64,
    /// Their random walk, m/s²/√s.
    pub accel_bias_random_walk_m_s2_per_sqrt_s: f64,
    /// The accelerometer biases' correlation time, s (`None`: a random walk).
    pub accel_bias_correlation_time_s: Option<f64>,
    /// A fix's position σ north, east, down where the log gives none, m.
    pub gnss_position_sigma_m: [f64; 3],
    /// A fix's velocity σ per component where the log gives none, m/s.
    pub gnss_velocity_sigma_m_s: f64,
    /// The antenna from the IMU in body axes, m.
    pub gnss_lever_arm_m: [f64; 3],
    /// The receiver's time offset, s: a fix stamped t describes the antenna at t + offset
    /// (positive: the fixes are stamped early).
    pub gnss_time_offset_s: f64,
    /// The σ of the vertical velocity 0 assumed at the start when the log has none, m/s.
    pub vertical_velocity_sigma_m_s: f64,
    /// The lowest horizontal speed whose course gives the heading, m/s.
    pub heading_speed_m_s: f64,
    /// The alignment's window, s.
    pub alignment_window_s: f64,
    /// The σ of the IMU's heading about the course, °.
    pub heading_offset_sigma_deg: f64,
    /// The false-alarm rate of each test.
    pub false_alarm_rate: f64,
    /// The filter's error states: 15, or 21 with the six scale factors.
    pub error_states: usize,
    /// Whether every fix's innovation is tested by a χ² gate at [`Settings::false_alarm_rate`]
    /// (a rejected fix is left out of the filter, the NIS test and the whiteness, and listed).
    pub innovation_gate: bool,
    /// The gyro scale factors' prior σ, ppm (with 21 states).
    pub gyro_scale_factor_sigma_ppm: f64,
    /// The accelerometer scale factors' prior σ, ppm (with 21 states).
    pub accel_scale_factor_sigma_ppm: f64,
}

impl Settings {
    /// The filter's error state: its blocks (validated with the settings).
    pub fn layout(&self) -> crate::ins::state::Layout {
        crate::ins::state::Layout::with_states(self.error_states)
            .expect("a validated error-state size")
    }

    /// The lever arm as a vector.
    pub fn lever_arm(&self) -> Vector3<f64> {
        Vector3::from(self.gnss_lever_arm_m)
    }
}
