//! What the report quotes beyond the verdicts: the mean error the truth's deterministic
//! discrepancy predicts, and the accuracy the calibration actually achieves.

use serde::Serialize;

use crate::ensemble::EnsembleStats;
use crate::filter::{FilterSchedule, FixCovariance, Stage};
use crate::model::Model;
use crate::simulation::{FixState, Observer, run_noise_free};
use crate::state::{ErrorState, StateVector};

/// A value of every state at one fix, [a priori, a posteriori] (m, m/s, m/s²).
pub type StagedState = [[f64; ErrorState::DIM]; Stage::ALL.len()];

/// The expected error of every realization, from one noise-free pass, and how well it explains
/// the ensemble's mean error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeanErrorPrediction {
    /// Predicted mean error m at every fix, [a priori, a posteriori], (m, m/s, m/s²).
    pub fixes: Vec<StagedState>,
    /// The worst |e_ave − m| / (σ/√N) over fixes, stages and states.
    pub worst_se: f64,
    /// Predicted average a posteriori NEES at the last fix, N + mᵀP⁻¹m (N the number of states).
    pub predicted_nees_final: f64,
    /// Measured average a posteriori NEES at the last fix.
    pub measured_nees_final: f64,
}

/// Collects the error e = δx − δx̂ at every fix.
struct Errors(Vec<StagedState>);

impl Observer for Errors {
    fn fix(&mut self, f: &FixState) {
        self.0
            .push([(f.delta_x - f.prior).into(), (f.delta_x - f.post).into()]);
    }
}

/// The mean error every realization of `model` shares: the filter's response to the truth's
/// deterministic discrepancy from eq. (5), computed by one noise-free pass (the system is
/// linear, so the expected error is the error of the expected inputs).
pub fn predicted_mean_error(model: &Model, schedule: &FilterSchedule) -> Vec<StagedState> {
    let mut errors = Errors(Vec::with_capacity(model.timeline.fixes()));
    run_noise_free(model, schedule, &mut errors);
    errors.0
}

fn stage_index(stage: Stage) -> usize {
    match stage {
        Stage::Prior => 0,
        Stage::Posterior => 1,
    }
}

/// Compares the predicted mean error with the measured one.
pub fn explain_mean_error(
    predicted: Vec<StagedState>,
    stats: &EnsembleStats,
    schedule: &FilterSchedule,
) -> MeanErrorPrediction {
    let n = stats.realizations as f64;
    let mut worst_se: f64 = 0.0;
    for (m, fix) in predicted.iter().zip(&stats.fixes) {
        for stage in Stage::ALL {
            let s = fix.stage(stage);
            for (k, predicted) in m[stage_index(stage)].iter().enumerate() {
                let se = (s.filter_cov[k][k] / n).sqrt();
                let d = (s.mean_error[k] - predicted).abs() / se;
                // A non-finite difference is the worst possible explanation.
                worst_se = if d.is_nan() {
                    f64::INFINITY
                } else {
                    worst_se.max(d)
                };
            }
        }
    }
    let last: &FixCovariance = schedule.fixes.last().expect("at least two fixes");
    let m = StateVector::from(
        predicted.last().expect("at least two fixes")[stage_index(Stage::Posterior)],
    );
    MeanErrorPrediction {
        predicted_nees_final: ErrorState::DIM as f64 + m.dot(&(last.p_post_inv * m)),
        measured_nees_final: stats
            .fixes
            .last()
            .expect("at least two fixes")
            .post
            .nees_avg,
        fixes: predicted,
        worst_se,
    }
}

/// The achieved RMS error √(mean² + variance) of each state after every fix: the actual a
/// posteriori error over the ensemble, (m, m/s, m/s²).
///
/// # Formula
/// RMS_k = √((1/N) Σ e_k²) = √(e_ave,k² + (N − 1)/N · P_ave,kk).
pub fn achieved_rms(stats: &EnsembleStats) -> Vec<[f64; ErrorState::DIM]> {
    let n = stats.realizations as f64;
    stats
        .fixes
        .iter()
        .map(|f| {
            let s = &f.post;
            std::array::from_fn(|k| {
                (s.mean_error[k].powi(2) + s.ensemble_cov[k][k] * (n - 1.0) / n).sqrt()
            })
        })
        .collect()
}

/// Largest |a posteriori mean error| / σ per state over all fixes.
pub fn max_mean_over_sigma(stats: &EnsembleStats) -> [f64; ErrorState::DIM] {
    std::array::from_fn(|k| {
        stats
            .fixes
            .iter()
            .map(|f| (f.post.mean_error[k] / f.post.filter_cov[k][k].sqrt()).abs())
            .fold(0.0, f64::max)
    })
}
