//! Sensitivity to the assumed statistics: what a wrong assumption costs and whether the checks
//! see it. For each statistic the filter assumes and each factor, the filter assumes that
//! statistic's standard deviation times the factor while the truth keeps its value; the exact
//! actual covariance gives the accuracy reached against the accuracy claimed and the closed-form
//! detection probabilities, and independent Monte Carlo ensembles measure the detection.
//!
//! The world is the one the filter's model assumes (euler truth, point samples), so that the
//! mistuning is the only discrepancy.

pub mod covariance;
pub mod detection;
pub mod sampler;

use crate::checks::{self, Budget, CheckId, Verdict};
use crate::config::{Case, Config};
use crate::ensemble::{self, EnsembleStats};
use crate::error::{ConfigError, FilterError};
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::progress::Progress;
pub use covariance::{ActualFix, actual_covariance};
pub use detection::Detection;

/// A statistic the filter assumes (a key of the configuration's `[filter]` section).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AssumedStatistic {
    /// Accelerometer noise variance W.
    AccelNoise,
    /// Bias prior variance.
    BiasPrior,
    /// GPS position noise σ.
    GpsPosition,
    /// GPS velocity noise σ.
    GpsVelocity,
    /// Initial position σ.
    InitialPosition,
    /// Initial velocity σ.
    InitialVelocity,
}

impl AssumedStatistic {
    /// Every assumed statistic, in the configuration's order.
    pub const ALL: [AssumedStatistic; 6] = [
        AssumedStatistic::AccelNoise,
        AssumedStatistic::BiasPrior,
        AssumedStatistic::GpsPosition,
        AssumedStatistic::GpsVelocity,
        AssumedStatistic::InitialPosition,
        AssumedStatistic::InitialVelocity,
    ];

    /// The `[filter]` key.
    pub fn name(self) -> &'static str {
        match self {
            AssumedStatistic::AccelNoise => "accel_noise_var_m2_s4",
            AssumedStatistic::BiasPrior => "bias_var_m2_s4",
            AssumedStatistic::GpsPosition => "gps_position_sigma_m",
            AssumedStatistic::GpsVelocity => "gps_velocity_sigma_m_s",
            AssumedStatistic::InitialPosition => "initial_position_sigma_m",
            AssumedStatistic::InitialVelocity => "initial_velocity_sigma_m_s",
        }
    }

    /// The statistic in words, as a standard deviation (the factor scales it).
    pub fn title(self) -> &'static str {
        match self {
            AssumedStatistic::AccelNoise => "accelerometer noise σ",
            AssumedStatistic::BiasPrior => "bias prior σ",
            AssumedStatistic::GpsPosition => "GPS position σ",
            AssumedStatistic::GpsVelocity => "GPS velocity σ",
            AssumedStatistic::InitialPosition => "initial position σ",
            AssumedStatistic::InitialVelocity => "initial velocity σ",
        }
    }

    /// The statistic named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// `config` with the filter assuming this statistic's standard deviation times `factor` (a
    /// variance times `factor²`), starting from the value the filter assumes in `config`.
    pub fn scaled(self, config: &Config, factor: f64) -> Config {
        let mut c = config.clone();
        let f = &mut c.filter;
        match self {
            AssumedStatistic::AccelNoise => {
                f.accel_noise_var_m2_s4 =
                    Some(config.filter_accel_noise_var_m2_s4() * factor * factor)
            }
            AssumedStatistic::BiasPrior => {
                f.bias_var_m2_s4 = Some(config.filter_bias_var_m2_s4() * factor * factor)
            }
            AssumedStatistic::GpsPosition => {
                f.gps_position_sigma_m = Some(config.filter_gps_position_sigma_m() * factor)
            }
            AssumedStatistic::GpsVelocity => {
                f.gps_velocity_sigma_m_s = Some(config.filter_gps_velocity_sigma_m_s() * factor)
            }
            AssumedStatistic::InitialPosition => {
                f.initial_position_sigma_m = Some(config.filter_initial_position_sigma_m() * factor)
            }
            AssumedStatistic::InitialVelocity => {
                f.initial_velocity_sigma_m_s =
                    Some(config.filter_initial_velocity_sigma_m_s() * factor)
            }
        }
        c
    }
}

