//! `accelcal.allan`: the Allan analysis of rate samples (the library's `allan::analyse`, which
//! `accelcal allan` runs on a log's column).

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use accelcal::allan::{self, export};

/// One analysis, kept whole so that the files `accelcal allan` writes come from it.
#[pyclass(frozen, module = "accelcal._accelcal")]
pub(crate) struct AllanAnalysis(allan::Analysis);

#[pymethods]
impl AllanAnalysis {
    /// `allan.json`, byte for byte.
    fn json(&self) -> String {
        export::allan_json(&self.0)
    }

    /// `noise.toml` with `source` named as the data's origin.
    fn noise_toml(&self, source: &str) -> String {
        export::noise_toml(&self.0, source)
    }

    /// `imu.yaml` with `source` named as the data's origin.
    fn imu_yaml(&self, source: &str) -> String {
        export::imu_yaml(&self.0, source)
    }
}

/// The overlapping Allan deviation, its intervals and the noise terms of rate samples `y`
/// (m/s², float64 and contiguous: the Python layer converts once) τ₀ = `tau0_s` apart. The GIL
/// is released during the analysis; Ctrl-C stops it between stretches of its pass
/// (`crate::interrupt::until_stopped`).
#[pyfunction]
pub(crate) fn allan_analysis(
    py: Python<'_>,
    y: PyReadonlyArray1<'_, f64>,
    tau0_s: f64,
    confidence: f64,
) -> PyResult<AllanAnalysis> {
    let y = y.as_slice().map_err(crate::bad_input)?;
    let analysis = crate::interrupt::until_stopped(py, |cancel| {
        allan::analyse_cancellable(y, tau0_s, confidence, cancel)
    })?
    .map_err(crate::bad_input)?;
    Ok(AllanAnalysis(analysis))
}
