//! The sensitivity study as JSON: the data contract of `accelcal sensitivity --json` and of
//! data.json's `sensitivity`.

use std::collections::BTreeMap;

use serde::Serialize;

use super::FinalSigma;
use crate::checks::CheckId;
use crate::sensitivity::Sensitivity;

/// One statistic at one factor.
#[derive(Clone, Debug, Serialize)]
pub struct CaseRecord {
    /// The `[filter]` key varied.
    pub parameter: &'static str,
    /// The factor on its standard deviation.
    pub factor: f64,
    /// The filter's σ at the last fix.
    pub claimed_sigma_final: FinalSigma,
    /// The actual error's σ at the last fix.
    pub actual_sigma_final: FinalSigma,
    /// tr(P⁻¹·P_actual) at the last fix.
    pub expected_nees_final: f64,
    /// tr(S⁻¹·S_actual) at the last fix.
    pub expected_nis_final: f64,
    /// Probability that each check fails: predicted from sampled ensembles where the sums carry
    /// the check, else measured by the Monte Carlo, else null.
    pub detection: BTreeMap<&'static str, Option<f64>>,
    /// How each detection probability was obtained: "sampled_sufficient_statistics",
    /// "monte_carlo", or null.
    pub detection_method: BTreeMap<&'static str, Option<&'static str>>,
    /// Sampled ensembles behind each "sampled_sufficient_statistics" probability.
    pub detection_draws: u64,
    /// Exact bounds [largest member, sum of members] on the detection probability, from the
    /// members' closed-form distributions (mean error, variance, NEES, NIS).
    pub detection_bounds: BTreeMap<&'static str, [f64; 2]>,
    /// The Monte Carlo measurement.
    pub monte_carlo: MonteCarloRecord,
}

/// The Monte Carlo part of a [`CaseRecord`].
#[derive(Clone, Debug, Serialize)]
pub struct MonteCarloRecord {
    /// Realizations per ensemble.
    pub realizations: u64,
    /// Independent ensembles.
    pub ensembles: u64,
    /// The engine that simulated them: "sample" or "epoch".
    pub engine: &'static str,
    /// Fraction of the ensembles in which each check failed; null when none ran.
    pub detected: Option<BTreeMap<&'static str, f64>>,
}

/// The whole study as written to JSON.
#[derive(Clone, Debug, Serialize)]
pub struct SensitivityRecord {
    /// The study-wide false-alarm rate of the checks.
    pub false_alarm_rate: f64,
    /// The factors on the standard deviations.
    pub factors: Vec<f64>,
    /// The filter's σ at the last fix with the configured statistics.
    pub tuned_sigma_final: FinalSigma,
    /// One per statistic and factor.
    pub cases: Vec<CaseRecord>,
}

/// The record of `s`.
pub fn record(s: &Sensitivity) -> SensitivityRecord {
    SensitivityRecord {
        false_alarm_rate: s.false_alarm_rate,
        factors: s.plan.factors.clone(),
        tuned_sigma_final: FinalSigma::from(s.tuned_sigma_final),
        cases: s
            .cases
            .iter()
            .map(|c| CaseRecord {
                parameter: c.parameter.name(),
                factor: c.factor,
                claimed_sigma_final: FinalSigma::from(c.claimed_sigma_final),
                actual_sigma_final: FinalSigma::from(c.actual_sigma_final),
                expected_nees_final: c.expected_nees_final,
                expected_nis_final: c.expected_nis_final,
                detection: CheckId::ALL
                    .iter()
                    .map(|&id| (id.name(), c.detection(id)))
                    .collect(),
                detection_method: CheckId::ALL
                    .iter()
                    .map(|&id| {
                        let method = if c.predicted[id.index()].is_some() {
                            Some("sampled_sufficient_statistics")
                        } else {
                            c.detected.as_ref().map(|_| "monte_carlo")
                        };
                        (id.name(), method)
                    })
                    .collect(),
                detection_draws: c.draws,
                detection_bounds: CheckId::ALL
                    .iter()
                    .filter_map(|&id| c.bounds[id.index()].map(|d| (id.name(), [d.lower, d.upper])))
                    .collect(),
                monte_carlo: MonteCarloRecord {
                    realizations: s.plan.realizations,
                    ensembles: c.ensembles,
                    engine: s.plan.engine.name(),
                    detected: c.detected.as_ref().map(|d| {
                        CheckId::ALL
                            .iter()
                            .map(|&id| (id.name(), d[id.index()]))
                            .collect()
                    }),
                },
            })
            .collect(),
    }
}

/// Serializes the `accelcal sensitivity` output into `w` as it goes.
///
/// # Errors
/// The writer's error, unchanged (the record itself always serializes: non-finite numbers are
/// written as `null`).
pub fn write_sensitivity_json(w: impl std::io::Write, s: &Sensitivity) -> std::io::Result<()> {
    serde_json::to_writer_pretty(w, &record(s)).map_err(std::io::Error::from)
}
