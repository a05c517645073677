//! One realization recorded in full: every accelerometer sample and every GPS fix.

use serde::Serialize;

use crate::filter::{FilterSchedule, rows};
use crate::model::Model;
use crate::simulation::{Draws, FixState, Observer, SampleState, run_realization};
use crate::state::{ErrorState, StateMatrix, StateVector};

/// The state at one accelerometer sample t_j.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleRecord {
    /// Time t_j, s.
    pub t_s: f64,
    /// True acceleration a(t_j), m/s².
    pub accel_m_s2: f64,
    /// The accelerometer's output a_c(t_j) = a + b + w, m/s².
    pub accel_output_m_s2: f64,
    /// True position p(t_j), m.
    pub truth_p_m: f64,
    /// True velocity v(t_j), m/s.
    pub truth_v_m_s: f64,
    /// Integrated accelerometer position p_c(t_j), m.
    pub computed_p_m: f64,
    /// Integrated accelerometer velocity v_c(t_j), m/s.
    pub computed_v_m_s: f64,
    /// True error state δx(t_j) = (p − p_c, v − v_c, b).
    pub delta_x: [f64; ErrorState::DIM],
    /// The filter's estimate δx̂(t_j), propagated from the last fix.
    pub estimate: [f64; ErrorState::DIM],
    /// The filter's σ = √diag P(t_j).
    pub sigma: [f64; ErrorState::DIM],
    /// The filter's covariance P(t_j), row-major.
    pub cov: [[f64; ErrorState::DIM]; ErrorState::DIM],
}

/// A realization at one GPS fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixRecord {
    /// Time of the fix t_i, s.
    pub t_s: f64,
    /// True error state δx(t_i) = (p − p_c, v − v_c, b).
    pub delta_x: [f64; ErrorState::DIM],
    /// A priori estimate δx̂(t_i⁻).
    pub prior: [f64; ErrorState::DIM],
    /// A posteriori estimate δx̂(t_i⁺).
    pub post: [f64; ErrorState::DIM],
    /// A priori σ = √diag P(t_i⁻).
    pub sigma_prior: [f64; ErrorState::DIM],
    /// A posteriori σ = √diag P(t_i⁺).
    pub sigma_post: [f64; ErrorState::DIM],
    /// A priori covariance P(t_i⁻), row-major.
    pub cov_prior: [[f64; ErrorState::DIM]; ErrorState::DIM],
    /// A posteriori covariance P(t_i⁺), row-major.
    pub cov_post: [[f64; ErrorState::DIM]; ErrorState::DIM],
    /// Residual r = δz − H·δx̂⁻, (m, m/s).
    pub residual: [f64; ErrorState::MEAS],
    /// Measurement δz = z − (p_c, v_c), (m, m/s).
    pub dz: [f64; ErrorState::MEAS],
}

/// One realization, recorded at every sample and every fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Realization {
    /// Seed of the random streams.
    pub seed: u64,
    /// Index of the realization: its stream is (seed, index).
    pub index: u64,
    /// True initial position p(0), m.
    pub p0_m: f64,
    /// True initial velocity v(0), m/s.
    pub v0_m_s: f64,
    /// The realization's bias b, m/s².
    pub bias_m_s2: f64,
    /// The accelerometer samples, in time order: every one, or those a figure can show (see
    /// [`record_for_figures`]); not written to JSON.
    #[serde(skip)]
    pub samples: Vec<SampleRecord>,
    /// Every GPS fix.
    pub fixes: Vec<FixRecord>,
}

fn sigma(p: &StateMatrix) -> [f64; ErrorState::DIM] {
    std::array::from_fn(|k| p[(k, k)].sqrt())
}

/// The detail window of a run from `t0_s` to `t1_s`: two seconds from two thirds into the run
/// (20–22 s of 30 s), the whole run when it is shorter. Figures show every sample there.
pub fn detail_window(t0_s: f64, t1_s: f64) -> (f64, f64) {
    const DETAIL_S: f64 = 2.0;
    let span = t1_s - t0_s;
    if span <= DETAIL_S {
        return (t0_s, t1_s);
    }
    let start = (t0_s + 2.0 * span / 3.0)
        .floor()
        .min(t1_s - DETAIL_S)
        .max(t0_s);
    (start, start + DETAIL_S)
}

/// Samples a bucket keeps at most: its first, and the smallest and largest error of each state.
const KEPT_PER_BUCKET: usize = 1 + 2 * ErrorState::DIM;

/// Keeps a long run's samples to what a figure can show: every sample in the detail window, and
/// elsewhere, per bucket of consecutive samples, the first one and those where an error
/// component δx − δx̂ is smallest or largest, so that spikes survive.
struct Thinning {
    bucket: usize,
    window: (f64, f64),
    pending: Vec<SampleRecord>,
}

