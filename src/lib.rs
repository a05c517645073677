//! accelcal: calibrates an accelerometer's bias with GPS through an error-state Kalman filter,
//! verifies the filter with Monte Carlo statistics, and writes the study up as an HTML report.
//!
//! The pipeline, one module per step: [`config`] → [`model`] → [`simulation`] → [`filter`] →
//! [`ensemble`] → [`checks`] → [`export`] and the report.

pub mod app;
pub mod checks;
pub mod cli;
pub mod config;
pub mod ensemble;
pub mod error;
pub mod export;
pub mod filter;
pub mod model;
pub mod output;
pub mod plot;
pub mod realization;
pub mod report;
pub mod simulation;
pub mod study;
