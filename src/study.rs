//! A whole study: one recorded realization and an ensemble for each truth model, with verdicts.
//! This is what the report presents; it holds numbers only, no formatting.

use anyhow::Result;

use crate::app::{ensemble_with_verdicts, schedule_of};
use crate::checks::Verdicts;
use crate::config::TruthModel;
use crate::ensemble::EnsembleRun;
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::realization::{self, Realization};

/// One ensemble's outcome.
#[derive(Clone, Debug)]
pub struct EnsembleOutcome {
    pub truth: TruthModel,
    pub run: EnsembleRun,
    pub verdicts: Verdicts,
}

/// Everything the report shows.
#[derive(Clone, Debug)]
pub struct Study {
    /// The configured model (its `truth` is the configured truth model).
    pub model: Model,
    /// The filter's covariances and gains (the same for every truth model).
    pub schedule: FilterSchedule,
    /// Realization 0 of the configured seed and truth model, recorded at every sample.
    pub realization: Realization,
    /// One ensemble per truth model, in [`TruthModel::ALL`] order.
    pub ensembles: Vec<EnsembleOutcome>,
}

impl Study {
    /// Runs the realization and both ensembles of `model`.
    pub fn run(model: &Model, quiet: bool) -> Result<Self> {
        let schedule = schedule_of(model)?;
        let realization = realization::record(model, &schedule, model.config.ensemble.seed, 0);
        let ensembles = TruthModel::ALL
            .iter()
            .map(|&truth| {
                let m = model.with_truth(truth);
                let (run, verdicts) = ensemble_with_verdicts(&m, &schedule, quiet);
                EnsembleOutcome {
                    truth,
                    run,
                    verdicts,
                }
            })
            .collect();
        Ok(Self {
            model: model.clone(),
            schedule,
            realization,
            ensembles,
        })
    }

    /// The ensemble of truth model `truth`.
    pub fn ensemble(&self, truth: TruthModel) -> &EnsembleOutcome {
        self.ensembles
            .iter()
            .find(|e| e.truth == truth)
            .expect("every truth model is run")
    }

    /// The ensemble of the configured truth model.
    pub fn primary(&self) -> &EnsembleOutcome {
        self.ensemble(self.model.truth)
    }
}
