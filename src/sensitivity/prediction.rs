//! The predictions of one statistic and factor, without simulation: the exact actual
//! covariance, the closed-form bounds on each check's detection and the sampled ensembles.

use super::{AssumedStatistic, Plan, actual_covariance, covariance, detection, sampler};
use super::{SAMPLED, SensitivityCase, SensitivityError, case_seed, mistuned, sigma};
use crate::checks::{Budget, CheckId};
use crate::config::Config;

/// What the predictions of every case share.
pub(super) struct Predictions<'a> {
    /// The model-exact world the filters are mistuned in.
    pub world: &'a Config,
    /// What runs.
    pub plan: &'a Plan,
    /// The checks' false-alarm budget.
    pub budget: &'a Budget,
    /// Sampled ensembles per case (0: none).
    pub draws: u64,
    /// The study's seed.
    pub seed: u64,
}

impl Predictions<'_> {
    /// The exact and sampled predictions for `parameter` × `factor`, without simulation.
    pub(super) fn case(
        &self,
        parameter: AssumedStatistic,
        factor: f64,
    ) -> Result<SensitivityCase, SensitivityError> {
        let (plan, budget, draws) = (self.plan, self.budget, self.draws);
        let (model, schedule) = mistuned(self.world, parameter, factor)?;
        let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
        let (last_fix, last_actual) = (
            schedule.fixes.last().expect("fixes"),
            actual.last().expect("fixes"),
        );
        let bounds = CheckId::ALL
            .iter()
            .map(|&id| detection::predicted(id, &schedule, &actual, plan.realizations, budget))
            .collect();
        let predicted = if draws > 0 {
            sampler::Sampler::new(
                &model.timeline,
                &schedule,
                &model.truth_stats,
                plan.realizations,
                model.residual_pair,
            )
            .detection(
                &schedule,
                budget,
                draws,
                case_seed(self.seed, SAMPLED, parameter, factor),
            )
        } else {
            vec![None; CheckId::ALL.len()]
        };
        Ok(SensitivityCase {
            parameter,
            factor,
            claimed_sigma_final: sigma(&last_fix.p_post),
            actual_sigma_final: sigma(&last_actual.post),
            expected_nees_final: covariance::weights(&last_fix.p_post_inv, &last_actual.post).0,
            expected_nis_final: covariance::weights(&last_fix.s_inv, &last_actual.innovation).0,
            predicted,
            draws,
            bounds,
            ensembles: plan.ensembles,
            detected: None,
        })
    }
}
