//! One realization of the study: truth, accelerometer, GPS, and the filter's estimate.
//!
//! The simulation is literal: the accelerometer output a_c = a + b + w is drawn at every sample
//! and integrated with the Euler formula of eq. (3); the truth is eq. (1) ("analytic") or eq. (4)
//! ("euler"); the GPS measures the truth plus white noise; the filter sees δz = z − (p_c, v_c),
//! eq. (6). What a caller keeps of a realization is decided by its [`Observer`].

use crate::config::{Case, TruthModel};
use crate::filter::FilterSchedule;
use crate::lanes::Real;
use crate::model::Model;
pub use crate::random::Stream;
use crate::random::splitmix64;
use crate::state::step::{Euler, accel_output};
use crate::state::{ErrorState, MeasVector, StateVector};

/// The key of the random streams of `case` under `seed`: realization l draws from
/// `Stream::new(key, l)`.
pub fn stream_key(seed: u64, case: Case) -> u64 {
    splitmix64(seed ^ splitmix64(0xC0DE_CA5E ^ case.stream_key()))
}

/// The random stream of realization `index` of `case` under `seed`. It depends on nothing else,
/// so results do not depend on the thread count or on how the ensemble is split, and different
/// cases draw independent numbers.
pub fn stream(seed: u64, case: Case, index: u64) -> Stream {
    Stream::new(stream_key(seed, case), index)
}

/// Where a realization's standard normal numbers come from.
pub trait Noise {
    /// The next standard normal number.
    fn normal(&mut self) -> f64;
}

impl Noise for Stream {
    #[inline]
    fn normal(&mut self) -> f64 {
        Stream::normal(self)
    }
}

/// No noise at all: every draw is its mean. A realization driven by it is the deterministic part
/// of every realization (the system is linear), so its errors are the ensemble's expected errors.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoNoise;

impl Noise for NoNoise {
    #[inline]
    fn normal(&mut self) -> f64 {
        0.0
    }
}

/// The state of a realization at one accelerometer sample t_j (after the fix update, if any).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleState {
    /// Sample index j.
    pub step: usize,
    /// True position p(t_j), m.
    pub truth_p_m: f64,
    /// True velocity v(t_j), m/s.
    pub truth_v_m_s: f64,
    /// Integrated accelerometer position p_c(t_j), m.
    pub computed_p_m: f64,
    /// Integrated accelerometer velocity v_c(t_j), m/s.
    pub computed_v_m_s: f64,
    /// The realization's bias b(t_j), m/s² (constant unless the truth's bias drifts).
    pub bias_m_s2: f64,
    /// The accelerometer's output a_c(t_j) = a + b + w, eq. (2): what a log of the sensor holds.
    /// It is integrated over [t_j, t_{j+1}]; at the last sample, which no step integrates, it is
    /// drawn after every other number of the realization.
    pub accel_output_m_s2: f64,
}

impl SampleState {
    /// The true error state δx(t_j) = (p − p_c, v − v_c, b).
    pub fn delta_x(&self) -> StateVector {
        error_state(
            self.truth_p_m - self.computed_p_m,
            self.truth_v_m_s - self.computed_v_m_s,
            self.bias_m_s2,
        )
    }
}

/// What a realization produced at one GPS fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixState {
    /// Fix index i.
    pub index: usize,
    /// True error state δx(t_i) = (p − p_c, v − v_c, b).
    pub delta_x: StateVector,
    /// A priori estimate δx̂(t_i⁻).
    pub prior: StateVector,
    /// A posteriori estimate δx̂(t_i⁺).
    pub post: StateVector,
    /// Residual r(t_i) = δz − H·δx̂⁻.
    pub residual: MeasVector,
    /// The measurement δz(t_i) = z − (p_c, v_c).
    pub dz: MeasVector,
    /// The GPS fix z(t_i) = (p + η_p, v + η_v): what a log of the receiver holds, (m, m/s).
    pub z: MeasVector,
}

