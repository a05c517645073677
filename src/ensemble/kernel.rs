//! The per-sample engine on lane groups: [`LANES`](crate::lanes::LANES) consecutive realizations simulated side by side,
//! each with its own random stream, performing exactly the operations of
//! [`crate::simulation::run_realization`] in the same order, so that every lane reproduces its
//! realization bit for bit (tested).

use super::lane_sums::LaneFix;
use crate::config::TruthModel;
use crate::filter::{FilterSchedule, FixCovariance};
use crate::lanes::{Lanes, Real};
use crate::model::Model;
use crate::random::LaneStreams;
use crate::simulation::BiasDrift;
use crate::state::ErrorState;
use crate::state::step::{Euler, accel_output};

// The truth below is the error state written out component by component.
const _: () = assert!(
    ErrorState::DIM == 3 && ErrorState::MEAS == 2,
    "ensemble/kernel.rs: simulate the new state's truth in SampleGroup::next_fix (as simulation.rs)"
);

/// The lane mask of a group with `active` realizations: 1 for the active lanes, 0 for the rest.
pub(super) fn lane_mask(active: usize) -> Lanes {
    Lanes(std::array::from_fn(|k| if k < active { 1.0 } else { 0.0 }))
}

/// A lane group advanced fix by fix: [`LaneGroup::next_fix`] integrates up to the next fix and
/// runs the filter through it.
pub trait LaneGroup {
    /// Advances to fix `i` (the fixes come in order) with the filter's `fix`.
    fn next_fix(&mut self, i: usize, fix: &FixCovariance) -> LaneFix;
}

/// The per-sample simulation of realizations `first..first + LANES` (only the first `active`
/// count; the others are zeroed at every fix). `EULER`: the truth is eq. (4), else eq. (1).
pub struct SampleGroup<'a, const EULER: bool> {
    model: &'a Model,
    rng: LaneStreams,
    mask: Lanes,
    p0: Lanes,
    v0: Lanes,
    /// The bias b(t_j) at the next sample to integrate.
    b: Lanes,
    /// The truth's bias step, when it drifts.
    drift: Option<BiasDrift>,
    /// (p_c, v_c, p_E, v_E), eqs. (3) and (4).
    state: [Lanes; 4],
    estimate: [Lanes; ErrorState::DIM],
    /// The next sample to integrate.
    j: usize,
}

impl<'a, const EULER: bool> SampleGroup<'a, EULER> {
    /// The group of realizations `first..` of the streams `key`, its initial values drawn.
    #[inline(always)]
    pub fn new(model: &'a Model, key: u64, first: u64, active: usize) -> Self {
        let cfg = &model.config;
        let ts = &model.truth_stats;
        let mut rng = LaneStreams::new(key, first);
        let s = Lanes::splat;
        // Draw order as in simulation::run_with: p(0), v(0), b.
        let p0 = s(cfg.initial.position_mean_m) + s(ts.initial_position_sigma_m) * rng.normal();
        let v0 = s(cfg.initial.velocity_mean_m_s) + s(ts.initial_velocity_sigma_m_s) * rng.normal();
        let b = s(ts.bias_var_m2_s4.sqrt()) * rng.normal();
        Self {
            model,
            rng,
            mask: lane_mask(active),
            p0,
            v0,
            b,
            drift: BiasDrift::of(model),
            state: [
                s(cfg.initial.position_mean_m),
                s(cfg.initial.velocity_mean_m_s),
                p0,
                v0,
            ],
            estimate: [Lanes::default(); ErrorState::DIM],
            j: 0,
        }
    }
}

