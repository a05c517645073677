//! `accelcal.calibrate(imu=…, gnss=…)`: the three-axis calibration of
//! `accelcal calibrate --imu --gnss` from columns. The IMU's columns become the reader's steps
//! (`input::imu_csv::held_steps`) and the GNSS columns its rows
//! (`input::gnss_csv::held_gnss`) with no text in between; the filter runs on them as the
//! command's `--estimate-noise` path runs on the logs it holds (`run::calibrate_held`). Every
//! number equals the command line's on the same data.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use accelcal::calibrate::imu::config::settings_of;
use accelcal::calibrate::imu::noise::{self, ImuKey};
use accelcal::calibrate::imu::run::{Calibrated, calibrate_held};
use accelcal::calibrate::imu::smoother::{Smoothed, smooth};
use accelcal::calibrate::imu::summary::{Summary, summary, write_estimates};
use accelcal::calibrate::imu::{CONSUMER, Settings};
use accelcal::error::ConfigError;
use accelcal::input::gnss_csv::held_gnss;
use accelcal::input::imu_csv::{ImuLayout, ImuSpan, held_steps};
use accelcal::input::records::{GnssRow, ImuStep};
use accelcal::report::RenderError;
use accelcal::report::calibration_imu::render;

use crate::config::Source;

/// The names the logs have in messages and in the summary (`imu_file`, `gnss_file`).
const IMU_NAME: &str = "imu";
const GNSS_NAME: &str = "gnss";

/// A finished three-axis calibration: what `summary.json`, `estimates.csv` and the page hold
/// (plain numbers: any Python thread may use it).
#[pyclass(frozen, module = "accelcal._accelcal")]
pub(crate) struct ImuCalibrationResult {
    page: Page,
    summary: Summary,
    estimates_csv: String,
}

/// The page of a finished run, from its filter records and their smoothing (of any error
/// state: [`accelcal::with_layout!`]), its summary and the command line that reproduces it.
type Page = Box<dyn Fn(&Summary, &str) -> Result<String, RenderError> + Send + Sync>;

#[pymethods]
impl ImuCalibrationResult {
    /// `summary.json`, byte for byte.
    fn summary_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.summary)
            .map(|json| json + "\n")
            .map_err(crate::bad_input)
    }

    /// `estimates.csv` (one row per fix), byte for byte.
    fn estimates_csv(&self) -> &str {
        &self.estimates_csv
    }

    /// The page `index.html`, with `command` as the line that reproduces it.
    fn html(&self, command: &str) -> PyResult<String> {
        (self.page)(&self.summary, command).map_err(crate::bad_input)
    }
}

/// The settings of `source` as `accelcal calibrate --imu --config` reads them; the consumer
/// defaults without one.
fn settings(source: Option<Source>) -> Result<Settings, ConfigError> {
    match source {
        Some(s) => settings_of(&s.read()?),
        None => Ok(CONSUMER),
    }
}

/// The keys `--estimate-noise [--estimate KEYS]` names: `None` for no estimation, the default
/// keys for an empty list.
fn keys(names: Option<Vec<String>>, confidence: f64) -> PyResult<Option<Vec<ImuKey>>> {
    let Some(names) = names else {
        return Ok(None);
    };
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(crate::bad_input(format!(
            "confidence = {confidence}: expected a number strictly between 0 and 1"
        )));
    }
    if names.is_empty() {
        return Ok(Some(ImuKey::DEFAULT.to_vec()));
    }
    names
        .iter()
        .map(|n| {
            ImuKey::parse(n).ok_or_else(|| {
                crate::bad_input(format!(
                    "estimate_noise: {n:?} is not a statistic the three-axis likelihood \
                     searches; expected one of {}",
                    ImuKey::ALL.map(ImuKey::name).join(", ")
                ))
            })
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// The logs held: the IMU's steps, span and layout, and the GNSS rows.
struct Held {
    steps: Vec<ImuStep>,
    span: ImuSpan,
    layout: ImuLayout,
    rows: Vec<GnssRow>,
}

/// The calibration of the held logs, with the noise estimate of `keys` first when given, as
/// `accelcal calibrate --imu --gnss [--estimate-noise]` computes it.
fn calibrate(
    held: &Held,
    settings: &Settings,
    keys: Option<&[ImuKey]>,
    confidence: f64,
    cancel: &accelcal::progress::Cancel,
) -> PyResult<ImuCalibrationResult> {
    let estimate = match keys {
        None => None,
        Some(keys) => Some(
            noise::estimate_cancellable(
                &held.rows,
                &held.steps,
                &held.span,
                (settings, keys, confidence),
                cancel,
            )
            .map_err(|_| crate::bad_input("interrupted"))?
            .ok_or_else(|| {
                crate::bad_input(
                    "the likelihood of the drive is not finite at the configured statistics: \
                         the filter cannot start from them",
                )
            })?,
        ),
    };
    let settings = estimate.as_ref().map_or(settings, |e| &e.settings);
    let (page, mut summary, estimates) = accelcal::with_layout!(settings.layout(), N => {
        let (c, s, sm, e) = finished::<N>(held, settings)?;
        let page: Page = Box::new(move |s: &Summary, command: &str| render(&c, s, &sm, command));
        (page, s, e)
    });
    summary.noise_estimate = estimate;
    Ok(ImuCalibrationResult {
        page,
        summary,
        estimates_csv: String::from_utf8(estimates).map_err(crate::bad_input)?,
    })
}

/// The held logs calibrated by a filter of `N` error states: the records, the summary, the
/// smoothing and `estimates.csv`'s bytes.
#[allow(clippy::type_complexity)]
fn finished<const N: usize>(
    held: &Held,
    settings: &Settings,
) -> PyResult<(Calibrated<N>, Summary, Vec<Smoothed<N>>, Vec<u8>)> {
    let calibrated = calibrate_held::<N>(
        &held.rows,
        (&held.steps, held.span, held.layout),
        settings,
        GNSS_NAME,
    )
    .map_err(crate::bad_input)?;
    let summary = summary(&calibrated, settings, IMU_NAME);
    let smoothed = smooth(&calibrated.records);
    let mut estimates = Vec::new();
    write_estimates(&calibrated, &smoothed, &mut estimates).map_err(crate::bad_input)?;
    Ok((calibrated, summary, smoothed, estimates))
}

/// The slices of `arrays` (float64 and contiguous: the Python layer converts once).
fn slices<'a, const N: usize>(
    arrays: &'a [PyReadonlyArray1<'_, f64>; N],
) -> PyResult<[&'a [f64]; N]> {
    let mut out: [&[f64]; N] = [&[]; N];
    for (s, a) in out.iter_mut().zip(arrays) {
        *s = a.as_slice().map_err(crate::bad_input)?;
    }
    Ok(out)
}

