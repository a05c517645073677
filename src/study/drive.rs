//! A real drive: the minute of comma2k19 shipped in `examples/comma2k19/`, calibrated as a user
//! would calibrate it, with noise statistics estimated from the drive itself.
//!
//! The files are compiled into the program, so the report's numbers always come from running
//! the calibration on the shipped files, wherever the program runs.

use crate::calibrate::summary::Calibration;
use crate::calibrate::{self, CalibrateError, Settings};
use crate::config::Config;
use crate::input::csv::read::LogText;
use crate::likelihood::{Key, NoiseEstimate, Request};

/// The shipped accelerometer log as recorded (gravity's component along the axis included).
pub const ACCEL_RAW: &[u8] = include_bytes!("../../examples/comma2k19/accel_raw.csv");
/// The same axis with gravity's component removed.
pub const ACCEL_GRAVCOMP: &[u8] = include_bytes!("../../examples/comma2k19/accel_gravcomp.csv");
/// The shipped GPS log.
pub const GPS: &[u8] = include_bytes!("../../examples/comma2k19/gps.csv");
/// The directory the files are shipped in, as the report names it.
pub const DRIVE_DIR: &str = "examples/comma2k19";

/// Which accelerometer log a run takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// `accel_gravcomp.csv`.
    GravityCompensated,
    /// `accel_raw.csv`.
    Raw,
}

impl Axis {
    /// The file's name.
    pub fn file(self) -> &'static str {
        match self {
            Axis::GravityCompensated => "accel_gravcomp.csv",
            Axis::Raw => "accel_raw.csv",
        }
    }

    fn text(self) -> &'static [u8] {
        match self {
            Axis::GravityCompensated => ACCEL_GRAVCOMP,
            Axis::Raw => ACCEL_RAW,
        }
    }
}

/// One calibration of the drive.
#[derive(Clone, Debug)]
pub struct DriveRun {
    /// The accelerometer log.
    pub axis: Axis,
    /// The calibration's summary and per-fix series.
    pub calibration: Calibration,
    /// The estimate of the statistics (with the filter's statistics, its bias model among
    /// them).
    pub noise: NoiseEstimate,
}

/// The runs of the section: the gravity-compensated axis with the GPS σ's estimated, then with the
/// white noise W too; the raw axis with a constant bias and with a random walk (K estimated).
pub const RUNS: [(Axis, &[Key]); 4] = [
    (
        Axis::GravityCompensated,
        &[Key::GpsPosition, Key::GpsVelocity],
    ),
    (
        Axis::GravityCompensated,
        &[Key::GpsPosition, Key::GpsVelocity, Key::AccelNoiseVar],
    ),
    (
        Axis::Raw,
        &[Key::GpsPosition, Key::GpsVelocity, Key::AccelNoiseVar],
    ),
    (
        Axis::Raw,
        &[
            Key::GpsPosition,
            Key::GpsVelocity,
            Key::AccelNoiseVar,
            Key::BiasRandomWalk,
        ],
    ),
];

/// The settings of a calibration with no configuration, as `calibrate` runs without
/// `--config`: the default statistics and α, the log's median step, the integration started from
/// the first fix with the GPS σ's as its prior σ's.
pub fn settings() -> Settings {
    Settings::from_config(&Config::default(), false, false)
        .expect("the default configuration is valid")
}

/// Calibrates the drive on `axis` with `keys` estimated.
///
/// # Errors
/// [`CalibrateError`] as [`calibrate::prepare_with`] (not for the shipped files).
pub fn run_one(axis: Axis, keys: &[Key]) -> Result<DriveRun, CalibrateError> {
    let accel = LogText::new(&format!("{DRIVE_DIR}/{}", axis.file()), axis.text());
    let gps = LogText::new(&format!("{DRIVE_DIR}/gps.csv"), GPS);
    let settings = settings();
    let request = Request {
        keys: keys.to_vec(),
        confidence: 0.95,
    };
    let prepared = calibrate::prepare_with(&accel, &gps, &settings, Some(&request))?;
    let noise = prepared
        .noise_estimate()
        .cloned()
        .expect("an estimate was asked for");
    Ok(DriveRun {
        axis,
        calibration: prepared.calibration(),
        noise,
    })
}

/// Every run of [`RUNS`].
///
/// # Errors
/// As [`run_one`].
pub fn run() -> Result<Vec<DriveRun>, CalibrateError> {
    RUNS.iter()
        .map(|(axis, keys)| run_one(*axis, keys))
        .collect()
}
