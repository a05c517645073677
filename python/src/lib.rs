//! The extension module `accelcal._accelcal`: thin calls into the accelcal library. The Python
//! layer (`python/accelcal/__init__.py`) checks arrays (dtype, shape, NaN, order) and builds the
//! result objects; this layer releases the GIL around the work and turns the library's errors
//! into Python exceptions carrying the command line's message.

mod allan;
mod calibrate;
mod calibrate_imu;
mod config;
mod interrupt;
mod monte_carlo;

use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;

use accelcal::error::ConfigError;

/// A library error as a Python exception: `FileNotFoundError` for a file that does not exist,
/// `ValueError` for every other bad input, with the message the command line prints.
pub(crate) fn bad_input(err: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(err.to_string())
}

/// A configuration error: a file that cannot be found is `FileNotFoundError`.
pub(crate) fn config_error(err: ConfigError) -> PyErr {
    match &err {
        ConfigError::Read { path, .. } if !std::path::Path::new(path).exists() => {
            PyFileNotFoundError::new_err(err.to_string())
        }
        _ => bad_input(err),
    }
}

#[pymodule]
fn _accelcal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(allan::allan_analysis, m)?)?;
    m.add_class::<allan::AllanAnalysis>()?;
    m.add_class::<calibrate::CalibrationResult>()?;
    m.add_function(wrap_pyfunction!(monte_carlo::ensemble_json, m)?)?;
    m.add_function(wrap_pyfunction!(monte_carlo::simulate_logs, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate_arrays, m)?)?;
    m.add_class::<calibrate_imu::ImuCalibrationResult>()?;
    m.add_function(wrap_pyfunction!(calibrate_imu::calibrate_imu_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(config::default_config, m)?)?;
    m.add_function(wrap_pyfunction!(config::toml_of_json, m)?)?;
    Ok(())
}