/// What the sensitivity study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The statistics to vary.
    pub parameters: Vec<AssumedStatistic>,
    /// The factors on their standard deviations.
    pub factors: Vec<f64>,
    /// Realizations per Monte Carlo ensemble.
    pub realizations: u64,
    /// Independent Monte Carlo ensembles per case; 0 skips the Monte Carlo.
    pub ensembles: u64,
}

impl Plan {
    /// The plan of `config`: every assumed statistic, `sensitivity.factors`,
    /// `sensitivity.ensembles` ensembles of `ensemble.realizations`.
    pub fn of(config: &Config) -> Self {
        Self {
            parameters: AssumedStatistic::ALL.to_vec(),
            factors: config.sensitivity.factors.clone(),
            realizations: config.ensemble.realizations,
            ensembles: config.sensitivity.ensembles,
        }
    }
}

/// Why a sensitivity plan cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SensitivityError {
    /// A scaled statistic leaves the accepted range.
    #[error("the filter assuming {parameter} × {factor}")]
    Config {
        /// The statistic.
        parameter: &'static str,
        /// The factor.
        factor: f64,
        /// The configuration's complaint.
        source: ConfigError,
    },
    /// A scaled filter's covariance stops being positive definite.
    #[error("the filter assuming {parameter} × {factor}")]
    Filter {
        /// The statistic.
        parameter: &'static str,
        /// The factor.
        factor: f64,
        /// The filter's complaint.
        source: FilterError,
    },
}

/// One statistic at one factor.
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivityCase {
    /// The statistic varied.
    pub parameter: AssumedStatistic,
    /// The factor on its standard deviation.
    pub factor: f64,
    /// The filter's σ at the last fix, a posteriori.
    pub claimed_sigma_final: [f64; 3],
    /// The actual error's σ at the last fix, a posteriori.
    pub actual_sigma_final: [f64; 3],
    /// Expected average a posteriori NEES at the last fix, tr(P⁻¹·P_actual).
    pub expected_nees_final: f64,
    /// Expected average NIS at the last fix, tr(S⁻¹·S_actual).
    pub expected_nis_final: f64,
    /// Predicted detection probability per check, in [`CheckId::ALL`] order; `None` where it
    /// is measured by Monte Carlo only.
    pub predicted: Vec<Option<Detection>>,
    /// Monte Carlo ensembles run.
    pub ensembles: u64,
    /// Fraction of the ensembles in which each check failed, in [`CheckId::ALL`] order.
    pub detected: Vec<f64>,
}

impl SensitivityCase {
    /// The detection probability of `id`: predicted where it has a closed form, else measured.
    pub fn detection(&self, id: CheckId) -> f64 {
        match self.predicted[id.index()] {
            Some(d) => d.probability,
            None => self.detected[id.index()],
        }
    }
}

/// The whole sensitivity study.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensitivity {
    /// What ran.
    pub plan: Plan,
    /// The study-wide false-alarm rate of the checks.
    pub false_alarm_rate: f64,
    /// The filter's σ at the last fix when it assumes the configured statistics.
    pub tuned_sigma_final: [f64; 3],
    /// One per statistic and factor, statistics outer.
    pub cases: Vec<SensitivityCase>,
}

/// The model-exact world of `config` with N = `realizations`.
fn world(config: &Config, realizations: u64) -> Config {
    let mut c = config.clone();
    c.ensemble.truth = Case::REPORT[0].truth;
    c.accelerometer.output = Case::REPORT[0].output;
    c.ensemble.realizations = realizations;
    c
}

