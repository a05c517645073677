//! The validated study model: time grid, acceleration profile, truth, and the noise statistics of
//! the truth and of the filter. Built once from a [`Config`]; everything downstream reads it.

mod memory;
mod validate;

use crate::config::{AccelerometerOutput, Case, Config, TruthModel};
use crate::error::ConfigError;
pub use memory::{MemoryEstimate, Work};
pub use validate::validate_calibration;
use validate::{validate, whole};

use crate::state::ErrorState;
pub use crate::state::{BiasModel, NoiseStats};

/// Largest number of accelerometer samples in a run.
pub const MAX_STEPS: usize = 10_000_000;
/// Largest number of GPS fixes in a run.
pub const MAX_FIXES: usize = 1_000_000;
/// Largest memory the running sums of one block of realizations may take, bytes:
/// [`SUM_FLOATS_PER_FIX`] floats per fix and the kept residual products. A run holds a few of
/// them at once (two per thread at most, and the total).
pub const MAX_SUMS_BYTES: usize = 256 << 20;
/// Floats of an ensemble's running sums at one fix in memory (`ensemble::FixSums`, which checks
/// at compile time that it has this size): for the a priori and the a posteriori stage each
/// [`SUM_FLOATS_PER_STAGE`], then Σ NIS.
pub const SUM_FLOATS_PER_FIX: usize = 2 * SUM_FLOATS_PER_STAGE + 1;
/// Floats of an ensemble's running sums of one stage at one fix in memory (`ensemble::StageSums`)
/// for the n states of the error state: Σe (n), Σe·eᵀ (n²), Σe·δx̂ᵀ (n²), Σδx̂ (n), Σδx̂² (n),
/// Σ NEES.
pub const SUM_FLOATS_PER_STAGE: usize = {
    let n = ErrorState::DIM;
    n + n * n + n * n + n + n + 1
};
/// Components of one GPS residual (position, velocity): the residual products per pair of fixes
/// are its square.
pub const RESIDUAL_WIDTH: usize = ErrorState::MEAS;
/// Runs with at most this many fixes test the residual whiteness of every pair of fixes by
/// default; longer runs test lags up to [`DEFAULT_MAX_LAG`] (every pair costs O(fixes²)).
pub const ALL_PAIRS_MAX_FIXES: usize = 1_000;
/// The default largest lag of the residual whiteness check beyond [`ALL_PAIRS_MAX_FIXES`] fixes.
pub const DEFAULT_MAX_LAG: usize = 50;
/// Largest ensemble.
pub const MAX_REALIZATIONS: u64 = 100_000_000;

/// Smallest variance or standard deviation the filter may assume.
pub use crate::config::FILTER_FLOOR;

/// Relative tolerance used to decide that a ratio of rates or times is a whole number.
const WHOLE_TOL: f64 = 1e-9;

/// The time grid: accelerometer samples t_j = j·Δt, j = 0..=steps, and the GPS fixes among them.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// Accelerometer sample period Δt, s.
    pub dt_s: f64,
    /// Number of accelerometer samples integrated; the run ends at t = steps·Δt.
    pub steps: usize,
    /// Accelerometer samples between two GPS fixes.
    pub steps_per_fix: usize,
    /// Sample index j of every GPS fix, increasing.
    pub fix_steps: Vec<usize>,
}

impl Timeline {
    /// Time of accelerometer sample j, s.
    pub fn time_s(&self, j: usize) -> f64 {
        j as f64 * self.dt_s
    }

    /// Times of the GPS fixes, s.
    pub fn fix_times_s(&self) -> Vec<f64> {
        self.fix_steps.iter().map(|&j| self.time_s(j)).collect()
    }

    /// Number of GPS fixes.
    pub fn fixes(&self) -> usize {
        self.fix_steps.len()
    }

    /// Index of the fix at time `t_s`, if a fix falls there.
    pub fn fix_index_at(&self, t_s: f64) -> Option<usize> {
        let j = whole(t_s / self.dt_s)?;
        self.fix_steps.binary_search(&(j as usize)).ok()
    }

    /// Time of fix `i`, s.
    pub fn fix_time_s(&self, i: usize) -> f64 {
        self.time_s(self.fix_steps[i])
    }
}

