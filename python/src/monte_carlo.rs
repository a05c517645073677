//! `accelcal.ensemble` and `accelcal.simulate`: the model loaded as the command line loads it
//! (`accelcal ensemble`, `accelcal simulate --logs`), the same JSON and the same logs.

use pyo3::prelude::*;
use pyo3::types::PyBytes;

use accelcal::ensemble::{Engine, Ensemble};
use accelcal::error::ConfigError;
use accelcal::filter::FilterSchedule;
use accelcal::logs::write::LogWriter;
use accelcal::model::Model;
use accelcal::{export, simulation, study};

use crate::config::{self, Source};

/// The model of `source` with the seed and the number of realizations set over it, an error in
/// the file pointing at its line as the command line's does (a value set by argument points
/// at none).
fn load_model(
    source: Option<Source>,
    seed: Option<u64>,
    realizations: Option<u64>,
) -> Result<Model, ConfigError> {
    let (text, mut config) = config::load(source)?;
    if let Some(s) = seed {
        config.ensemble.seed = s;
    }
    if let Some(n) = realizations {
        config.ensemble.realizations = n;
    }
    let from_arguments: Vec<&str> = [
        ("ensemble.seed", seed.is_some()),
        ("ensemble.realizations", realizations.is_some()),
    ]
    .into_iter()
    .filter_map(|(field, set)| set.then_some(field))
    .collect();
    Model::new(&config).map_err(|e| match (&text, &e) {
        (Some(t), ConfigError::Invalid { field, .. }) if !from_arguments.contains(field) => {
            t.locate(e)
        }
        _ => e,
    })
}

fn source(kind: Option<&str>, value: Option<String>) -> Option<Source> {
    kind.zip(value).map(|(k, v)| Source::of(k, v))
}

/// The JSON `accelcal ensemble` writes to `--json`, as text. The GIL is released during the
/// run; Ctrl-C stops it between blocks (`crate::interrupt::until_stopped`).
#[pyfunction]
#[pyo3(signature = (config_kind, config_value, realizations, seed, engine))]
pub(crate) fn ensemble_json(
    py: Python<'_>,
    config_kind: Option<&str>,
    config_value: Option<String>,
    realizations: Option<u64>,
    seed: Option<u64>,
    engine: &str,
) -> PyResult<String> {
    let engine = match engine {
        "sample" => Engine::Sample,
        "epoch" => Engine::Epoch,
        other => {
            return Err(crate::bad_input(format!(
                "engine = {other:?}: expected \"sample\" or \"epoch\""
            )));
        }
    };
    let model = load_model(source(config_kind, config_value), seed, realizations)
        .map_err(crate::config_error)?;
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).map_err(crate::bad_input)?;
    crate::interrupt::until_stopped(py, |cancel| {
        // study::run_case with a flag: the workers stop between blocks once Ctrl-C raised it.
        let ensemble = Ensemble::new(&model, &schedule).with_engine(engine);
        let run = ensemble
            .try_run(cancel, |_| {})
            .map_err(|e| e.to_string())?;
        let outcome = study::judge_case(&model, &schedule, run);
        let doc = export::ensemble_doc(&model.config, &schedule, &outcome);
        let mut out = Vec::new();
        export::write_ensemble_json(&mut out, &model.config, &doc)
            .map_err(|e| format!("cannot write the ensemble JSON: {e}"))?;
        String::from_utf8(out).map_err(|e| e.to_string())
    })?
    .map_err(crate::bad_input)
}

/// The three logs `accelcal simulate --logs` writes (accelerometer.csv, gps.csv, truth.csv) for
/// realization `realization`, as bytes.
#[pyfunction]
#[pyo3(signature = (config_kind, config_value, realization, seed))]
pub(crate) fn simulate_logs<'py>(
    py: Python<'py>,
    config_kind: Option<&str>,
    config_value: Option<String>,
    realization: u64,
    seed: Option<u64>,
) -> PyResult<[Bound<'py, PyBytes>; 3]> {
    let model =
        load_model(source(config_kind, config_value), seed, None).map_err(crate::config_error)?;
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).map_err(crate::bad_input)?;
    let logs = py.detach(|| {
        let (mut accel, mut gps, mut truth) = (Vec::new(), Vec::new(), Vec::new());
        let mut writer = LogWriter::new(&model.timeline, &mut accel, &mut gps, &mut truth)?;
        simulation::run_realization(
            &model,
            &schedule,
            model.config.ensemble.seed,
            realization,
            &mut writer,
        );
        writer.finish()?;
        Ok::<_, std::io::Error>([accel, gps, truth])
    });
    let logs = logs.map_err(crate::bad_input)?;
    Ok(logs.map(|bytes| PyBytes::new(py, &bytes)))
}
