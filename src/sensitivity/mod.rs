//! Sensitivity to the assumed statistics: what a wrong assumption costs and whether the checks
//! see it. For each statistic the filter assumes and each factor, the filter assumes that
//! statistic's standard deviation times the factor while the truth keeps its value; the exact
//! actual covariance gives the accuracy reached against the accuracy claimed and, per check, exact
//! bounds on the detection probability; draws of the ensemble's fix-level sums ([`sampler`])
//! predict the detection probability itself, and independent Monte Carlo ensembles measure it.
//!
//! The world is the one the filter's model assumes (euler truth, point samples), so that the
//! mistuning is the only discrepancy: `ensemble.truth` and `accelerometer.output` of the
//! configuration are not used here.

pub mod covariance;
pub mod detection;
mod prediction;
pub mod sampler;
mod scaled;
mod statistic;

use crate::checks::{self, Budget, CheckId, Verdict};
use crate::config::{Case, Config};
use crate::ensemble::{Engine, Ensemble, EnsembleStats};
use crate::error::{ConfigError, FilterError};
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::progress::Progress;
use crate::state::ErrorState;
pub use covariance::{ActualFix, SampleCovariance, actual_covariance, covariance_at_samples};
pub use detection::Detection;
pub use statistic::AssumedStatistic;

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
    /// Draws of the ensemble's sums per case that predict the detection probabilities; 0 skips
    /// the prediction.
    pub draws: u64,
    /// The engine of the Monte Carlo ensembles.
    pub engine: Engine,
}

impl Plan {
    /// The plan of `config`: every assumed statistic, `sensitivity.factors`,
    /// `sensitivity.ensembles` ensembles of `ensemble.realizations` by the epoch engine,
    /// `sensitivity.draws` draws.
    pub fn of(config: &Config) -> Self {
        Self {
            parameters: AssumedStatistic::of(config),
            factors: config.sensitivity.factors.clone(),
            realizations: config.ensemble.realizations,
            ensembles: config.sensitivity.ensembles,
            draws: config.sensitivity.draws,
            engine: Engine::Epoch,
        }
    }
}

/// Why a sensitivity plan cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SensitivityError {
    /// The configuration in the study's world (euler truth, point samples) is out of range.
    #[error("the sensitivity study's world (euler truth, point samples)")]
    World {
        /// The configuration's complaint.
        source: ConfigError,
    },
    /// The configured filter's covariance stops being positive definite.
    #[error("the sensitivity study's filter as configured")]
    Configured {
        /// The filter's complaint.
        source: FilterError,
    },
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
    #[error(
        "the sensitivity study's filter assuming σ × {factor} for filter.{parameter}, which \
         takes it to {}",
        crate::config::show(*value)
    )]
    Filter {
        /// The statistic.
        parameter: &'static str,
        /// The factor on its standard deviation.
        factor: f64,
        /// The scaled value (a variance scales by the factor's square).
        value: f64,
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
    pub claimed_sigma_final: [f64; ErrorState::DIM],
    /// The actual error's σ at the last fix, a posteriori.
    pub actual_sigma_final: [f64; ErrorState::DIM],
    /// Expected average a posteriori NEES at the last fix, tr(P⁻¹·P_actual).
    pub expected_nees_final: f64,
    /// Expected average NIS at the last fix, tr(S⁻¹·S_actual).
    pub expected_nis_final: f64,
    /// Predicted detection probability per check, in [`CheckId::ALL`] order: the fraction of
    /// [`SensitivityCase::draws`] sampled ensembles in which the check fails; `None` for the
    /// residual whiteness, which the sampled sums do not carry, and when nothing was drawn.
    pub predicted: Vec<Option<f64>>,
    /// Sampled ensembles behind [`SensitivityCase::predicted`].
    pub draws: u64,
    /// Exact bounds on the detection probability from the members' closed-form distributions,
    /// in [`CheckId::ALL`] order; `None` for the correlation scores, which have none.
    pub bounds: Vec<Option<Detection>>,
    /// Monte Carlo ensembles run.
    pub ensembles: u64,
    /// Fraction of the ensembles in which each check failed, in [`CheckId::ALL`] order; `None`
    /// when no ensemble ran.
    pub detected: Option<Vec<f64>>,
}

