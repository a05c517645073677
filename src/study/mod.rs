//! A whole study: an ensemble for each case (truth model and accelerometer output), each with
//! its verdicts, the mean error its deterministic part predicts and the accuracy it achieves,
//! and one recorded realization of a consistent case. Numbers only, no formatting.
//!
//! This is the orchestration every command shares; it reports progress through a [`Progress`]
//! it is handed, and knows nothing of terminals or pages.

pub mod analysis;
pub mod correlated;
pub mod drift;
pub mod drive;
pub mod drive3d;
pub mod identify;
pub mod ins;
pub mod noise;

use crate::checks::{self, Budget, Verdicts};
use crate::config::Case;
use crate::ensemble::{Ensemble, EnsembleRun};
use crate::error::FilterError;
use crate::filter::FilterSchedule;
use crate::model::Model;
pub use crate::progress::{Progress, Silent};
use crate::realization::{self, Realization};
use crate::sensitivity::{self, Plan, Sensitivity, SensitivityError};
use crate::state::ErrorState;

pub use analysis::{MeanErrorPrediction, StagedState, max_mean_over_sigma};

/// The samples of the recorded realization that the report keeps, at most about: a run with
/// more is thinned to what its figures can show.
pub const FIGURE_SAMPLES: usize = 20_000;

/// One case's ensemble and what it shows.
#[derive(Clone, Debug)]
pub struct CaseOutcome {
    /// The simulated case.
    pub case: Case,
    /// The statistics and the run time.
    pub run: EnsembleRun,
    /// The checks' verdicts.
    pub verdicts: Verdicts,
    /// Largest |a posteriori mean error| / σ per state over all fixes (σ the filter's).
    pub max_mean_over_sigma: [f64; ErrorState::DIM],
    /// The predicted mean error and how well it explains the measured one.
    pub prediction: MeanErrorPrediction,
    /// Achieved RMS a posteriori error of each state at every fix, (m, m/s, m/s²).
    pub achieved_rms: Vec<[f64; ErrorState::DIM]>,
}

impl CaseOutcome {
    /// The achieved RMS error at the last fix.
    pub fn achieved_rms_final(&self) -> [f64; ErrorState::DIM] {
        *self.achieved_rms.last().expect("at least two fixes")
    }
}

/// Runs `ensemble` and judges it.
pub fn run_case(ensemble: &Ensemble, progress: &mut dyn Progress) -> CaseOutcome {
    let model = ensemble.model();
    progress.start(&model.case().id(), ensemble.partition().realizations);
    let run = ensemble.run(|done| progress.advance(done));
    progress.finish();
    judge_case(model, ensemble.schedule(), run)
}

/// Judges the finished ensemble `run` of `model`: verdicts, predicted mean error, achieved
/// accuracy. Used for a whole run and for merged shards alike.
pub fn judge_case(model: &Model, schedule: &FilterSchedule, run: EnsembleRun) -> CaseOutcome {
    let case = model.case();
    let budget = Budget::study(model.config.checks.false_alarm_rate);
    let verdicts = checks::evaluate(&run.stats, &budget);
    let predicted = analysis::predicted_mean_error(model, schedule);
    CaseOutcome {
        case,
        max_mean_over_sigma: max_mean_over_sigma(&run.stats),
        prediction: analysis::explain_mean_error(predicted, &run.stats, schedule),
        achieved_rms: analysis::achieved_rms(&run.stats),
        run,
        verdicts,
    }
}

/// Everything the report shows.
#[derive(Clone, Debug)]
pub struct Study {
    /// The configured model.
    pub model: Model,
    /// The filter's covariances and gains (the same for every case).
    pub schedule: FilterSchedule,
    /// One outcome per case: [`Case::REPORT`] in order, then the configured case when it is
    /// not one of them.
    pub cases: Vec<CaseOutcome>,
    /// Realization 0 of a consistent case (see [`Study::realization_case`]), at every sample.
    pub realization: Realization,
    /// The case of the recorded realization: the first of (analytic truth, interval means),
    /// (euler truth, point samples) whose checks all pass, else the first of them.
    pub realization_case: Case,
    /// The sensitivity to the assumed statistics, when it was run ([`Study::with_sensitivity`]).
    pub sensitivity: Option<Sensitivity>,
    /// The drifting-bias study, when it was run ([`Study::with_drift`]).
    pub drift: Option<drift::DriftStudy>,
    /// The real drive's calibrations, when they were run ([`Study::with_real_drive`]).
    pub real_drive: Option<Vec<drive::DriveRun>>,
    /// The real drive in three axes, when it was calibrated ([`Study::with_real_drive_3d`]).
    pub real_drive_3d: Option<drive3d::RealDrive3d>,
    /// Noise statistics estimated from simulated drives, when they were run
    /// ([`Study::with_noise`]).
    pub noise: Option<noise::NoiseStudy>,
    /// The white noise's identifiability on two drives, run with [`Study::with_noise`].
    pub white_noise: Option<identify::WhiteNoiseDrives>,
    /// The three-axis study, when it was run ([`Study::with_ins`]).
    pub ins: Option<ins::InsResults>,
}