/// Receives what a realization produces. Both hooks default to doing nothing.
pub trait Observer {
    /// Whether [`Observer::sample`] is wanted; when false the kernel skips computing its input.
    const SAMPLES: bool = false;
    /// Called at every accelerometer sample j = 0..=steps, after any fix update at j.
    #[inline]
    fn sample(&mut self, _state: &SampleState) {}
    /// Called at every GPS fix, in order.
    fn fix(&mut self, state: &FixState);
}

/// The initial values drawn for a realization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draws {
    /// True initial position p(0), m.
    pub p0_m: f64,
    /// True initial velocity v(0), m/s.
    pub v0_m_s: f64,
    /// Bias b(0), m/s².
    pub bias_m_s2: f64,
}

/// Runs realization `index` of `model` under `seed` through the filter `schedule`, reporting to
/// `observer`. Draw order: p(0), v(0), b; then, fix by fix, w at every sample up to the fix (each
/// followed by the bias's increment η_b when the truth's bias drifts) and (η_p, η_v) at the fix;
/// then, for an observer that records samples, the same after the last fix and w of the last
/// sample's output.
pub fn run_realization<O: Observer>(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    index: u64,
    observer: &mut O,
) -> Draws {
    run_with(
        model,
        schedule,
        &mut stream(seed, model.case(), index),
        observer,
    )
}

/// Runs the noise-free realization of `model`: initial values at their means, zero bias, no
/// accelerometer or GPS noise. Its errors are the expected errors of every realization.
pub fn run_noise_free<O: Observer>(
    model: &Model,
    schedule: &FilterSchedule,
    observer: &mut O,
) -> Draws {
    run_with(model, schedule, &mut NoNoise, observer)
}

/// The simulation of one realization with the normal numbers of `rng`.
fn run_with<N: Noise, O: Observer>(
    model: &Model,
    schedule: &FilterSchedule,
    rng: &mut N,
    observer: &mut O,
) -> Draws {
    let cfg = &model.config;
    let ts = &model.truth_stats;
    let draws = Draws {
        p0_m: cfg.initial.position_mean_m + ts.initial_position_sigma_m * rng.normal(),
        v0_m_s: cfg.initial.velocity_mean_m_s + ts.initial_velocity_sigma_m_s * rng.normal(),
        bias_m_s2: ts.bias_var_m2_s4.sqrt() * rng.normal(),
    };
    let run = Run::new(model, draws);
    let tl = &model.timeline;
    // eq. (3) starts from the prior means; eq. (4) from the true initial values.
    let mut s = [
        cfg.initial.position_mean_m,
        cfg.initial.velocity_mean_m_s,
        draws.p0_m,
        draws.v0_m_s,
    ];
    let mut estimate = StateVector::zeros();
    let mut j = 0;
    let mut bias = draws.bias_m_s2;
    for (i, (&jf, fix)) in tl.fix_steps.iter().zip(&schedule.fixes).enumerate() {
        // The constant bias keeps its own loop, so that it costs what it did before drift existed.
        match run.drift {
            None => s = run.integrate(j, jf, s, rng, observer),
            Some(drift) => {
                (s, bias) = run.integrate_drifting(j, jf, (s, bias), drift, rng, observer)
            }
        }
        j = jf;
        let (delta_x, z, dz) = run.measure(i, jf, s, bias, rng);
        let (prior, post, residual) = fix.step(&estimate.into(), &dz.into());
        let (prior, post, residual) = (prior.into(), post.into(), MeasVector::from(residual));
        estimate = post;
        observer.fix(&FixState {
            index: i,
            delta_x,
            prior,
            post,
            residual,
            dz,
            z,
        });
    }
    if O::SAMPLES {
        let end = match run.drift {
            None => run.integrate(j, tl.steps, s, rng, observer),
            Some(drift) => {
                let end;
                (end, bias) = run.integrate_drifting(j, tl.steps, (s, bias), drift, rng, observer);
                end
            }
        };
        let ac = accel_output(model.accel_m_s2[tl.steps], bias, run.w_sigma, rng.normal());
        observer.sample(&run.sample(tl.steps, end, bias, ac));
    }
    draws
}

/// The truth's drifting bias over one accelerometer step: b ← φ·b + √q_b·η_b (see
/// [`crate::state::BiasModel::step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiasDrift {
    /// φ(Δt).
    pub phi: f64,
    /// √q_b(Δt), m/s².
    pub sigma_m_s2: f64,
}