/// σ of the diagonal of `p`.
fn sigma(p: &crate::filter::Matrix3) -> [f64; 3] {
    std::array::from_fn(|k| p[(k, k)].sqrt())
}

/// Runs `plan` on `base` (its statistics are the truth's; its `[filter]` the starting point).
/// The Monte Carlo ensembles of case c, ensemble k draw from seed `ensemble.seed` mixed with
/// (c, k): results do not depend on the thread count.
///
/// # Errors
/// [`SensitivityError`] when a scaled statistic is out of range or breaks the filter.
pub fn run(
    base: &Config,
    plan: &Plan,
    progress: &mut dyn Progress,
) -> Result<Sensitivity, SensitivityError> {
    let world = world(base, plan.realizations);
    let budget = Budget::study(base.checks.false_alarm_rate);
    let tuned = Model::new(&world).map_err(|source| SensitivityError::Config {
        parameter: "configured",
        factor: 1.0,
        source,
    })?;
    let tuned_schedule =
        FilterSchedule::new(&tuned.timeline, &tuned.filter_stats).map_err(|source| {
            SensitivityError::Filter {
                parameter: "configured",
                factor: 1.0,
                source,
            }
        })?;
    let total =
        (plan.parameters.len() * plan.factors.len()) as u64 * plan.ensembles * plan.realizations;
    progress.start("sensitivity", total);
    let mut done = 0;
    let mut cases = Vec::new();
    for &parameter in &plan.parameters {
        for &factor in &plan.factors {
            let config = parameter.scaled(&world, factor);
            let name = parameter.name();
            let model = Model::new(&config).map_err(|source| SensitivityError::Config {
                parameter: name,
                factor,
                source,
            })?;
            let schedule =
                FilterSchedule::new(&model.timeline, &model.filter_stats).map_err(|source| {
                    SensitivityError::Filter {
                        parameter: name,
                        factor,
                        source,
                    }
                })?;
            let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
            let (last_fix, last_actual) = (
                schedule.fixes.last().expect("fixes"),
                actual.last().expect("fixes"),
            );
            let predicted = CheckId::ALL
                .iter()
                .map(|&id| detection::predicted(id, &schedule, &actual, plan.realizations, &budget))
                .collect();
            let mut failures = [0u64; 7];
            for k in 0..plan.ensembles {
                let seed = mix(base.ensemble.seed, cases.len() as u64, k);
                let acc = ensemble::run(&model, &schedule, seed, plan.realizations, |d| {
                    progress.advance(done + d)
                });
                done += plan.realizations;
                let stats = EnsembleStats::from_sums(&acc, &schedule);
                let v = checks::evaluate(&stats, &budget);
                for c in &v.checks {
                    failures[c.id.index()] += u64::from(c.verdict == Verdict::Fail);
                }
            }
            cases.push(SensitivityCase {
                parameter,
                factor,
                claimed_sigma_final: sigma(&last_fix.p_post),
                actual_sigma_final: sigma(&last_actual.post),
                expected_nees_final: covariance::weights(&last_fix.p_post_inv, &last_actual.post).0,
                expected_nis_final: covariance::weights(&last_fix.s_inv, &last_actual.innovation).0,
                predicted,
                ensembles: plan.ensembles,
                detected: failures
                    .iter()
                    .map(|&f| f as f64 / plan.ensembles.max(1) as f64)
                    .collect(),
            });
        }
    }
    progress.finish();
    Ok(Sensitivity {
        plan: plan.clone(),
        false_alarm_rate: base.checks.false_alarm_rate,
        tuned_sigma_final: sigma(&tuned_schedule.fixes.last().expect("fixes").p_post),
        cases,
    })
}

/// The seed of ensemble `k` of case `case` under `seed`.
fn mix(seed: u64, case: u64, k: u64) -> u64 {
    let mut z = seed ^ 0x5E45_171F_17E5_0000 ^ (case << 32) ^ k;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