impl Study {
    /// Runs every case of `model` and records one realization.
    ///
    /// # Errors
    /// [`FilterError`] when the filter's covariance stops being positive definite.
    pub fn run(model: &Model, progress: &mut dyn Progress) -> Result<Self, FilterError> {
        let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
        let mut cases: Vec<Case> = Case::REPORT.to_vec();
        if !cases.contains(&model.case()) {
            cases.push(model.case());
        }
        let cases: Vec<CaseOutcome> = cases
            .into_iter()
            .map(|case| {
                let model = model.with_case(case);
                run_case(&Ensemble::new(&model, &schedule), progress)
            })
            .collect();
        let preferred = [Case::INTERVAL_MEANS, Case::MODEL_WORLD];
        let realization_case = preferred
            .into_iter()
            .find(|c| {
                cases
                    .iter()
                    .any(|o| o.case == *c && o.verdicts.all_passed())
            })
            .unwrap_or(preferred[0]);
        let realization = realization::record_for_figures(
            &model.with_case(realization_case),
            &schedule,
            model.config.ensemble.seed,
            0,
            FIGURE_SAMPLES,
        );
        Ok(Self {
            model: model.clone(),
            schedule,
            cases,
            realization,
            realization_case,
            sensitivity: None,
            drift: None,
            real_drive: None,
            real_drive_3d: None,
            noise: None,
            white_noise: None,
            ins: None,
        })
    }

    /// The study with its sensitivity to the assumed statistics (the configuration's plan).
    ///
    /// # Errors
    /// [`SensitivityError`] when a scaled statistic is out of range or breaks the filter.
    pub fn with_sensitivity(
        mut self,
        progress: &mut dyn Progress,
    ) -> Result<Self, SensitivityError> {
        let config = &self.model.config;
        self.sensitivity = Some(sensitivity::run(config, &Plan::of(config), progress)?);
        Ok(self)
    }

    /// The study with its drifting-bias study ([`drift::run`]), when the configuration can run
    /// [`drift::DRIFT_DURATION_S`] seconds (it keeps its rates and statistics).
    ///
    /// # Errors
    /// [`FilterError`] when a filter's covariance stops being positive definite.
    pub fn with_drift(mut self, progress: &mut dyn Progress) -> Result<Self, FilterError> {
        self.drift = drift::run(&self.model.config, progress)?;
        Ok(self)
    }

    /// The study with the three-axis study of the default three-axis file ([`ins::run`],
    /// [`ins::REPORT_REALIZATIONS`] realizations per ensemble).
    ///
    /// # Errors
    /// [`crate::ins::ensemble::RealizationError`] when a filter's covariance breaks down.
    pub fn with_ins(
        mut self,
        progress: &mut dyn Progress,
    ) -> Result<Self, crate::ins::ensemble::RealizationError> {
        let config = crate::config::ins::InsConfig::default();
        self.ins = Some(ins::run(&config, ins::REPORT_REALIZATIONS, progress)?);
        Ok(self)
    }

    /// The study with the shipped real drive calibrated ([`drive::run`]).
    ///
    /// # Errors
    /// [`crate::calibrate::CalibrateError`] only if the shipped files did not calibrate.
    pub fn with_real_drive(mut self) -> Result<Self, crate::calibrate::CalibrateError> {
        self.real_drive = Some(drive::run()?);
        Ok(self)
    }

    /// The study with the shipped minute calibrated in three axes ([`drive3d::run`]).
    ///
    /// # Errors
    /// [`drive3d::Drive3dError`] only if the shipped files did not calibrate.
    pub fn with_real_drive_3d(mut self) -> Result<Self, drive3d::Drive3dError> {
        self.real_drive_3d = Some(drive3d::run()?);
        Ok(self)
    }

    /// The study with its noise statistics from simulated drives ([`noise::run`], `drives`
    /// drives of the configuration's rates and statistics) and the white noise's
    /// identifiability on two drives ([`identify::run`]).
    ///
    /// # Errors
    /// [`FilterError`] when a filter's covariance is not positive definite.
    pub fn with_noise(
        mut self,
        drives: u64,
        progress: &mut dyn Progress,
    ) -> Result<Self, FilterError> {
        // A study in which no drive could be calibrated has nothing to show.
        self.noise =
            noise::run(&self.model.config, drives, progress)?.filter(|s| !s.estimates.is_empty());
        self.white_noise = identify::run(&self.model.config)?;
        Ok(self)
    }

    /// The outcome of `case`.
    ///
    /// # Panics
    /// When `case` was not run.
    pub fn case(&self, case: Case) -> &CaseOutcome {
        self.cases
            .iter()
            .find(|o| o.case == case)
            .expect("the case was run")
    }
}