/// The three-axis calibration of the IMU's columns (`imu_t` s and the six of `layout`:
/// "rates" ax, ay, az m/s², gx, gy, gz rad/s; "increments" dvx, dvy, dvz m/s, dthx, dthy,
/// dthz rad) with the GNSS fixes' columns (`gnss_required`: t s, lat °, lon °, height m;
/// `gnss_optional`: the nine optional columns, each given or `None`, NaN where not measured).
/// `estimate` as `--estimate-noise [--estimate KEYS]`. The columns are read in place to build
/// the steps and the rows, the GIL released; the filter then runs on a thread of its own that
/// Ctrl-C leaves behind (`crate::interrupt::leaving_behind`); the likelihood's search polls its
/// flag at every evaluation and ends within one, the filter's runs poll none.
#[pyfunction]
#[pyo3(signature = (imu_t, imu_columns, layout, gnss_required, gnss_optional, config_kind, config_value, estimate, confidence))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn calibrate_imu_arrays(
    py: Python<'_>,
    imu_t: PyReadonlyArray1<'_, f64>,
    imu_columns: [PyReadonlyArray1<'_, f64>; 6],
    layout: &str,
    gnss_required: [PyReadonlyArray1<'_, f64>; 4],
    gnss_optional: [Option<PyReadonlyArray1<'_, f64>>; 9],
    config_kind: Option<&str>,
    config_value: Option<String>,
    estimate: Option<Vec<String>>,
    confidence: f64,
) -> PyResult<ImuCalibrationResult> {
    let layout = match layout {
        "rates" => ImuLayout::Rates,
        "increments" => ImuLayout::Increments,
        other => {
            return Err(crate::bad_input(format!(
                "layout = {other:?}: expected \"rates\" or \"increments\""
            )));
        }
    };
    let source = config_kind.zip(config_value).map(|(k, v)| Source::of(k, v));
    let settings = settings(source).map_err(crate::config_error)?;
    let keys = keys(estimate, confidence)?;
    if keys.is_some() {
        noise::check_estimable(&settings).map_err(crate::config_error)?;
    }
    let t = imu_t.as_slice().map_err(crate::bad_input)?;
    let columns = slices(&imu_columns)?;
    let required = slices(&gnss_required)?;
    let mut optional: [Option<&[f64]>; 9] = [None; 9];
    for (o, a) in optional.iter_mut().zip(&gnss_optional) {
        *o = a
            .as_ref()
            .map(|a| a.as_slice().map_err(crate::bad_input))
            .transpose()?;
    }
    let axes = settings.axes;
    let held = py.detach(|| {
        let rows = held_gnss(GNSS_NAME, required, optional).map_err(crate::bad_input)?;
        let (steps, span, layout) =
            held_steps(IMU_NAME, t, columns, layout, axes).map_err(crate::bad_input)?;
        Ok::<_, PyErr>(Held {
            steps,
            span,
            layout,
            rows,
        })
    })?;
    crate::interrupt::leaving_behind(py, move |cancel| {
        calibrate(&held, &settings, keys.as_deref(), confidence, cancel)
    })?
}
