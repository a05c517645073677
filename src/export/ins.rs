//! The three-axis ensemble as JSON (`accelcal ensemble --model ins`): the linear study's
//! summary shape (`checks` with `id`, `verdict`, …) with `"model": "ins"`, the calibration at
//! the end of the drive, and the NEES and NIS averages at every fix.

use serde::Serialize;

use super::{CheckRecord, ResidualPairs};
use crate::checks::{ResidualPair, Verdicts};
use crate::config::ins::InsConfig;
use crate::ensemble::Statistics;
use crate::ins::ensemble::{Calibration, Outcome};
use crate::ins::names::MEASUREMENTS;
use crate::ins::state::Layout;
use crate::stats::binomial_band;

/// One error state at the end of the drive.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateRecord {
    /// The state's key, e.g. `gyro_bias_x`.
    pub state: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// The filter's σ at the last fix, root mean square over the ensemble.
    pub filter_sigma: f64,
    /// The achieved error at the last fix, root mean square over the ensemble.
    pub achieved_rms: f64,
    /// achieved_rms / filter_sigma: 1 when the filter's claim holds.
    pub ratio: f64,
    /// Realizations whose final |error| ≤ 1.96 σ (the truth inside its own 95 % interval).
    pub within_95: u64,
    /// The binomial band of `within_95` for Bin(N, 0.95) at the study's false-alarm rate.
    pub within_95_band: [u64; 2],
}

/// The headline: the linear summary's fields that apply.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InsSummary {
    /// Number of realizations N.
    pub realizations: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// The study-wide false-alarm rate.
    pub false_alarm_rate: f64,
    /// True only when every check is "pass".
    pub all_passed: bool,
    /// Every check, in catalogue order.
    pub checks: Vec<CheckRecord>,
    /// Which pairs of fixes the residual whiteness check tested.
    pub residual_pairs: ResidualPairs,
    /// Every error state at the end of the drive.
    pub final_states: Vec<StateRecord>,
    /// Timing: varies between runs.
    pub realizations_per_s: f64,
    /// Timing: varies between runs.
    pub elapsed_s: f64,
}

/// The averages at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixRecord {
    /// The fix's time, s.
    pub time_s: f64,
    /// Average NEES before the update (15 when consistent).
    pub nees_prior: f64,
    /// Average NEES after the update.
    pub nees_post: f64,
    /// Average NIS (6 when consistent).
    pub nis: f64,
}

/// The `accelcal ensemble --model ins` output.
#[derive(Serialize)]
pub struct InsEnsembleFile<'a> {
    /// The version that wrote it.
    pub accelcal_version: &'static str,
    /// "ins", or "car" for an IMU in a vehicle.
    pub model: &'static str,
    /// The configuration.
    pub config: &'a InsConfig,
    /// The headline.
    pub summary: InsSummary,
    /// The residual pair of the first and last fixes.
    pub residual_pair: &'a ResidualPair,
    /// Every fix's averages.
    pub fixes: Vec<FixRecord>,
}

fn states<const N: usize>(c: &Calibration<N>, alpha: f64) -> Vec<StateRecord> {
    let band = binomial_band(c.realizations, 0.95, alpha);
    Layout::of::<N>()
        .variables()
        .enumerate()
        .map(|(k, v)| StateRecord {
            state: v.key,
            unit: v.unit,
            filter_sigma: c.filter_sigma[k],
            achieved_rms: c.achieved_rms[k],
            ratio: c.achieved_rms[k] / c.filter_sigma[k],
            within_95: c.within_95[k],
            within_95_band: [band.0, band.1],
        })
        .collect()
}

/// The document of one three-axis ensemble.
pub fn document<'a, const N: usize>(
    config: &'a InsConfig,
    outcome: &Outcome<N>,
    verdicts: &'a Verdicts,
    elapsed_s: f64,
) -> InsEnsembleFile<'a> {
    let stats = &outcome.stats;
    let times: Vec<f64> = stats.fixes.iter().map(|f| f.time_s).collect();
    let n = times.len();
    let names = Layout::of::<N>().variable_list();
    InsEnsembleFile {
        accelcal_version: env!("CARGO_PKG_VERSION"),
        model: if config.is_car() { "car" } else { "ins" },
        config,
        summary: InsSummary {
            realizations: stats.realizations,
            seed: config.ensemble.seed,
            false_alarm_rate: verdicts.false_alarm_rate,
            all_passed: verdicts.all_passed(),
            checks: verdicts
                .checks
                .iter()
                .map(|c| CheckRecord::with_names(c, &times, &names, &MEASUREMENTS))
                .collect(),
            residual_pairs: ResidualPairs {
                all_pairs: stats.residual_layout.max_lag().is_none(),
                max_lag: stats
                    .residual_layout
                    .max_lag()
                    .unwrap_or(n.saturating_sub(1)),
            },
            final_states: states(&outcome.calibration, config.checks.false_alarm_rate),
            realizations_per_s: stats.realizations as f64 / elapsed_s,
            elapsed_s,
        },
        residual_pair: &verdicts.residual_pair,
        fixes: stats
            .fixes
            .iter()
            .enumerate()
            .map(|(i, f)| FixRecord {
                time_s: f.time_s,
                nees_prior: f.prior.nees_avg,
                nees_post: f.post.nees_avg,
                nis: stats.nis_avg(i),
            })
            .collect(),
    }
}