impl<const EULER: bool> LaneGroup for SampleGroup<'_, EULER> {
    #[inline(always)]
    fn next_fix(&mut self, i: usize, fix: &FixCovariance) -> LaneFix {
        let model = self.model;
        let ts = &model.truth_stats;
        let s = Lanes::splat;
        let tl = &model.timeline;
        let euler = Euler::new(tl.dt_s);
        let w_sigma = s(ts.accel_noise_var_m2_s4.sqrt());
        let mut b = self.b;
        let jf = tl.fix_steps[i];
        let [mut pc, mut vc, mut pe, mut ve] = self.state;
        let mut j = self.j;
        if let Some(drift) = self.drift {
            // As simulation::Run::integrate_drifting: w, then the bias's increment, per sample.
            for &a in &model.accel_m_s2[j..jf] {
                let ac = accel_output(s(a), b, w_sigma, self.rng.normal());
                (pc, vc) = euler.step((pc, vc), ac);
                if EULER {
                    (pe, ve) = euler.step((pe, ve), s(a));
                }
                b = drift.advance(b, self.rng.normal());
            }
            self.b = b;
            j = jf;
        }
        while j < jf {
            // The interval's noises in runs of the generator's buffer: the same numbers, in the
            // same order, as one `normal()` per sample.
            let w = self.rng.normals(jf - j);
            for (&a, &w) in model.accel_m_s2[j..].iter().zip(w) {
                // eq. (2), then eq. (3); eq. (4) for the Euler truth.
                let ac = accel_output(s(a), b, w_sigma, w);
                (pc, vc) = euler.step((pc, vc), ac);
                if EULER {
                    (pe, ve) = euler.step((pe, ve), s(a));
                }
            }
            j += w.len();
        }
        self.state = [pc, vc, pe, ve];
        self.j = jf;
        let (tp, tv) = if EULER {
            (pe, ve)
        } else {
            let [dp, dv] = model.analytic_offsets_at_fix[i];
            (
                self.p0 + self.v0 * s(tl.time_s(jf)) + s(dp),
                self.v0 + s(dv),
            )
        };
        let mask = self.mask;
        // δx = (δp, δv, b) in ErrorState order; z = (z_p, z_v) in measurement order.
        let delta_x = [(tp - pc) * mask, (tv - vc) * mask, b * mask];
        let z = [
            tp + s(ts.gps_position_sigma_m) * self.rng.normal(),
            tv + s(ts.gps_velocity_sigma_m_s) * self.rng.normal(),
        ];
        let dz = [
            (z[ErrorState::GPS_POSITION] - pc) * mask,
            (z[ErrorState::GPS_VELOCITY] - vc) * mask,
        ];
        let (prior, post, residual) = fix.step(&self.estimate, &dz);
        self.estimate = post;
        LaneFix {
            delta_x,
            prior,
            post,
            residual,
        }
    }
}

/// Runs the realizations `first..first + LANES` of the streams `key` (only the first `active`
/// count) and hands each fix to `on_fix`.
#[inline(always)]
pub fn run_group(
    model: &Model,
    schedule: &FilterSchedule,
    key: u64,
    first: u64,
    active: usize,
    on_fix: impl FnMut(usize, &LaneFix),
) {
    fn all<G: LaneGroup>(
        mut g: G,
        schedule: &FilterSchedule,
        mut on_fix: impl FnMut(usize, &LaneFix),
    ) {
        for (i, fix) in schedule.fixes.iter().enumerate() {
            let f = g.next_fix(i, fix);
            on_fix(i, &f);
        }
    }
    match model.truth() {
        TruthModel::Euler => all(
            SampleGroup::<true>::new(model, key, first, active),
            schedule,
            on_fix,
        ),
        TruthModel::Analytic => all(
            SampleGroup::<false>::new(model, key, first, active),
            schedule,
            on_fix,
        ),
    }
}

#[inline(always)]
fn bare_group_lanes(
    model: &Model,
    schedule: &FilterSchedule,
    key: u64,
    first: u64,
    active: usize,
) -> f64 {
    let mut acc = Lanes::default();
    run_group(model, schedule, key, first, active, |_, f| {
        acc += f.post[ErrorState::BIAS]
    });
    acc.sum()
}

crate::lanes::vectorized! {
    /// The bare kernel for benchmarks: one lane group without statistics; returns the sum of the
    /// final bias estimates.
    pub fn bare_group(
        model: &Model,
        schedule: &FilterSchedule,
        key: u64,
        first: u64,
        active: usize,
    ) -> f64 => bare_group_lanes
}
