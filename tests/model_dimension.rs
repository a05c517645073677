//! A state model with one more state runs through the filter, an ensemble and every check.
//!
//! The test-only model adds a constant accelerometer scale-factor error s to the error state: the
//! accelerometer reads (1 + s)·a(t) + b + w, so the integrated velocity and position err by
//! −s·a(t) besides −b. Φ then depends on the known profile a(t_j) (on the time, never on the
//! realization), which the filter schedule and the model-exact engine must honour step by step.
//! A filter that assumes the truth's statistics must pass every check at N = 2 000; one that
//! assumes a scale factor ten times smaller than it is must fail.

mod common;

use accelcal::checks::{self, Budget, Verdict};
use accelcal::config::Config;
use accelcal::ensemble::EnsembleStats;
use accelcal::ensemble::linear::{self, LinearRun};
use accelcal::filter::FilterSchedule;
use accelcal::model::{Model, NoiseStats};
use accelcal::state::{ErrorState, StateModel, Variable};
use nalgebra::SMatrix;

/// States: the error state and the scale factor.
const N: usize = ErrorState::DIM + 1;
/// Measurements: the error state's.
const M: usize = ErrorState::MEAS;
/// Index of the scale-factor error.
const SCALE: usize = ErrorState::DIM;

/// The error state with a constant scale-factor error, over a known acceleration profile.
struct ScaleFactorState {
    stats: NoiseStats,
    /// Prior variance of the scale-factor error s, dimensionless².
    scale_var: f64,
    /// The deterministic acceleration a(t_j) at every sample, m/s².
    accel_m_s2: Vec<f64>,
    dt_s: f64,
}

impl ScaleFactorState {
    fn error_state(&self) -> ErrorState {
        ErrorState { stats: self.stats }
    }
}

impl StateModel<N, M> for ScaleFactorState {
    const STATES: [Variable; N] = {
        let e = <ErrorState as StateModel<{ ErrorState::DIM }, M>>::STATES;
        let scale = Variable {
            key: "scale_factor",
            name: "scale-factor error",
            symbol: "s",
            unit: "1",
        };
        [e[0], e[1], e[2], scale]
    };
    const MEASUREMENTS: [Variable; M] =
        <ErrorState as StateModel<{ ErrorState::DIM }, M>>::MEASUREMENTS;

    /// eq. (5) with the scale factor entering like the bias, weighted by a(t): one step of
    /// length τ from the sample at t.
    fn transition(&self, t_s: f64, tau_s: f64) -> SMatrix<f64, N, N> {
        let a = self.accel_m_s2[(t_s / self.dt_s).round() as usize];
        let mut phi = SMatrix::<f64, N, N>::identity();
        phi.fixed_view_mut::<{ ErrorState::DIM }, { ErrorState::DIM }>(0, 0)
            .copy_from(&self.error_state().transition(t_s, tau_s));
        phi[(ErrorState::POSITION, SCALE)] = -0.5 * tau_s * tau_s * a;
        phi[(ErrorState::VELOCITY, SCALE)] = -tau_s * a;
        phi
    }

    fn process_noise(&self, t_s: f64, tau_s: f64) -> SMatrix<f64, N, N> {
        let mut q = SMatrix::<f64, N, N>::zeros();
        q.fixed_view_mut::<{ ErrorState::DIM }, { ErrorState::DIM }>(0, 0)
            .copy_from(&self.error_state().process_noise(t_s, tau_s));
        q
    }

    fn observation(&self) -> SMatrix<f64, M, N> {
        let mut h = SMatrix::<f64, M, N>::zeros();
        h.fixed_view_mut::<M, { ErrorState::DIM }>(0, 0)
            .copy_from(&self.error_state().observation());
        h
    }

    fn measurement_noise(&self) -> SMatrix<f64, M, M> {
        self.error_state().measurement_noise()
    }

    fn initial_covariance(&self) -> SMatrix<f64, N, N> {
        let mut p = SMatrix::<f64, N, N>::zeros();
        p.fixed_view_mut::<{ ErrorState::DIM }, { ErrorState::DIM }>(0, 0)
            .copy_from(&self.error_state().initial_covariance());
        p[(SCALE, SCALE)] = self.scale_var;
        p
    }
}

/// A 30 s run at 50 Hz with 5 Hz fixes: long enough for the profile to make s observable.
fn model() -> Model {
    let mut config = Config::default();
    config.accelerometer.sample_rate_hz = 50.0;
    config.ensemble.truth = accelcal::config::TruthModel::Euler;
    Model::new(&config).unwrap()
}

