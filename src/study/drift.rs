//! A drifting bias seen by two filters: one that believes the bias constant, as the problem
//! statement's model does, and one that models its random walk. Both run on the same truth, a
//! random-walk bias over a run long enough for the drift to matter; for each, the σ it claims
//! against the RMS error it achieves (exact, from the covariance recursion of a suboptimal
//! filter) and the verdicts of the checks on a Monte Carlo ensemble.

use crate::checks::Verdicts;
use crate::config::{BiasModelKind, Config, TruthModel};
use crate::ensemble::{Engine, Ensemble};
use crate::error::FilterError;
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::progress::Progress;
use crate::sensitivity::actual_covariance;
use crate::state::{BiasModel, ErrorState};

/// Length of the run, s: long enough for a constant-bias filter's claim to part from its error.
pub const DRIFT_DURATION_S: f64 = 300.0;
/// K of the truth's random walk when the configured truth's bias is not a random walk, m/s² per
/// √s: over the run the bias moves by K·√300 ≈ 0.017 m/s², a sixth of the default prior σ_b.
pub const DRIFT_K_M_S2_PER_SQRT_S: f64 = 1e-3;
/// Most realizations of each filter's ensemble (fewer when the configuration asks for fewer).
pub const DRIFT_REALIZATIONS: u64 = 2_000;
/// Most points of each series kept for the figure and `data.json`.
const SERIES_POINTS: usize = 150;

/// One filter on the drifting truth.
#[derive(Clone, Debug)]
pub struct DriftFilter {
    /// The bias model the filter assumes.
    pub bias_model: BiasModel,
    /// Fix times of the series, s.
    pub time_s: Vec<f64>,
    /// The filter's a posteriori σ of each state at those fixes, (m, m/s, m/s²).
    pub claimed_sigma: Vec<[f64; ErrorState::DIM]>,
    /// The actual a posteriori RMS error of each state there (the error has zero mean on the
    /// euler truth, so the RMS is the actual σ), (m, m/s, m/s²).
    pub achieved_rms: Vec<[f64; ErrorState::DIM]>,
    /// The checks' verdicts on the ensemble.
    pub verdicts: Verdicts,
}

/// The drifting-bias study.
#[derive(Clone, Debug)]
pub struct DriftStudy {
    /// K of the truth's random walk, m/s² per √s.
    pub k_m_s2_per_sqrt_s: f64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// Realizations of each ensemble.
    pub realizations: u64,
    /// The filter that assumes a constant bias.
    pub constant: DriftFilter,
    /// The filter that assumes the truth's random walk.
    pub random_walk: DriftFilter,
}

/// The configuration of the drifting truth: `config` with the euler truth (the filter's model
/// exact but for the bias), a run of [`DRIFT_DURATION_S`], the random walk of K, and the filter's
/// bias model `filter`; every other statistic the filter assumes is the truth's.
fn drift_config(config: &Config, k: f64, filter: BiasModelKind) -> Config {
    let mut c = config.clone();
    c.profile.duration_s = DRIFT_DURATION_S;
    c.ensemble.truth = TruthModel::Euler;
    c.ensemble.realizations = c.ensemble.realizations.min(DRIFT_REALIZATIONS);
    c.checks.residual_pair_s = None;
    let a = &mut c.accelerometer;
    a.bias_model = BiasModelKind::RandomWalk;
    a.bias_random_walk_m_s2_per_sqrt_s = Some(k);
    a.bias_correlation_time_s = None;
    c.filter = Default::default();
    c.filter.bias_model = Some(filter);
    c
}

/// K of the study: the configured truth's when its bias is a random walk with K > 0, else
/// [`DRIFT_K_M_S2_PER_SQRT_S`].
pub fn drift_k(config: &Config) -> f64 {
    let a = &config.accelerometer;
    match (a.bias_model, a.bias_random_walk_m_s2_per_sqrt_s) {
        (BiasModelKind::RandomWalk, Some(k)) if k > 0.0 => k,
        _ => DRIFT_K_M_S2_PER_SQRT_S,
    }
}

/// Runs the filter of `model` (a drifting configuration of [`drift_config`]).
fn one_filter(model: &Model, progress: &mut dyn Progress) -> Result<DriftFilter, FilterError> {
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    // The recursion of a suboptimal filter is exact when the filter's Φ is the truth's: a
    // constant and a random-walk bias share Φ (φ = 1) and differ in Q only.
    let truth = crate::filter::ErrorStateModel::new(model.timeline.dt_s, &model.truth_stats);
    assert_eq!(
        truth.phi, schedule.model.phi,
        "the filters share the truth's Φ"
    );
    let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
    let every = schedule.fixes.len().div_ceil(SERIES_POINTS).max(1);
    let kept: Vec<usize> = (0..schedule.fixes.len())
        .filter(|i| (i + 1) % every == 0)
        .collect();
    let sigma = |p: &crate::state::StateMatrix| std::array::from_fn(|s| p[(s, s)].sqrt());
    let ensemble = Ensemble::new(model, &schedule).with_engine(Engine::Epoch);
    let outcome = super::run_case(&ensemble, progress);
    Ok(DriftFilter {
        bias_model: model.filter_stats.bias_model,
        time_s: kept.iter().map(|&i| schedule.fixes[i].time_s).collect(),
        claimed_sigma: kept
            .iter()
            .map(|&i| sigma(&schedule.fixes[i].p_post))
            .collect(),
        achieved_rms: kept.iter().map(|&i| sigma(&actual[i].post)).collect(),
        verdicts: outcome.verdicts,
    })
}

/// Runs the drifting-bias study of `config`: the constant-bias filter and the random-walk filter
/// on the same random-walk truth. `None` when the configuration's rates cannot make a run of
/// [`DRIFT_DURATION_S`] (too many samples or fixes).
///
/// # Errors
/// [`FilterError`] when a filter's covariance stops being positive definite.
pub fn run(
    config: &Config,
    progress: &mut dyn Progress,
) -> Result<Option<DriftStudy>, FilterError> {
    let k = drift_k(config);
    let models = [BiasModelKind::Constant, BiasModelKind::RandomWalk]
        .map(|filter| Model::new(&drift_config(config, k, filter)));
    let [Ok(constant), Ok(random_walk)] = models else {
        return Ok(None);
    };
    let constant = one_filter(&constant, progress)?;
    let random_walk = one_filter(&random_walk, progress)?;
    Ok(Some(DriftStudy {
        k_m_s2_per_sqrt_s: k,
        duration_s: DRIFT_DURATION_S,
        realizations: config.ensemble.realizations.min(DRIFT_REALIZATIONS),
        constant,
        random_walk,
    }))
}

impl DriftFilter {
    /// The index of the kept fix nearest `t_s`.
    pub fn nearest(&self, t_s: f64) -> usize {
        (0..self.time_s.len())
            .min_by(|&a, &b| {
                (self.time_s[a] - t_s)
                    .abs()
                    .total_cmp(&(self.time_s[b] - t_s).abs())
            })
            .expect("at least one point")
    }
}