impl Thinning {
    fn flush(&mut self, out: &mut Vec<SampleRecord>) {
        if self.pending.is_empty() {
            return;
        }
        let error = |s: &SampleRecord, k: usize| s.delta_x[k] - s.estimate[k];
        let mut keep = vec![0];
        for k in 0..ErrorState::DIM {
            let by = |a: &&SampleRecord, b: &&SampleRecord| error(a, k).total_cmp(&error(b, k));
            let indexed = || self.pending.iter().enumerate();
            keep.extend(indexed().min_by(|a, b| by(&a.1, &b.1)).map(|(i, _)| i));
            keep.extend(indexed().max_by(|a, b| by(&a.1, &b.1)).map(|(i, _)| i));
        }
        keep.sort_unstable();
        keep.dedup();
        out.extend(keep.into_iter().map(|i| self.pending[i].clone()));
        self.pending.clear();
    }
}

struct Recorder<'a> {
    model: &'a Model,
    schedule: &'a FilterSchedule,
    estimate: StateVector,
    cov: StateMatrix,
    samples: Vec<SampleRecord>,
    fixes: Vec<FixRecord>,
    thinning: Option<Thinning>,
}

impl Observer for Recorder<'_> {
    const SAMPLES: bool = true;

    fn sample(&mut self, s: &SampleState) {
        let t_s = self.model.timeline.time_s(s.step);
        let p = &self.model.config.profile;
        let record = SampleRecord {
            t_s,
            accel_m_s2: p.accel_amplitude_m_s2 * (p.accel_angular_freq_rad_s * t_s).sin(),
            accel_output_m_s2: s.accel_output_m_s2,
            truth_p_m: s.truth_p_m,
            truth_v_m_s: s.truth_v_m_s,
            computed_p_m: s.computed_p_m,
            computed_v_m_s: s.computed_v_m_s,
            delta_x: s.delta_x().into(),
            estimate: self.estimate.into(),
            sigma: sigma(&self.cov),
            cov: rows(&self.cov),
        };
        match &mut self.thinning {
            None => self.samples.push(record),
            Some(thin) => {
                let in_window = t_s >= thin.window.0 && t_s <= thin.window.1;
                if in_window || s.step == self.model.timeline.steps {
                    thin.flush(&mut self.samples);
                    self.samples.push(record);
                } else {
                    thin.pending.push(record);
                    if thin.pending.len() == thin.bucket {
                        thin.flush(&mut self.samples);
                    }
                }
            }
        }
        // Propagate to the next sample: δx̂ ← Φ·δx̂, P ← Φ·P·Φᵀ + Q.
        let m = &self.schedule.model;
        self.estimate = m.phi * self.estimate;
        self.cov = m.propagate(&self.cov);
    }

    fn fix(&mut self, f: &FixState) {
        let c = &self.schedule.fixes[f.index];
        self.estimate = f.post;
        self.cov = c.p_post;
        self.fixes.push(FixRecord {
            t_s: c.time_s,
            delta_x: f.delta_x.into(),
            prior: f.prior.into(),
            post: f.post.into(),
            sigma_prior: sigma(&c.p_prior),
            sigma_post: sigma(&c.p_post),
            cov_prior: rows(&c.p_prior),
            cov_post: rows(&c.p_post),
            residual: f.residual.into(),
            dz: f.dz.into(),
        });
    }
}

/// Runs realization `index` under `seed` and records it in full.
pub fn record(model: &Model, schedule: &FilterSchedule, seed: u64, index: u64) -> Realization {
    record_with(model, schedule, seed, index, None)
}

/// Runs realization `index` under `seed` and records every fix, and of the samples what figures
/// of at most about `max_samples` points can show (see [`detail_window`]): every sample when the
/// run has no more, else every sample of the detail window and the first, smallest and largest
/// errors of each bucket of samples elsewhere. Memory then stays bounded for hour-long runs.
pub fn record_for_figures(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    index: u64,
    max_samples: usize,
) -> Realization {
    let steps = model.timeline.steps + 1;
    let thinning = (steps > max_samples).then(|| Thinning {
        bucket: (KEPT_PER_BUCKET * steps).div_ceil(max_samples.max(KEPT_PER_BUCKET)),
        window: detail_window(0.0, model.timeline.time_s(model.timeline.steps)),
        pending: Vec::new(),
    });
    record_with(model, schedule, seed, index, thinning)
}

fn record_with(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    index: u64,
    thinning: Option<Thinning>,
) -> Realization {
    let capacity = if thinning.is_some() {
        0
    } else {
        model.timeline.steps + 1
    };
    let mut rec = Recorder {
        model,
        schedule,
        estimate: StateVector::zeros(),
        cov: schedule.model.p0,
        samples: Vec::with_capacity(capacity),
        fixes: Vec::with_capacity(model.timeline.fixes()),
        thinning,
    };
    let Draws {
        p0_m,
        v0_m_s,
        bias_m_s2,
    } = run_realization(model, schedule, seed, index, &mut rec);
    Realization {
        seed,
        index,
        p0_m,
        v0_m_s,
        bias_m_s2,
        samples: rec.samples,
        fixes: rec.fixes,
    }
}