/// The 4-state model with the truth's statistics and a scale-factor σ of `scale_sigma`.
fn four_state(model: &Model, stats: NoiseStats, scale_sigma: f64) -> ScaleFactorState {
    ScaleFactorState {
        stats,
        scale_var: scale_sigma * scale_sigma,
        accel_m_s2: model.accel_m_s2.clone(),
        dt_s: model.timeline.dt_s,
    }
}

/// Truth's scale-factor σ: 1 %, which moves the velocity by about 0.1 m/s at the profile's 10
/// m/s² — several GPS velocity σ.
const SCALE_SIGMA: f64 = 0.01;

/// The filter's covariance recursion with plain arrays (no nalgebra): Φ and Q per step from the
/// definitions above written out again, the gain by the 2×2 inverse, Joseph form. Returns
/// (P⁻, P⁺) at every fix.
type Plain = [[f64; N]; N];
fn plain_filter(model: &Model, stats: &NoiseStats, scale_var: f64) -> Vec<(Plain, Plain)> {
    let dt = model.timeline.dt_s;
    let mul = |a: &Plain, b: &Plain| -> Plain {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..N).map(|k| a[i][k] * b[k][j]).sum()))
    };
    let tr = |a: &Plain| -> Plain { std::array::from_fn(|i| std::array::from_fn(|j| a[j][i])) };
    let mut p: Plain = [[0.0; N]; N];
    p[0][0] = stats.initial_position_sigma_m.powi(2);
    p[1][1] = stats.initial_velocity_sigma_m_s.powi(2);
    p[2][2] = stats.bias_var_m2_s4;
    p[3][3] = scale_var;
    let w = stats.accel_noise_var_m2_s4;
    let g = [-0.5 * dt * dt, -dt, 0.0, 0.0];
    let r = [
        stats.gps_position_sigma_m.powi(2),
        stats.gps_velocity_sigma_m_s.powi(2),
    ];
    let mut out = Vec::new();
    let mut j = 0;
    for &jf in &model.timeline.fix_steps {
        while j < jf {
            let a = model.accel_m_s2[j];
            let phi: Plain = [
                [1.0, dt, -0.5 * dt * dt, -0.5 * dt * dt * a],
                [0.0, 1.0, -dt, -dt * a],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ];
            p = mul(&mul(&phi, &p), &tr(&phi));
            for (r_, gr) in g.iter().enumerate() {
                for (c, gc) in g.iter().enumerate() {
                    p[r_][c] += gr * gc * w;
                }
            }
            j += 1;
        }
        let prior = p;
        // S = H P Hᵀ + R is the top-left 2×2 block plus R.
        let s = [[p[0][0] + r[0], p[0][1]], [p[1][0], p[1][1] + r[1]]];
        let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        let s_inv = [
            [s[1][1] / det, -s[0][1] / det],
            [-s[1][0] / det, s[0][0] / det],
        ];
        // K = P Hᵀ S⁻¹: P's first two columns times S⁻¹.
        let k: [[f64; M]; N] = std::array::from_fn(|i| {
            std::array::from_fn(|c| p[i][0] * s_inv[0][c] + p[i][1] * s_inv[1][c])
        });
        let mut i_kh: Plain = std::array::from_fn(|i| std::array::from_fn(|c| f64::from(i == c)));
        for (i, row) in i_kh.iter_mut().enumerate() {
            row[0] -= k[i][0];
            row[1] -= k[i][1];
        }
        let mut post = mul(&mul(&i_kh, &p), &tr(&i_kh));
        for (i, row) in post.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v += k[i][0] * r[0] * k[c][0] + k[i][1] * r[1] * k[c][1];
            }
        }
        p = post;
        out.push((prior, post));
    }
    out
}

#[test]
fn the_filter_runs_a_four_state_model_as_an_independent_implementation_does() {
    let model = model();
    let four = four_state(&model, model.filter_stats, SCALE_SIGMA);
    let schedule = FilterSchedule::<N, M>::of(&four, &model.timeline).unwrap();
    let plain = plain_filter(&model, &model.filter_stats, four.scale_var);
    assert_eq!(schedule.fixes.len(), plain.len());
    for (fix, (prior, post)) in schedule.fixes.iter().zip(&plain) {
        for (ours, theirs) in [(&fix.p_prior, prior), (&fix.p_post, post)] {
            for r in 0..N {
                for c in 0..N {
                    let scale = (ours[(r, r)] * ours[(c, c)]).sqrt();
                    let err = (ours[(r, c)] - theirs[r][c]).abs() / scale;
                    assert!(err < 1e-10, "P({r}, {c}) at {} s: {err:e}", fix.time_s);
                }
            }
        }
    }
    // The scale factor is learnt: its σ falls well below the prior's.
    let last = schedule.fixes.last().unwrap();
    assert!(last.p_post[(SCALE, SCALE)].sqrt() < 0.2 * SCALE_SIGMA);
}