impl BiasDrift {
    /// The bias after one step from `b`, with the standard normal increment `eta`:
    /// φ·b + √q_b·η_b, for one realization or a lane group (the same bits).
    #[inline(always)]
    pub fn advance<R: Real>(self, b: R, eta: R) -> R {
        R::splat(self.phi) * b + R::splat(self.sigma_m_s2) * eta
    }

    /// The drift of `model`'s truth over one step, `None` for a constant bias.
    pub fn of(model: &Model) -> Option<Self> {
        let ts = &model.truth_stats;
        ts.bias_model.drifts().then(|| {
            let (phi, q) = ts.bias_model.step(model.timeline.dt_s, ts.bias_var_m2_s4);
            BiasDrift {
                phi,
                sigma_m_s2: q.sqrt(),
            }
        })
    }
}

/// What stays fixed through one realization: the model, the initial draws and the step constants.
struct Run<'a> {
    model: &'a Model,
    draws: Draws,
    /// The bias's step, when it drifts.
    drift: Option<BiasDrift>,
    /// σ of the accelerometer's white noise w, m/s².
    w_sigma: f64,
    /// The step of eqs. (3) and (4).
    euler: Euler,
}

impl<'a> Run<'a> {
    fn new(model: &'a Model, draws: Draws) -> Self {
        Run {
            model,
            draws,
            drift: BiasDrift::of(model),
            w_sigma: model.truth_stats.accel_noise_var_m2_s4.sqrt(),
            euler: Euler::new(model.timeline.dt_s),
        }
    }

    /// The true position and velocity at sample `j`, given the Euler-integrated truth (p_E, v_E).
    fn truth_at(&self, j: usize, pe: f64, ve: f64) -> (f64, f64) {
        let d = &self.draws;
        match self.model.truth() {
            TruthModel::Analytic => {
                let t_s = self.model.timeline.time_s(j);
                self.model.analytic_truth(t_s, d.p0_m, d.v0_m_s)
            }
            TruthModel::Euler => (pe, ve),
        }
    }

    /// The state at sample `j` from the integration state (p_c, v_c, p_E, v_E), the bias b(t_j)
    /// and the output a_c.
    fn sample(&self, j: usize, [pc, vc, pe, ve]: [f64; 4], bias: f64, ac: f64) -> SampleState {
        let (tp, tv) = self.truth_at(j, pe, ve);
        SampleState {
            step: j,
            truth_p_m: tp,
            truth_v_m_s: tv,
            computed_p_m: pc,
            computed_v_m_s: vc,
            bias_m_s2: bias,
            accel_output_m_s2: ac,
        }
    }

    /// The integration state (p_c, v_c, p_E, v_E) advanced sample by sample from `j` to `end`.
    /// It is passed by value so that it lives in registers through the hot loop.
    #[inline(always)]
    fn integrate<N: Noise, O: Observer>(
        &self,
        j: usize,
        end: usize,
        state: [f64; 4],
        rng: &mut N,
        obs: &mut O,
    ) -> [f64; 4] {
        let (b, w_sigma, euler) = (self.draws.bias_m_s2, self.w_sigma, self.euler);
        let [mut pc, mut vc, mut pe, mut ve] = state;
        for (k, &a) in self.model.accel_m_s2[j..end].iter().enumerate() {
            // eq. (2): the accelerometer's output.
            let ac = accel_output(a, b, w_sigma, rng.normal());
            if O::SAMPLES {
                obs.sample(&self.sample(j + k, [pc, vc, pe, ve], b, ac));
            }
            // eq. (3): position uses the velocity before the step.
            (pc, vc) = euler.step((pc, vc), ac);
            // eq. (4): the true acceleration through the same formula.
            (pe, ve) = euler.step((pe, ve), a);
        }
        [pc, vc, pe, ve]
    }

