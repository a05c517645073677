//! Exporters: results to bytes (JSON, CSV). They open nothing: a document is built whole or
//! serialized into any writer the caller gives (a file, standard output, a buffer in tests). This
//! is an edge of the library: the typed verdicts become the stable field names of the data
//! contract.

pub mod ins;
pub mod noise;
pub mod sensitivity;

use serde::Serialize;

use crate::checks::{Check, CheckId, ResidualPair};
use crate::config::{AccelerometerOutput, Config, TruthModel};
use crate::ensemble::FixStats;
use crate::filter::FilterSchedule;
use crate::realization::Realization;
use crate::state::{ErrorState, Variable};
use crate::study::{CaseOutcome, StagedState, Study};

// `FinalSigma` and the columns of `realization_csv` name the three states one by one.
const _: () = assert!(ErrorState::DIM == 3);

/// A value per state at the last fix: the filter's a posteriori σ, or the achieved RMS error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FinalSigma {
    /// Position, m.
    pub position_m: f64,
    /// Velocity, m/s.
    pub velocity_m_s: f64,
    /// Bias, m/s².
    pub bias_m_s2: f64,
}

impl From<[f64; ErrorState::DIM]> for FinalSigma {
    fn from(x: [f64; ErrorState::DIM]) -> Self {
        Self {
            position_m: x[ErrorState::POSITION],
            velocity_m_s: x[ErrorState::VELOCITY],
            bias_m_s2: x[ErrorState::BIAS],
        }
    }
}

/// One check as written to JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckRecord {
    /// Stable identifier, e.g. `covariance_match`.
    pub id: CheckId,
    /// The hypothesis a consistent filter satisfies.
    pub hypothesis: &'static str,
    /// What each member computes.
    pub statistic: &'static str,
    /// "normal" (scores) or "chisquared" (scaled χ² statistics).
    pub kind: &'static str,
    /// Distinct members tested, M.
    pub members: usize,
    /// This check's share of the study-wide false-alarm rate.
    pub false_alarm_rate: f64,
    /// The worst member's statistic: |z| for normal scores, the value for χ² statistics; null
    /// when there are no members.
    pub worst: f64,
    /// The end of the band on the worst member's side.
    pub bound: f64,
    /// Acceptance band of every member, lower end.
    pub lower: f64,
    /// Acceptance band of every member, upper end.
    pub upper: f64,
    /// True only for the verdict "pass".
    pub passed: bool,
    /// "pass", "fail" or "untestable".
    pub verdict: &'static str,
    /// The smallest N at which the check can fail.
    pub min_realizations: u64,
    /// Members outside the band.
    pub failures: usize,
    /// Time of the worst member's fix, s.
    pub worst_time_s: f64,
    /// The worst member in words.
    pub worst_member: String,
    /// When the check starts to fail: the time of the earliest fix with a member outside, s;
    /// null when none is.
    pub first_failure_time_s: Option<f64>,
    /// That member in words; null when none is outside.
    pub first_failure_member: Option<String>,
}

impl CheckRecord {
    /// The record of `c`; `fix_times_s` name the members' fixes.
    pub fn new(c: &Check, fix_times_s: &[f64]) -> Self {
        Self::with_names(
            c,
            fix_times_s,
            &ErrorState::VARIABLES,
            &ErrorState::MEASURED,
        )
    }

    /// The record of `c` for a model whose states and measurements are `states` and
    /// `measurements`.
    pub fn with_names(
        c: &Check,
        fix_times_s: &[f64],
        states: &[Variable],
        measurements: &[Variable],
    ) -> Self {
        let worst = c.worst.map(|w| w.member);
        Self {
            id: c.id,
            hypothesis: c.id.hypothesis(),
            statistic: c.id.statistic(),
            kind: if c.is_normal() {
                "normal"
            } else {
                "chisquared"
            },
            members: c.members,
            false_alarm_rate: c.false_alarm_rate,
            worst: c.worst_value(),
            bound: c.bound(),
            lower: c.lower,
            upper: c.upper,
            passed: c.passed(),
            verdict: c.verdict.name(),
            min_realizations: c.min_realizations,
            failures: c.failures,
            worst_time_s: worst.map_or(f64::NAN, |m| fix_times_s[m.fix()]),
            worst_member: worst.map_or_else(
                || "no member could be tested".to_string(),
                |m| m.describe_with(fix_times_s, states, measurements),
            ),
            first_failure_time_s: c.first_failure.map(|m| fix_times_s[m.fix()]),
            first_failure_member: c
                .first_failure
                .map(|m| m.describe_with(fix_times_s, states, measurements)),
        }
    }
}