/// The validated model of one study.
#[derive(Clone, Debug)]
pub struct Model {
    /// The configuration it was built from.
    pub config: Config,
    /// The time grid.
    pub timeline: Timeline,
    /// The deterministic part of the accelerometer output at every sample j = 0..=steps, m/s²:
    /// a(t_j) for point samples, the mean of a(t) over [t_j, t_j + Δt] for interval means. The
    /// Euler truth (eq. 4) integrates these values too, so that eq. (5) is exact for it; the value
    /// at the last sample is integrated by no step and only enters a log of the sensor.
    pub accel_m_s2: Vec<f64>,
    /// The truth's noise statistics.
    pub truth_stats: NoiseStats,
    /// The filter's assumed noise statistics.
    pub filter_stats: NoiseStats,
    /// The fix indices [m, i], m < i, of the single residual pair the problem statement asks
    /// for: `checks.residual_pair_s`, or the fixes nearest one third and two thirds of the run.
    pub residual_pair: [usize; 2],
    /// The part of the closed-form truth that does not depend on p(0), v(0), at every fix:
    /// (p(t) − p(0) − v(0)·t, v(t) − v(0)), so eq. (1) costs no trigonometry per realization.
    pub analytic_offsets_at_fix: Vec<[f64; 2]>,
}

impl Model {
    /// Validates `config` and derives the model.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first field outside its accepted range.
    pub fn new(config: &Config) -> Result<Self, ConfigError> {
        validate(config)?;
        let p = &config.profile;
        let a = &config.accelerometer;
        let g = &config.gps;
        let dt_s = 1.0 / a.sample_rate_hz;
        let steps = whole(p.duration_s * a.sample_rate_hz).expect("validated") as usize;
        let steps_per_fix = whole(a.sample_rate_hz / g.sample_rate_hz).expect("validated") as usize;
        let first = if g.fix_at_start { 0 } else { steps_per_fix };
        let fix_steps: Vec<usize> = (first..=steps).step_by(steps_per_fix).collect();
        let timeline = Timeline {
            dt_s,
            steps,
            steps_per_fix,
            fix_steps,
        };
        let accel_m_s2 = accelerometer_input(config, &timeline, config.accelerometer.output);
        let truth_stats = config.truth_stats();
        let filter_stats = filter_stats(config);
        let residual_pair = match config.checks.residual_pair_s {
            Some(times) => times.map(|t| timeline.fix_index_at(t).expect("validated fix time")),
            None => {
                let n = timeline.fixes();
                let near = |frac: f64| {
                    let t = frac * timeline.time_s(timeline.steps);
                    (0..n)
                        .min_by(|&a, &b| {
                            let da = (timeline.fix_time_s(a) - t).abs();
                            let db = (timeline.fix_time_s(b) - t).abs();
                            da.total_cmp(&db)
                        })
                        .expect("at least two fixes")
                };
                let m = near(1.0 / 3.0).min(n - 2);
                [m, near(2.0 / 3.0).max(m + 1)]
            }
        };
        let analytic_offsets_at_fix = timeline
            .fix_steps
            .iter()
            .map(|&j| analytic_offsets(config, timeline.time_s(j)))
            .collect();
        Ok(Self {
            config: config.clone(),
            residual_pair,
            analytic_offsets_at_fix,
            timeline,
            accel_m_s2,
            truth_stats,
            filter_stats,
        })
    }

    /// The largest lag, in fixes, of the residual pairs the ensemble keeps and the whiteness
    /// check tests: `checks.residual_max_lag`, or by default every pair (`None`) up to
    /// [`ALL_PAIRS_MAX_FIXES`] fixes and [`DEFAULT_MAX_LAG`] beyond.
    pub fn residual_max_lag(&self) -> Option<usize> {
        match self.config.checks.residual_max_lag {
            Some(l) => Some(l as usize),
            None if self.timeline.fixes() <= ALL_PAIRS_MAX_FIXES => None,
            None => Some(DEFAULT_MAX_LAG),
        }
    }

