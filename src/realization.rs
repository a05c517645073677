//! One realization recorded in full: every accelerometer sample and every GPS fix.

use serde::Serialize;

use crate::filter::{FilterSchedule, Matrix3, Vector3};
use crate::model::Model;
use crate::simulation::{Draws, FixState, Observer, SampleState, run_realization};

/// The state at one accelerometer sample t_j.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleRecord {
    pub t_s: f64,
    /// True acceleration a(t_j), m/s².
    pub accel_m_s2: f64,
    pub truth_p_m: f64,
    pub truth_v_m_s: f64,
    pub computed_p_m: f64,
    pub computed_v_m_s: f64,
    /// True error state δx(t_j) = (p − p_c, v − v_c, b).
    pub delta_x: [f64; 3],
    /// The filter's estimate δx̂(t_j), propagated from the last fix.
    pub estimate: [f64; 3],
    /// The filter's σ = √diag P(t_j).
    pub sigma: [f64; 3],
    /// The filter's covariance P(t_j), row-major.
    pub cov: [[f64; 3]; 3],
}

/// A realization at one GPS fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixRecord {
    pub t_s: f64,
    pub delta_x: [f64; 3],
    pub prior: [f64; 3],
    pub post: [f64; 3],
    pub sigma_prior: [f64; 3],
    pub sigma_post: [f64; 3],
    /// A priori covariance P(t_i⁻), row-major.
    pub cov_prior: [[f64; 3]; 3],
    /// A posteriori covariance P(t_i⁺), row-major.
    pub cov_post: [[f64; 3]; 3],
    /// Residual r = δz − H·δx̂⁻, (m, m/s).
    pub residual: [f64; 2],
    /// Measurement δz = z − (p_c, v_c), (m, m/s).
    pub dz: [f64; 2],
}

/// One realization, recorded at every sample and every fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Realization {
    pub seed: u64,
    pub index: u64,
    pub p0_m: f64,
    pub v0_m_s: f64,
    pub bias_m_s2: f64,
    #[serde(skip)]
    pub samples: Vec<SampleRecord>,
    pub fixes: Vec<FixRecord>,
}

fn sigma(p: &Matrix3) -> [f64; 3] {
    std::array::from_fn(|k| p[(k, k)].sqrt())
}

fn rows(p: &Matrix3) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| p[(r, c)]))
}

struct Recorder<'a> {
    model: &'a Model,
    schedule: &'a FilterSchedule,
    estimate: Vector3,
    cov: Matrix3,
    samples: Vec<SampleRecord>,
    fixes: Vec<FixRecord>,
}

impl Observer for Recorder<'_> {
    const SAMPLES: bool = true;

    fn sample(&mut self, s: &SampleState) {
        let t_s = self.model.timeline.time_s(s.step);
        let p = &self.model.config.profile;
        self.samples.push(SampleRecord {
            t_s,
            accel_m_s2: p.accel_amplitude_m_s2 * (p.accel_angular_freq_rad_s * t_s).sin(),
            truth_p_m: s.truth_p_m,
            truth_v_m_s: s.truth_v_m_s,
            computed_p_m: s.computed_p_m,
            computed_v_m_s: s.computed_v_m_s,
            delta_x: [
                s.truth_p_m - s.computed_p_m,
                s.truth_v_m_s - s.computed_v_m_s,
                s.bias_m_s2,
            ],
            estimate: self.estimate.into(),
            sigma: sigma(&self.cov),
            cov: rows(&self.cov),
        });
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
    let mut rec = Recorder {
        model,
        schedule,
        estimate: Vector3::zeros(),
        cov: schedule.model.p0,
        samples: Vec::with_capacity(model.timeline.steps + 1),
        fixes: Vec::with_capacity(model.timeline.fixes()),
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
