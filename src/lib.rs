//! accelcal: calibrates an accelerometer's bias with GPS through an error-state Kalman filter,
//! verifies the filter with Monte Carlo statistics, and writes the study up as an HTML report.
//!
//! The pipeline, one module per step, each depending only on the ones before it:
//! [`config`] → [`model`] → [`state`] → [`filter`] → [`simulation`] → [`realization`], [`ensemble`] →
//! [`stats`], [`checks`] → [`study`], [`sensitivity`] → [`export`], [`plot`] → [`report`].
//! Below the study, [`input`] reads the sensor logs, [`logs`] writes those of a simulated run,
//! and [`calibrate`] runs the filter and a smoother over them; [`allan`] measures the accelerometer's noise terms from a static log.
//! [`format`](mod@format), [`output`], [`progress`] and [`error`] are leaves every step may use. The `accelcal` binary (`src/main.rs`) parses the command line and calls
//! [`study`], [`sensitivity`], [`calibrate`], [`export`] and [`report`].
#![warn(missing_docs)]

pub mod allan;
pub mod calibrate;
pub mod checks;
pub mod config;
pub mod ensemble;
pub mod error;
pub mod export;
pub mod filter;
pub mod format;
pub mod input;
pub mod ins;
pub mod lanes;
pub mod likelihood;
pub mod logs;
pub mod model;
pub mod output;
pub mod plot;
pub mod progress;
pub mod random;
pub mod realization;
pub mod report;
pub mod sensitivity;
pub mod simulation;
pub mod state;
pub mod stats;
pub mod study;
#[cfg(test)]
mod test_support;
