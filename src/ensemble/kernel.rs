//! The per-sample engine on lane groups: [`LANES`] consecutive realizations simulated side by side,
//! each with its own random stream, performing exactly the operations of
//! [`crate::simulation::run_realization`] in the same order, so that every lane reproduces its
//! realization bit for bit (tested).

use super::lane_sums::{FixSink, LaneFix};
use crate::config::TruthModel;
use crate::filter::FilterSchedule;
use crate::lanes::{LANES, Lanes, Real};
use crate::model::Model;
use crate::random::LaneStreams;

/// The lane mask of a group with `active` realizations: 1 for the active lanes, 0 for the rest.
pub(super) fn lane_mask(active: usize) -> Lanes {
    Lanes(std::array::from_fn(|k| if k < active { 1.0 } else { 0.0 }))
}

/// Runs the realizations `first..first + LANES` of the streams `key` (only the first `active`
/// count; the others are zeroed at every fix) and hands each fix to `on_fix`.
#[inline(always)]
pub fn run_group(
    model: &Model,
    schedule: &FilterSchedule,
    key: u64,
    first: u64,
    active: usize,
    on_fix: &mut impl FixSink,
) {
    match model.truth() {
        TruthModel::Euler => run_group_with::<true>(model, schedule, key, first, active, on_fix),
        TruthModel::Analytic => {
            run_group_with::<false>(model, schedule, key, first, active, on_fix)
        }
    }
}

#[inline(always)]
fn run_group_with<const EULER: bool>(
    model: &Model,
    schedule: &FilterSchedule,
    key: u64,
    first: u64,
    active: usize,
    on_fix: &mut impl FixSink,
) {
    let cfg = &model.config;
    let ts = &model.truth_stats;
    let mask = lane_mask(active);
    let mut rng = LaneStreams::new(key, first);
    let s = Lanes::splat;
    // Draw order as in simulation::run_with: p(0), v(0), b.
    let p0 = s(cfg.initial.position_mean_m) + s(ts.initial_position_sigma_m) * rng.normal();
    let v0 = s(cfg.initial.velocity_mean_m_s) + s(ts.initial_velocity_sigma_m_s) * rng.normal();
    let b = s(ts.bias_var_m2_s4.sqrt()) * rng.normal();
    let w_sigma = s(ts.accel_noise_var_m2_s4.sqrt());
    let (eta_p_sigma, eta_v_sigma) = (s(ts.gps_position_sigma_m), s(ts.gps_velocity_sigma_m_s));
    let tl = &model.timeline;
    let dt = tl.dt_s;
    let half_dt2 = 0.5 * dt * dt;
    let accel = &model.accel_m_s2;

    let mut pc = s(cfg.initial.position_mean_m);
    let mut vc = s(cfg.initial.velocity_mean_m_s);
    let (mut pe, mut ve) = (p0, v0);
    let mut estimate = [Lanes::default(); 3];
    let mut j = 0;
    for (i, (&jf, fix)) in tl.fix_steps.iter().zip(&schedule.fixes).enumerate() {
        for &a in &accel[j..jf] {
            // eq. (2), then eq. (3); eq. (4) for the Euler truth.
            let ac = (s(a) + b) + w_sigma * rng.normal();
            pc += vc * s(dt) + ac * s(half_dt2);
            vc += ac * s(dt);
            if EULER {
                pe += ve * s(dt) + s(a * half_dt2);
                ve += s(a * dt);
            }
        }
        j = jf;
        let (tp, tv) = if EULER {
            (pe, ve)
        } else {
            let [dp, dv] = model.analytic_offsets_at_fix[i];
            (p0 + v0 * s(tl.time_s(jf)) + s(dp), v0 + s(dv))
        };
        let delta_x = [(tp - pc) * mask, (tv - vc) * mask, b * mask];
        let z = [
            tp + eta_p_sigma * rng.normal(),
            tv + eta_v_sigma * rng.normal(),
        ];
        let dz = [(z[0] - pc) * mask, (z[1] - vc) * mask];
        let (prior, post, residual) = fix.step(&estimate, &dz);
        estimate = post;
        on_fix.fix(
            i,
            &LaneFix {
                delta_x,
                prior,
                post,
                residual,
            },
        );
    }
}

/// Keeps only the sum of the bias estimates: enough to keep the optimizer from removing the work.
struct Discard(Lanes);

impl FixSink for Discard {
    #[inline(always)]
    fn fix(&mut self, _i: usize, f: &LaneFix) {
        self.0 += f.post[2];
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
    let mut sink = Discard(Lanes::default());
    run_group(model, schedule, key, first, active, &mut sink);
    sink.0.sum()
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

const _: () = assert!(LANES == super::sums::BATCH);
