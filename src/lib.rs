//! accelcal: calibrates inertial sensors with GNSS through error-state Kalman filters, verifies
//! the filters with Monte Carlo statistics, and writes the results up as HTML reports.
//!
//! Two worlds, each module depending only on the ones before it:
//!
//! - One axis, an accelerometer's bias from GPS: [`config`] → [`model`] → [`state`] →
//!   [`filter`] → [`simulation`] → [`realization`], [`ensemble`] → [`stats`], [`checks`] →
//!   [`study`], [`sensitivity`] → [`export`], [`plot`] → [`report`]. [`calibrate`] runs the
//!   filter and a smoother over recorded logs ([`likelihood`] estimates their noise statistics);
//!   [`logs`] writes those of a simulated run.
//! - Three axes, a whole IMU from GNSS: [`input`] reads the recordings (CSV, MCAP, ROS 1 and ROS 2
//!   bags); [`ins`] is the navigation layer (the Earth, the strapdown mechanization, the
//!   error-state filter and its measurements, one driver for every run, the Monte Carlo
//!   ensemble); [`calibrate::imu`] calibrates a recording (`calibrate --imu`); [`report`] writes
//!   both worlds' pages. [`allan`] measures the noise terms of a static log ([`allan::imu`]: each
//!   channel of an IMU); [`intrinsics`] calibrates an IMU from static poses on a table.
//!
//! [`format`](mod@format), [`output`], [`progress`], [`error`], [`lanes`] and [`random`] are
//! leaves every step may use. The `accelcal` binary (`src/main.rs`) parses the command line and
//! calls the library; `docs/ARCHITECTURE.md` is the map.
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
pub mod intrinsics;
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