    /// Which truth model the ensemble simulates (`ensemble.truth`).
    pub fn truth(&self) -> TruthModel {
        self.config.ensemble.truth
    }

    /// The simulated case: the truth model and the accelerometer output.
    pub fn case(&self) -> Case {
        self.config.case()
    }

    /// The same model with another truth model.
    pub fn with_truth(&self, truth: TruthModel) -> Self {
        self.with_case(Case {
            truth,
            output: self.config.accelerometer.output,
        })
    }

    /// The same model simulating another case.
    pub fn with_case(&self, case: Case) -> Self {
        let mut m = self.clone();
        m.config.ensemble.truth = case.truth;
        if m.config.accelerometer.output != case.output {
            m.config.accelerometer.output = case.output;
            m.accel_m_s2 = accelerometer_input(&m.config, &m.timeline, case.output);
        }
        m
    }

    /// Closed-form true position and velocity at time `t_s` for initial values `p0_m`, `v0_m_s`:
    /// eq. (1), p(t) = p0 + (v0 + A/ω)·t − (A/ω²)·sin(ωt), v(t) = v0 + (A/ω)·(1 − cos(ωt)).
    pub fn analytic_truth(&self, t_s: f64, p0_m: f64, v0_m_s: f64) -> (f64, f64) {
        let [dp, dv] = analytic_offsets(&self.config, t_s);
        (p0_m + v0_m_s * t_s + dp, v0_m_s + dv)
    }

    /// [`Model::analytic_truth`] at fix `i`, from the tabulated offsets.
    #[inline]
    pub fn analytic_truth_at_fix(&self, i: usize, t_s: f64, p0_m: f64, v0_m_s: f64) -> (f64, f64) {
        let [dp, dv] = self.analytic_offsets_at_fix[i];
        (p0_m + v0_m_s * t_s + dp, v0_m_s + dv)
    }
}

/// The statistics the filter assumes: each `[filter]` key, or the truth's value where it is left
/// out (of a configuration whose filter keys are valid: [`Model::new`] or
/// [`validate_calibration`]).
pub fn filter_stats(config: &Config) -> NoiseStats {
    config.filter_stats()
}

/// The deterministic accelerometer input at every sample (see [`Model::accel_m_s2`]).
///
/// # Formula
/// Point samples: a(t_j) = A·sin(ω·t_j). Interval means: (1/Δt)∫ A·sin(ωt) dt over
/// [t_j, t_j + Δt] = A·sin(ω·(t_j + Δt/2))·sin(ωΔt/2)/(ωΔt/2), written so that nothing cancels.
fn accelerometer_input(config: &Config, tl: &Timeline, output: AccelerometerOutput) -> Vec<f64> {
    let a = config.profile.accel_amplitude_m_s2;
    let w = config.profile.accel_angular_freq_rad_s;
    let half = 0.5 * w * tl.dt_s;
    let sinc = if half == 0.0 { 1.0 } else { half.sin() / half };
    (0..=tl.steps)
        .map(|j| {
            let t = tl.time_s(j);
            match output {
                AccelerometerOutput::Sample => a * (w * t).sin(),
                AccelerometerOutput::IntervalMean => a * (w * (t + 0.5 * tl.dt_s)).sin() * sinc,
            }
        })
        .collect()
}