/// The headline of one ensemble: the data contract's `"summary"`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Truth model of the ensemble.
    pub truth: TruthModel,
    /// What the accelerometer reports: "sample" or "interval_mean".
    pub accelerometer_output: AccelerometerOutput,
    /// Number of realizations N.
    pub realizations: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// The engine that simulated the realizations: "sample" or "epoch".
    pub engine: crate::ensemble::Engine,
    /// The filter's a posteriori σ at the last fix: the accuracy it claims.
    pub final_sigma: FinalSigma,
    /// The achieved RMS a posteriori error at the last fix, √(mean² + variance) over the
    /// ensemble: the accuracy the calibration reaches.
    pub achieved_rms: FinalSigma,
    /// How well the mean error predicted from the truth's deterministic part explains the
    /// measured one.
    pub mean_error_prediction: PredictionSummary,
    /// The study-wide false-alarm rate: the probability that a consistent filter gets any
    /// "fail" over all checks.
    pub false_alarm_rate: f64,
    /// True only when every check is "pass".
    pub all_passed: bool,
    /// Every check, in catalogue order.
    pub checks: Vec<CheckRecord>,
    /// Which pairs of fixes the residual whiteness check tested.
    pub residual_pairs: ResidualPairs,
    /// Timing: varies between runs.
    pub realizations_per_s: f64,
    /// Timing: varies between runs.
    pub elapsed_s: f64,
}

/// Which pairs of fixes the residual whiteness check tested: every pair, or the pairs at most
/// `max_lag` fixes apart (long runs, see `checks.residual_max_lag`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualPairs {
    /// True when every pair t_m < t_i was tested.
    pub all_pairs: bool,
    /// The largest lag tested, in fixes.
    pub max_lag: usize,
}

/// The summary of a [`MeanErrorPrediction`](crate::study::analysis::MeanErrorPrediction).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PredictionSummary {
    /// The worst |e_ave − m_pred| / (σ/√N) over fixes, stages and states.
    pub worst_se: f64,
    /// Predicted average a posteriori NEES at the last fix, 3 + m_predᵀ P⁻¹ m_pred.
    pub predicted_nees_final: f64,
    /// Measured average a posteriori NEES at the last fix.
    pub measured_nees_final: f64,
}

/// One ensemble's results as written to JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnsembleDoc<'a> {
    /// The headline.
    pub summary: Summary,
    /// The statement's single residual pair.
    pub residual_pair: &'a ResidualPair,
    /// Largest |z| of the residual whiteness members at each lag t_i − t_m.
    pub residual_whiteness_by_lag: Vec<LagWorst>,
    /// The ensemble statistics at every fix.
    pub fixes: &'a [FixStats],
    /// The predicted mean error at every fix, [a priori, a posteriori].
    pub predicted_mean_error: &'a [StagedState],
    /// The achieved RMS a posteriori error at every fix.
    pub achieved_rms: &'a [[f64; ErrorState::DIM]],
}

/// Worst normalized residual correlation at one lag.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LagWorst {
    /// The lag t_i − t_m, s.
    pub lag_s: f64,
    /// The largest |z| over the pairs at this lag.
    pub max_abs_z: f64,
}

/// Builds the JSON document of one case's ensemble.
pub fn ensemble_doc<'a>(
    config: &Config,
    schedule: &FilterSchedule,
    outcome: &'a CaseOutcome,
) -> EnsembleDoc<'a> {
    let last = schedule.fixes.last().expect("at least two fixes");
    let (run, verdicts) = (&outcome.run, &outcome.verdicts);
    let stats = &run.stats;
    let fix_times_s: Vec<f64> = stats.fixes.iter().map(|f| f.time_s).collect();
    let n = stats.fixes.len();
    let max_lag = stats.residual_layout.max_lag().unwrap_or(n - 1);
    let residual_whiteness_by_lag = (1..=max_lag.min(n - 1))
        .map(|lag| {
            let max_abs_z = (lag..n)
                .flat_map(|i| {
                    let m = i - lag;
                    // Residual component c of fix i is row M·i + c of the residual layout.
                    const M: usize = ErrorState::MEAS;
                    (0..M * M).map(move |c| {
                        crate::checks::residual_z(stats, M * i + c / M, M * m + c % M).abs()
                    })
                })
                .fold(0.0, f64::max);
            LagWorst {
                lag_s: stats.fixes[lag].time_s - stats.fixes[0].time_s,
                max_abs_z,
            }
        })
        .collect();
    EnsembleDoc {
        summary: Summary {
            truth: outcome.case.truth,
            accelerometer_output: outcome.case.output,
            realizations: stats.realizations,
            seed: config.ensemble.seed,
            engine: run.engine,
            final_sigma: FinalSigma::from(std::array::from_fn(|k| last.p_post[(k, k)].sqrt())),
            achieved_rms: FinalSigma::from(outcome.achieved_rms_final()),
            mean_error_prediction: PredictionSummary {
                worst_se: outcome.prediction.worst_se,
                predicted_nees_final: outcome.prediction.predicted_nees_final,
                measured_nees_final: outcome.prediction.measured_nees_final,
            },
            false_alarm_rate: verdicts.false_alarm_rate,
            all_passed: verdicts.all_passed(),
            checks: verdicts
                .checks
                .iter()
                .map(|c| CheckRecord::new(c, &fix_times_s))
                .collect(),
            residual_pairs: ResidualPairs {
                all_pairs: stats.residual_layout.max_lag().is_none(),
                max_lag: stats.residual_layout.max_lag().unwrap_or(n - 1),
            },
            realizations_per_s: run.realizations_per_s(),
            elapsed_s: run.elapsed_s,
        },
        residual_pair: &verdicts.residual_pair,
        residual_whiteness_by_lag,
        fixes: &stats.fixes,
        predicted_mean_error: &outcome.prediction.fixes,
        achieved_rms: &outcome.achieved_rms,
    }
}