/// The confidence of each one-sided bound on a sampled or measured detection probability.
pub const CONFIDENCE: f64 = 0.95;

impl SensitivityCase {
    /// The detection probability of `id`: predicted where the sums are sampled, else measured,
    /// else unknown.
    pub fn detection(&self, id: CheckId) -> Option<f64> {
        self.predicted[id.index()].or_else(|| Some(self.detected.as_ref()?[id.index()]))
    }

    /// Bounds (lower, upper) on the detection probability of `id`, each holding with at least
    /// [`CONFIDENCE`]: the tighter of the exact closed-form bounds and the one-sided
    /// Clopper–Pearson bounds of the sampled fraction or, where nothing was sampled, of the
    /// measured one. `None` when there is neither.
    pub fn detection_interval(&self, id: CheckId) -> Option<(f64, f64)> {
        let i = id.index();
        let exact = self.bounds[i].map(|d| (d.lower, d.upper));
        let counted = match (self.predicted[i], &self.detected) {
            (Some(p), _) => Some((p, self.draws)),
            (None, Some(m)) if self.ensembles > 0 => Some((m[i], self.ensembles)),
            _ => None,
        };
        let binomial = counted.map(|(fraction, trials)| {
            let failed = (fraction * trials as f64).round() as u64;
            crate::stats::clopper_pearson(failed, trials, CONFIDENCE)
        });
        match (exact, binomial) {
            (Some((a, b)), Some((c, d))) => Some((a.max(c), b.min(d))),
            (e, b) => e.or(b),
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
    pub tuned_sigma_final: [f64; ErrorState::DIM],
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
fn sigma(p: &crate::state::StateMatrix) -> [f64; ErrorState::DIM] {
    std::array::from_fn(|k| p[(k, k)].sqrt())
}

/// The filter schedule of the configured filter in `world`.
fn configured(world: &Config) -> Result<FilterSchedule, SensitivityError> {
    let model = Model::new(world).map_err(|source| SensitivityError::World { source })?;
    FilterSchedule::new(&model.timeline, &model.filter_stats)
        .map_err(|source| SensitivityError::Configured { source })
}

/// The filter of `parameter` × `factor` in `world`, with its schedule.
///
/// The scaled statistic is not held to the range a configuration may set (`ensemble` accepts a
/// `[filter]` value at the range's edge, which the factors then carry beyond it): the filter's
/// covariance recursion, which refuses a covariance that is not positive definite, is its check.
fn mistuned(
    world: &Config,
    parameter: AssumedStatistic,
    factor: f64,
) -> Result<(Model, FilterSchedule), SensitivityError> {
    let mut model = Model::new(world).map_err(|source| SensitivityError::Config {
        parameter: parameter.name(),
        factor,
        source,
    })?;
    model.filter_stats = parameter.scaled_stats(&model.filter_stats, factor);
    model.config = parameter.scaled(world, factor);
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats).map_err(|source| {
        SensitivityError::Filter {
            parameter: parameter.name(),
            factor,
            value: parameter.value(&model.filter_stats),
            source,
        }
    })?;
    Ok((model, schedule))
}

/// Runs `plan` on `base` (its statistics are the truth's; its `[filter]` the starting point).
/// The sampled ensembles and the Monte Carlo ensembles of a case draw from seeds derived from
/// `ensemble.seed`, the statistic and the factor (not the case's place in the plan), so a case
/// gives the same numbers in any plan and on any thread count.
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
    let tuned_schedule = configured(&world)?;
    let grid: Vec<(AssumedStatistic, f64)> = plan
        .parameters
        .iter()
        .flat_map(|&p| plan.factors.iter().map(move |&f| (p, f)))
        .collect();
    // The sampler's Wishart draws need enough realizations (smaller ensembles are not sampled).
    let draws = if plan.realizations >= sampler::Sampler::MIN_REALIZATIONS {
        plan.draws
    } else {
        0
    };
    let seed = base.ensemble.seed;

    // Exact and sampled predictions, no simulation.
    progress.start_in("predict", grid.len() as u64 * draws, "sampled ensembles");
    let mut cases = Vec::with_capacity(grid.len());
    for &(parameter, factor) in &grid {
        let predictions = prediction::Predictions {
            world: &world,
            plan,
            budget: &budget,
            draws,
            seed,
        };
        cases.push(predictions.case(parameter, factor)?);
        progress.advance(cases.len() as u64 * draws);
    }
    progress.finish();

    // Independent Monte Carlo ensembles of every case.
    if plan.ensembles > 0 {
        let total = grid.len() as u64 * plan.ensembles * plan.realizations;
        progress.start("sensitivity", total);
        let mut done = 0;
        for case in &mut cases {
            let failures = monte_carlo(&world, plan, &budget, seed, case, (progress, done))?;
            done += plan.ensembles * plan.realizations;
            case.detected = Some(
                failures
                    .iter()
                    .map(|&f| f as f64 / plan.ensembles as f64)
                    .collect(),
            );
        }
        progress.finish();
    }
    Ok(Sensitivity {
        plan: plan.clone(),
        false_alarm_rate: base.checks.false_alarm_rate,
        tuned_sigma_final: sigma(&tuned_schedule.fixes.last().expect("fixes").p_post),
        cases,
    })
}

/// Runs the Monte Carlo ensembles of `case` and counts, per check in [`CheckId::ALL`] order,
/// the ensembles in which it failed; `progress` is told the realizations done, counted from the
/// second element.
fn monte_carlo(
    world: &Config,
    plan: &Plan,
    budget: &Budget,
    seed: u64,
    case: &SensitivityCase,
    (progress, before): (&mut dyn Progress, u64),
) -> Result<Vec<u64>, SensitivityError> {
    // Built again rather than kept from the first pass: one covariance pass, against
    // memory that would grow with cases × fixes.
    let (model, schedule) = mistuned(world, case.parameter, case.factor)?;
    let mut ensemble = Ensemble::new(&model, &schedule)
        .with_engine(plan.engine)
        .with_realizations(plan.realizations);
    let mut failures = vec![0u64; CheckId::ALL.len()];
    let mut done = before;
    for k in 0..plan.ensembles {
        let seed = mix(case_seed(seed, ENSEMBLES, case.parameter, case.factor), k);
        ensemble = ensemble.with_seed(seed);
        let acc = ensemble.sums(|d| progress.advance(done + d));
        done += plan.realizations;
        let stats = EnsembleStats::from_sums(&acc, &schedule);
        let v = checks::evaluate(&stats, budget);
        for (failed, c) in failures.iter_mut().zip(&v.checks) {
            *failed += u64::from(c.verdict == Verdict::Fail);
        }
    }
    Ok(failures)
}

/// Domains of the seeds a case derives: its sampled ensembles and its Monte Carlo ensembles.
const SAMPLED: u64 = 0x5A;
const ENSEMBLES: u64 = 0xE5;

/// The seed of `parameter` × `factor` in `domain` under `seed`.
fn case_seed(seed: u64, domain: u64, parameter: AssumedStatistic, factor: f64) -> u64 {
    let index = AssumedStatistic::ALL
        .iter()
        .position(|p| *p == parameter)
        .expect("every statistic is in ALL") as u64;
    mix(mix(mix(seed, domain), index), factor.to_bits())
}

/// `seed` mixed with `value`: SplitMix64 of their combination.
fn mix(seed: u64, value: u64) -> u64 {
    crate::random::splitmix64(seed.wrapping_add(value.wrapping_mul(0xD1B5_4A32_D192_ED03)))
}