/// The ensemble statistics of `realizations` realizations of the truth (the model's statistics,
/// scale-factor σ [`SCALE_SIGMA`]) filtered by a filter assuming `filter_scale_sigma`.
fn ensemble(realizations: u64, filter_scale_sigma: f64) -> EnsembleStats<N, M> {
    let model = model();
    let truth = four_state(&model, model.truth_stats, SCALE_SIGMA);
    let filter = four_state(&model, model.filter_stats, filter_scale_sigma);
    let schedule = FilterSchedule::<N, M>::of(&filter, &model.timeline).unwrap();
    let run = LinearRun {
        realizations,
        seed: 7,
        max_lag: model.residual_max_lag(),
        pair: model.residual_pair,
    };
    let sums = linear::run(&truth, &schedule, &model.timeline, &run);
    EnsembleStats::from_sums(&sums, &schedule)
}

#[test]
fn a_consistent_four_state_filter_passes_every_check() {
    let stats = ensemble(2_000, SCALE_SIGMA);
    assert_eq!(stats.fixes[0].prior.mean_error.len(), N);
    let budget = Budget::study(Config::default().checks.false_alarm_rate);
    let verdicts = checks::evaluate(&stats, &budget);
    for c in &verdicts.checks {
        assert_eq!(c.verdict, Verdict::Pass, "{:?}: {c:?}", c.id);
    }
    // Every state is a member of the per-state checks: the scale factor's members are there.
    let per_state = checks::CATALOGUE[0].count(&stats);
    let fixes = stats.fixes.len();
    // Constant states (bias, scale factor) count their a priori member at the first fix only.
    assert_eq!(per_state, fixes * (2 * N - 2) + 2);
}

#[test]
fn a_four_state_filter_that_underrates_the_scale_factor_fails() {
    let stats = ensemble(2_000, 0.1 * SCALE_SIGMA);
    let budget = Budget::study(Config::default().checks.false_alarm_rate);
    let verdicts = checks::evaluate(&stats, &budget);
    let failed: Vec<_> = verdicts
        .checks
        .iter()
        .filter(|c| c.verdict == Verdict::Fail)
        .map(|c| c.id)
        .collect();
    assert!(
        failed.contains(&checks::CheckId::NEES),
        "a tenfold too small scale-factor σ must fail NEES; failed: {failed:?}"
    );
}

/// The verdicts of the model-exact engine on the error state: the truth with `truth_stats`, the
/// filter with the model's.
fn error_state_verdicts(truth_stats: NoiseStats) -> checks::Verdicts {
    let model = model();
    let truth = ErrorState { stats: truth_stats };
    let filter = ErrorState {
        stats: model.filter_stats,
    };
    let schedule = FilterSchedule::of(&filter, &model.timeline).unwrap();
    let run = LinearRun {
        realizations: 2_000,
        seed: 3,
        max_lag: model.residual_max_lag(),
        pair: model.residual_pair,
    };
    let sums = linear::run(&truth, &schedule, &model.timeline, &run);
    let stats: EnsembleStats = EnsembleStats::from_sums(&sums, &schedule);
    let budget = Budget::study(Config::default().checks.false_alarm_rate);
    checks::evaluate(&stats, &budget)
}

/// The same model-exact engine on the error state itself: a filter that assumes the truth's
/// statistics passes every check, and one whose truth has twice the GPS position σ it assumes
/// fails NIS (the negative control: the engine's truth is the one configured).
#[test]
fn the_model_exact_engine_runs_the_error_state_too() {
    let stats = model().truth_stats;
    for c in &error_state_verdicts(stats).checks {
        assert_eq!(c.verdict, Verdict::Pass, "{:?}: {c:?}", c.id);
    }
    let noisier = NoiseStats {
        gps_position_sigma_m: 2.0 * stats.gps_position_sigma_m,
        ..stats
    };
    let v = error_state_verdicts(noisier);
    assert_eq!(v.get(checks::CheckId::NIS).verdict, Verdict::Fail);
}