    /// [`Run::integrate`] with a drifting bias: after each sample's w, the bias's increment η_b
    /// moves b(t_j) to b(t_{j+1}) = φ·b(t_j) + √q_b·η_b. Returns the integration state and the
    /// bias at `end`.
    #[inline(always)]
    fn integrate_drifting<N: Noise, O: Observer>(
        &self,
        j: usize,
        end: usize,
        (state, bias): ([f64; 4], f64),
        drift: BiasDrift,
        rng: &mut N,
        obs: &mut O,
    ) -> ([f64; 4], f64) {
        let (w_sigma, euler) = (self.w_sigma, self.euler);
        let [mut pc, mut vc, mut pe, mut ve] = state;
        let mut b = bias;
        for (k, &a) in self.model.accel_m_s2[j..end].iter().enumerate() {
            // eq. (2): the accelerometer's output, the bias held over the step.
            let ac = accel_output(a, b, w_sigma, rng.normal());
            if O::SAMPLES {
                obs.sample(&self.sample(j + k, [pc, vc, pe, ve], b, ac));
            }
            (pc, vc) = euler.step((pc, vc), ac);
            (pe, ve) = euler.step((pe, ve), a);
            b = drift.advance(b, rng.normal());
        }
        ([pc, vc, pe, ve], b)
    }

    /// The true error state δx, the GPS fix z and the filter's measurement δz at fix `i` (sample
    /// `jf`), from the integration state (p_c, v_c, p_E, v_E) and the bias b(t_i).
    fn measure<N: Noise>(
        &self,
        i: usize,
        jf: usize,
        [pc, vc, pe, ve]: [f64; 4],
        bias: f64,
        rng: &mut N,
    ) -> (StateVector, MeasVector, MeasVector) {
        let d = &self.draws;
        let (tp, tv) = match self.model.truth() {
            TruthModel::Analytic => {
                let t_s = self.model.timeline.time_s(jf);
                self.model.analytic_truth_at_fix(i, t_s, d.p0_m, d.v0_m_s)
            }
            TruthModel::Euler => (pe, ve),
        };
        let delta_x = error_state(tp - pc, tv - vc, bias);
        // eq. (6): δz = z − (p_c, v_c), with z the receiver's fix.
        let ts = &self.model.truth_stats;
        // Drawn in this order: η_p, then η_v.
        let zp = tp + ts.gps_position_sigma_m * rng.normal();
        let zv = tv + ts.gps_velocity_sigma_m_s * rng.normal();
        (delta_x, measurement(zp, zv), measurement(zp - pc, zv - vc))
    }
}

// A GPS measurement is (position, velocity), and the true error state (δp, δv, b) is simulated
// component by component (`Run::measure`, `SampleState::delta_x`): a new state or measured
// component needs its truth simulated here, in `error_state` and `measurement`, before the
// program compiles again.
const _: () = assert!(
    ErrorState::DIM == 3 && ErrorState::MEAS == 2,
    "simulation.rs: simulate the new state's truth (error_state, Run::measure, SampleState)"
);

/// A GPS measurement (or its difference to the integration) from its position and velocity.
pub fn measurement(position_m: f64, velocity_m_s: f64) -> MeasVector {
    let mut z = MeasVector::zeros();
    z[ErrorState::GPS_POSITION] = position_m;
    z[ErrorState::GPS_VELOCITY] = velocity_m_s;
    z
}

/// The error state δx = (δp, δv, b) from its components.
pub fn error_state(dp_m: f64, dv_m_s: f64, bias_m_s2: f64) -> StateVector {
    let mut x = StateVector::zeros();
    x[ErrorState::POSITION] = dp_m;
    x[ErrorState::VELOCITY] = dv_m_s;
    x[ErrorState::BIAS] = bias_m_s2;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_fixed_by_seed_and_index() {
        let case = Case::REPORT[0];
        let a: Vec<u64> = (0..4).map(|_| stream(7, case, 3).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(stream(7, case, 3).next_u64(), stream(7, case, 4).next_u64());
        assert_ne!(stream(7, case, 3).next_u64(), stream(8, case, 3).next_u64());
        let first: Vec<u64> = Case::REPORT
            .iter()
            .map(|&c| stream(7, c, 3).next_u64())
            .collect();
        assert!(first[0] != first[1] && first[1] != first[2] && first[0] != first[2]);
    }
}
