//! Shared helpers of the integration tests.
#![allow(dead_code)]

pub mod plain;

use accelcal::checks::Verdicts;
use accelcal::config::{Config, TruthModel};
use accelcal::filter::FilterSchedule;
use accelcal::model::Model;

/// Model and schedule of `config`.
pub fn model_of(config: &Config) -> (Model, FilterSchedule) {
    let model = Model::new(config).expect("valid configuration");
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
    (model, schedule)
}

/// Runs the ensemble of `config` with `truth` and evaluates its checks.
pub fn verdicts_of(config: &Config, truth: TruthModel) -> Verdicts {
    let (model, schedule) = model_of(config);
    accelcal::study::run_case(
        &model.with_truth(truth),
        &schedule,
        &mut accelcal::study::Silent,
    )
    .verdicts
}

/// Path of the built binary.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_accelcal")
}
