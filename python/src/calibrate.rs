//! `accelcal.calibrate`: the calibration of `accelcal calibrate` from arrays. The accelerometer's
//! arrays are read in place (`input::csv::arrays::AccelArrays`: calibrate's pass takes the slices, no
//! text in between); the GPS fixes, a few thousand rows, are written once as the GPS log's CSV in
//! memory with every number in its shortest round-trip form (`input::csv::text::push_row`), which
//! reads back as the same doubles. Every number equals the command line's on the same data.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use accelcal::calibrate::summary::Calibration;
use accelcal::calibrate::{self, Settings};
use accelcal::config::Config;
use accelcal::error::ConfigError;
use accelcal::input::csv::GPS_COLUMNS;
use accelcal::input::csv::arrays::AccelArrays;
use accelcal::input::csv::read::LogText;
use accelcal::input::csv::text::{header, push_row};
use accelcal::likelihood::{Key, Request};

use crate::config::{self, Source};

/// A finished calibration: its summary, its estimates and what its page needs.
#[pyclass(frozen, unsendable, module = "accelcal._accelcal")]
pub(crate) struct CalibrationResult {
    calibration: Calibration,
    estimates_csv: String,
}

#[pymethods]
impl CalibrationResult {
    /// `summary.json`, byte for byte.
    fn summary_json(&self) -> String {
        self.calibration.summary.to_json()
    }

    /// `estimates.csv` (one row per GPS fix), byte for byte.
    fn estimates_csv(&self) -> &str {
        &self.estimates_csv
    }

    /// The page `index.html`, with `command` as the line that reproduces it.
    fn html(&self, command: &str) -> PyResult<String> {
        accelcal::report::calibration::render(&self.calibration, command, false)
            .map_err(crate::bad_input)
    }
}

/// The settings of `source` as `accelcal calibrate --config` reads them.
fn settings(source: Option<Source>) -> Result<Settings, ConfigError> {
    let (text, config): (_, Config) = config::load(source)?;
    Settings::from_config_text(&config, text.as_ref())
}

/// What `--estimate-noise [--estimate KEYS]` asks for: `None` for no estimation, an empty list
/// for the default statistics.
fn request(
    keys: Option<Vec<String>>,
    confidence: f64,
    settings: &Settings,
) -> PyResult<Option<Request>> {
    let Some(names) = keys else {
        return Ok(None);
    };
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(crate::bad_input(format!(
            "confidence = {confidence}: expected a number strictly between 0 and 1"
        )));
    }
    let stats = &settings.filter_stats;
    let mut named = Vec::new();
    for n in &names {
        named.push(Key::parse(n).ok_or_else(|| {
            crate::bad_input(format!(
                "estimate_noise: {n:?} is not a statistic the likelihood searches; expected \
                 one of {}",
                Key::ALL.map(|k| k.name()).join(", ")
            ))
        })?);
    }
    Request::new(&named, confidence, stats)
        .map(Some)
        .map_err(|e| crate::bad_input(e.to_string()))
}

/// Columns of equal length as a log's CSV text.
fn csv(columns: &[&str], values: &[&[f64]]) -> String {
    let n = values.first().map_or(0, |v| v.len());
    let mut out = String::with_capacity(24 * values.len() * n + 64);
    out.push_str(&header(columns));
    let mut row = vec![0.0; values.len()];
    for i in 0..n {
        for (r, v) in row.iter_mut().zip(values) {
            *r = v[i];
        }
        push_row(&mut out, &row);
    }
    out
}

/// The calibration of the accelerometer samples `at`, `a` with the GPS fixes `gt`, `gp`, `gv`
/// and its `estimates.csv`.
fn calibrate_slices(
    [at, a, gt, gp, gv]: [&[f64]; 5],
    settings: &Settings,
    request: Option<&Request>,
) -> PyResult<(Calibration, String)> {
    let accel_log = AccelArrays::new("accel", at, a).map_err(crate::bad_input)?;
    let gps_log = LogText::new("gps", csv(&GPS_COLUMNS, &[gt, gp, gv]));
    let prepared = calibrate::prepare_with(&accel_log, &gps_log, settings, request)
        .map_err(crate::bad_input)?;
    let mut estimates = Vec::new();
    prepared
        .write_fix_estimates(&mut estimates)
        .map_err(crate::bad_input)?;
    let estimates = String::from_utf8(estimates).map_err(crate::bad_input)?;
    Ok((prepared.calibration(), estimates))
}

/// The calibration of the accelerometer samples (`accel_t` s, `accel` m/s²) with the GPS fixes
/// (`gps_t` s, `gps_position` m, `gps_velocity` m/s); `estimate` as [`request`]. The arrays
/// are float64 and contiguous (the Python layer converts once and checks them) and read in
/// place, the GIL released during the work. With a noise estimate the arrays are copied once
/// and the work runs on a thread of its own that Ctrl-C leaves behind
/// (`crate::interrupt::leaving_behind`): the likelihood's search polls no flag.
#[pyfunction]
#[pyo3(signature = (accel_t, accel, gps_t, gps_position, gps_velocity, config_kind, config_value, estimate, confidence))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn calibrate_arrays(
    py: Python<'_>,
    accel_t: PyReadonlyArray1<'_, f64>,
    accel: PyReadonlyArray1<'_, f64>,
    gps_t: PyReadonlyArray1<'_, f64>,
    gps_position: PyReadonlyArray1<'_, f64>,
    gps_velocity: PyReadonlyArray1<'_, f64>,
    config_kind: Option<&str>,
    config_value: Option<String>,
    estimate: Option<Vec<String>>,
    confidence: f64,
) -> PyResult<CalibrationResult> {
    let source = config_kind.zip(config_value).map(|(k, v)| Source::of(k, v));
    let settings = settings(source).map_err(crate::config_error)?;
    let request = request(estimate, confidence, &settings)?;
    let arrays = [&accel_t, &accel, &gps_t, &gps_position, &gps_velocity];
    let mut slices: [&[f64]; 5] = [&[]; 5];
    for (s, a) in slices.iter_mut().zip(arrays) {
        *s = a.as_slice().map_err(crate::bad_input)?;
    }
    let (calibration, estimates_csv) = match request {
        None => py.detach(|| calibrate_slices(slices, &settings, None))?,
        Some(request) => {
            // Owned: an interrupted search goes on after the arrays may be gone.
            let owned = slices.map(<[f64]>::to_vec);
            crate::interrupt::leaving_behind(py, move |_| {
                calibrate_slices(
                    owned.each_ref().map(Vec::as_slice),
                    &settings,
                    Some(&request),
                )
            })??
        }
    };
    Ok(CalibrationResult {
        calibration,
        estimates_csv,
    })
}