/// The closed-form truth less its initial-value terms: ((A/ω)·t − (A/ω²)·sin ωt, (A/ω)·(1 − cos ωt)),
/// written as (A·t²·(x − sin x)/x², A·t·2·sin²(x/2)/x) with x = ωt so that no large terms cancel
/// when ωt is small.
fn analytic_offsets(config: &Config, t_s: f64) -> [f64; 2] {
    let a = config.profile.accel_amplitude_m_s2;
    let x = config.profile.accel_angular_freq_rad_s * t_s;
    if x == 0.0 {
        return [0.0, 0.0];
    }
    // (x − sin x)/x²: its Taylor series below 0.5 rad, where the difference would lose digits.
    let g = if x.abs() < 0.5 {
        let x2 = x * x;
        x / 6.0
            * (1.0
                - x2 / 20.0
                    * (1.0
                        - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0 * (1.0 - x2 / 156.0)))))
    } else {
        (x - x.sin()) / (x * x)
    };
    let h = 2.0 * (0.5 * x).sin().powi(2) / x;
    [a * t_s * t_s * g, a * t_s * h]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_timeline_matches_the_statement() {
        let m = Model::new(&Config::default()).unwrap();
        let t = &m.timeline;
        assert_eq!(t.steps, 6000);
        assert_eq!(t.steps_per_fix, 40);
        assert_eq!(t.fixes(), 150);
        assert_eq!(t.fix_steps[0], 40);
        assert_eq!(*t.fix_steps.last().unwrap(), 6000);
        assert_eq!(t.fix_index_at(10.0), Some(49));
        assert_eq!(m.residual_pair.map(|i| t.fix_time_s(i)), [10.0, 20.0]);
        let mut c = Config::default();
        c.profile.duration_s = 0.4;
        let m = Model::new(&c).unwrap();
        assert_eq!(
            m.residual_pair.map(|i| m.timeline.fix_time_s(i)),
            [0.2, 0.4]
        );
    }

    #[test]
    fn fix_at_start_adds_a_fix_at_zero() {
        let mut c = Config::default();
        c.gps.fix_at_start = true;
        let m = Model::new(&c).unwrap();
        assert_eq!(m.timeline.fixes(), 151);
        assert_eq!(m.timeline.fix_steps[0], 0);
    }

    #[test]
    fn analytic_truth_is_accurate_for_small_angles() {
        let mut c = Config::default();
        c.profile.accel_angular_freq_rad_s = 1e-9;
        let m = Model::new(&c).unwrap();
        // For ωt → 0 the profile is a ≈ A·ω·t: v = A·ω·t²/2, p = A·ω·t³/6.
        let (p, v) = m.analytic_truth(30.0, 0.0, 0.0);
        approx::assert_relative_eq!(v, 10.0 * 1e-9 * 900.0 / 2.0, max_relative = 1e-9);
        approx::assert_relative_eq!(p, 10.0 * 1e-9 * 27000.0 / 6.0, max_relative = 1e-9);
        // Both branches of the series agree where they meet.
        let c = Config::default();
        let w = c.profile.accel_angular_freq_rad_s;
        let below = analytic_offsets(&c, 0.4999999 / w);
        let above = analytic_offsets(&c, 0.5000001 / w);
        approx::assert_relative_eq!(below[0], above[0], max_relative = 1e-5);
    }

    #[test]
    fn interval_means_integrate_the_profile_exactly() {
        let mut c = Config::default();
        c.accelerometer.output = AccelerometerOutput::IntervalMean;
        let m = Model::new(&c).unwrap();
        let dt = m.timeline.dt_s;
        // Δt times the interval mean is the exact velocity increment of eq. (1).
        for j in [0, 1, 777, 5999] {
            let t = m.timeline.time_s(j);
            let dv = m.analytic_truth(t + dt, 0.0, 0.0).1 - m.analytic_truth(t, 0.0, 0.0).1;
            approx::assert_relative_eq!(
                m.accel_m_s2[j] * dt,
                dv,
                max_relative = 1e-9,
                epsilon = 1e-15
            );
        }
        // Switching the case back restores point samples.
        let back = m.with_case(Case::REPORT[1]);
        assert_eq!(
            back.accel_m_s2,
            Model::new(&Config::default()).unwrap().accel_m_s2
        );
    }

    #[test]
    fn analytic_truth_integrates_the_profile() {
        let m = Model::new(&Config::default()).unwrap();
        let (p0, v0) = m.analytic_truth(0.0, 3.0, 100.0);
        assert!((p0 - 3.0).abs() < 1e-12 && (v0 - 100.0).abs() < 1e-12);
        // Central difference of v must be a(t).
        let (t, h) = (7.3, 1e-4);
        let dv =
            (m.analytic_truth(t + h, 0.0, 0.0).1 - m.analytic_truth(t - h, 0.0, 0.0).1) / (2.0 * h);
        let a = 10.0 * (m.config.profile.accel_angular_freq_rad_s * t).sin();
        assert!((dv - a).abs() < 1e-6, "{dv} vs {a}");
    }
}