/// The `accelcal ensemble` output: version, configuration and the ensemble.
#[derive(Serialize)]
struct EnsembleFile<'a> {
    accelcal_version: &'static str,
    config: &'a Config,
    #[serde(flatten)]
    ensemble: &'a EnsembleDoc<'a>,
}

/// Serializes the `accelcal ensemble` output into `w` as it goes: the text of every fix is
/// written and dropped, never held whole (at 4·10⁵ fixes it is 1.6 GB).
///
/// # Errors
/// The writer's error, unchanged (the document itself always serializes: non-finite numbers
/// are written as `null`).
pub fn write_ensemble_json(
    w: impl std::io::Write,
    config: &Config,
    doc: &EnsembleDoc<'_>,
) -> std::io::Result<()> {
    let file = EnsembleFile {
        accelcal_version: env!("CARGO_PKG_VERSION"),
        config,
        ensemble: doc,
    };
    serde_json::to_writer_pretty(w, &file).map_err(std::io::Error::from)
}

/// One realization at every accelerometer sample, as CSV with a header row.
pub fn realization_csv(r: &Realization, fix_times_s: &[f64]) -> String {
    let mut out = String::from(
        "t_s,accel_true_m_s2,p_true_m,v_true_m_s,p_computed_m,v_computed_m_s,\
         dp_true_m,dv_true_m_s,bias_true_m_s2,dp_est_m,dv_est_m_s,bias_est_m_s2,\
         sigma_p_m,sigma_v_m_s,sigma_b_m_s2,cov_pv_m2_s,cov_pb_m2_s2,cov_vb_m2_s3,gps_fix\n",
    );
    let (dp, dv, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
    let mut next_fix = fix_times_s.iter().peekable();
    for s in &r.samples {
        let fix = match next_fix.peek() {
            Some(&&t) if (t - s.t_s).abs() < 1e-9 => {
                next_fix.next();
                1
            }
            _ => 0,
        };
        let v = [
            s.t_s,
            s.accel_m_s2,
            s.truth_p_m,
            s.truth_v_m_s,
            s.computed_p_m,
            s.computed_v_m_s,
            s.delta_x[dp],
            s.delta_x[dv],
            s.delta_x[b],
            s.estimate[dp],
            s.estimate[dv],
            s.estimate[b],
            s.sigma[dp],
            s.sigma[dv],
            s.sigma[b],
            s.cov[dp][dv],
            s.cov[dp][b],
            s.cov[dv][b],
        ];
        for x in v {
            out.push_str(&format!("{x:.12e},"));
        }
        out.push_str(&format!("{fix}\n"));
    }
    out
}

/// The case a record belongs to.
#[derive(Serialize)]
struct CaseRecord {
    truth: TruthModel,
    accelerometer_output: AccelerometerOutput,
}

/// The report's `data.json`: configuration, the realization at the GPS fixes, every case's
/// ensemble.
#[derive(Serialize)]
struct ReportData<'a> {
    accelcal_version: &'static str,
    config: &'a Config,
    /// The configured truth model.
    primary_truth: TruthModel,
    /// The case of the recorded realization.
    realization_case: CaseRecord,
    realization: &'a Realization,
    /// One per case, in the report's order.
    ensembles: Vec<EnsembleDoc<'a>>,
}

/// The report's data file without the records of its sections, and whether it is indented:
/// the default run's is, a long run's is compact (a third of the size). The report appends each
/// section's record (`report::data_json`).
pub fn report_data_head(study: &Study) -> (String, bool) {
    let ensembles = study
        .cases
        .iter()
        .map(|o| ensemble_doc(&study.model.config, &study.schedule, o))
        .collect();
    let data = ReportData {
        accelcal_version: env!("CARGO_PKG_VERSION"),
        config: &study.model.config,
        primary_truth: study.model.truth(),
        realization_case: CaseRecord {
            truth: study.realization_case.truth,
            accelerometer_output: study.realization_case.output,
        },
        realization: &study.realization,
        ensembles,
    };
    let pretty = study.model.timeline.fixes() <= crate::model::ALL_PAIRS_MAX_FIXES;
    if pretty {
        serde_json::to_string_pretty(&data)
    } else {
        serde_json::to_string(&data)
    }
    .map(|text| (text, pretty))
    .expect("finite numbers serialize")
}
