//! Exporters: results to bytes. They do no IO, so tests call them directly.

use serde::{Serialize, Serializer};

use crate::checks::{Check, ResidualPair, Verdicts};
use crate::config::{Config, TruthModel};
use crate::ensemble::{EnsembleRun, FixStats};
use crate::filter::FilterSchedule;
use crate::realization::Realization;

/// Serializes a matrix with NaN entries as `null` (JSON has no NaN).
pub fn nan_as_null_matrix<S: Serializer>(m: &[[f64; 3]; 3], s: S) -> Result<S::Ok, S::Error> {
    let rows: Vec<Vec<Option<f64>>> = m
        .iter()
        .map(|row| row.iter().map(|x| x.is_finite().then_some(*x)).collect())
        .collect();
    rows.serialize(s)
}

/// The filter's a posteriori σ at the last fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FinalSigma {
    pub position_m: f64,
    pub velocity_m_s: f64,
    pub bias_m_s2: f64,
}

/// The headline of one ensemble: the data contract's `"summary"`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub truth: TruthModel,
    pub realizations: u64,
    pub seed: u64,
    pub final_sigma: FinalSigma,
    pub all_passed: bool,
    pub checks: Vec<Check>,
    /// Timing: varies between runs.
    pub realizations_per_s: f64,
    /// Timing: varies between runs.
    pub elapsed_s: f64,
}

/// One ensemble's results as written to JSON.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnsembleDoc<'a> {
    pub summary: Summary,
    pub residual_pair: &'a ResidualPair,
    /// Largest |z| of the residual whiteness members at each lag t_i − t_m.
    pub residual_whiteness_by_lag: Vec<LagWorst>,
    pub fixes: &'a [FixStats],
}

/// Worst normalized residual correlation at one lag.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LagWorst {
    pub lag_s: f64,
    pub max_abs_z: f64,
}

/// Builds the JSON document of one ensemble.
pub fn ensemble_doc<'a>(
    config: &Config,
    truth: TruthModel,
    schedule: &FilterSchedule,
    run: &'a EnsembleRun,
    verdicts: &'a Verdicts,
) -> EnsembleDoc<'a> {
    let last = schedule.fixes.last().expect("at least two fixes");
    let stats = &run.stats;
    let n = stats.fixes.len();
    let residual_whiteness_by_lag = (1..n)
        .map(|lag| {
            let max_abs_z = (lag..n)
                .flat_map(|i| {
                    let m = i - lag;
                    (0..4).map(move |c| {
                        crate::checks::residual_z(stats, 2 * i + c / 2, 2 * m + c % 2).abs()
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
            truth,
            realizations: stats.realizations,
            seed: config.ensemble.seed,
            final_sigma: FinalSigma {
                position_m: last.p_post[(0, 0)].sqrt(),
                velocity_m_s: last.p_post[(1, 1)].sqrt(),
                bias_m_s2: last.p_post[(2, 2)].sqrt(),
            },
            all_passed: verdicts.all_passed(),
            checks: verdicts.checks.clone(),
            realizations_per_s: run.realizations_per_s(),
            elapsed_s: run.elapsed_s,
        },
        residual_pair: &verdicts.residual_pair,
        residual_whiteness_by_lag,
        fixes: &stats.fixes,
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

/// Serializes the `accelcal ensemble` output.
pub fn ensemble_json(config: &Config, doc: &EnsembleDoc<'_>) -> String {
    serde_json::to_string_pretty(&EnsembleFile {
        accelcal_version: env!("CARGO_PKG_VERSION"),
        config,
        ensemble: doc,
    })
    .expect("finite numbers serialize")
}

/// One realization at every accelerometer sample, as CSV with a header row.
pub fn realization_csv(r: &Realization, fix_times_s: &[f64]) -> String {
    let mut out = String::from(
        "t_s,accel_true_m_s2,p_true_m,v_true_m_s,p_computed_m,v_computed_m_s,\
         dp_true_m,dv_true_m_s,bias_true_m_s2,dp_est_m,dv_est_m_s,bias_est_m_s2,\
         sigma_p_m,sigma_v_m_s,sigma_b_m_s2,cov_pv_m2_s,cov_pb_m2_s2,cov_vb_m2_s3,gps_fix\n",
    );
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
            s.delta_x[0],
            s.delta_x[1],
            s.delta_x[2],
            s.estimate[0],
            s.estimate[1],
            s.estimate[2],
            s.sigma[0],
            s.sigma[1],
            s.sigma[2],
            s.cov[0][1],
            s.cov[0][2],
            s.cov[1][2],
        ];
        for x in v {
            out.push_str(&format!("{x:.12e},"));
        }
        out.push_str(&format!("{fix}\n"));
    }
    out
}

/// The report's `data.json`: configuration, the realization at the GPS fixes, every ensemble.
#[derive(Serialize)]
struct ReportData<'a> {
    accelcal_version: &'static str,
    config: &'a Config,
    primary_truth: TruthModel,
    realization: &'a Realization,
    ensembles: Vec<EnsembleDoc<'a>>,
}

/// Serializes the report's data file.
pub fn report_data_json(study: &crate::study::Study) -> String {
    let ensembles = study
        .ensembles
        .iter()
        .map(|e| {
            ensemble_doc(
                &study.model.config,
                e.truth,
                &study.schedule,
                &e.run,
                &e.verdicts,
            )
        })
        .collect();
    serde_json::to_string_pretty(&ReportData {
        accelcal_version: env!("CARGO_PKG_VERSION"),
        config: &study.model.config,
        primary_truth: study.model.truth,
        realization: &study.realization,
        ensembles,
    })
    .expect("finite numbers serialize")
}
