//! The epoch-level engine: exact in distribution at the fixes, with one draw per interval.
//!
//! Between two fixes the accelerometer noises w(t_j) enter the error state only through their
//! effect on (δp, δv) at the next fix: with n samples of Δt in the interval, eq. (5) gives
//! ν = −Σ_k w_k·(Δt²/2 + (n − 1 − k)·Δt², Δt), a 2-D Gaussian with covariance
//!
//! ```text
//! W·G(n),  G = [Δt⁴·(n³/3 − n/12)   n²·Δt³/2]
//!              [n²·Δt³/2            n·Δt²   ]
//! ```
//!
//! (the sum Σ Φᵏ·Q·Φᵏᵀ of the filter's own recursion, restricted to δp, δv). The rest of δx(t_i) is
//! deterministic given the initial errors and the bias: δp = D_p(t_i) + δp(0) + δv(0)·t_i −
//! b·t_i²/2 − N_p(t_i), δv = D_v(t_i) + δv(0) − b·t_i − N_v(t_i), where D is the noise-free error
//! (zero for the Euler truth; the closed-form truth minus the Euler integral for the analytic one)
//! and N the accumulated noise, N(t_i) = Φ(τ)·N(t_{i−1}) + ν_i. The GPS noise is drawn as in the
//! per-sample engine, so every error, estimate and residual at the fixes has the same joint
//! distribution with about a tenth of the random numbers.
//!
//! A drifting bias is drawn with the rest of the error state: the random part x = δx − D moves
//! from fix to fix as x(t_i) = Φ_i·x(t_{i−1}) + ν_i, ν_i ~ N(0, Q_i), with Φ_i the product of the
//! interval's steps and Q_i = Σ_k Φ^k·Q(Δt)·Φ^kᵀ its accumulated noise, both of the truth's model
//! (bias included); one 3-D draw per interval through the Cholesky factor of Q_i.

use super::kernel::{LaneGroup, lane_mask};
use super::lane_sums::LaneFix;
use crate::filter::{FilterSchedule, FixCovariance};
use crate::lanes::{Lanes, Real};
use crate::model::Model;
use crate::random::LaneStreams;
use crate::simulation::{FixState, Observer, run_noise_free};
use crate::state::{ErrorState, StateMatrix, StateModel};

// The interval draw below is the error state written out component by component.
const _: () = assert!(
    ErrorState::DIM == 3 && ErrorState::MEAS == 2,
    "ensemble/epoch.rs: draw the new state in EpochGroup (next_fix, next_drifting)"
);

/// What the epoch engine needs of a model, computed once per ensemble.
#[derive(Clone, Debug, PartialEq)]
pub struct EpochPlan {
    /// The noise-free error (δp, δv) at every fix.
    offsets: Vec<[f64; 2]>,
    /// t_i, s.
    t_s: Vec<f64>,
    /// t_i²/2, s².
    half_t2: Vec<f64>,
    /// The interval τ_i = t_i − t_{i−1}, s.
    tau_s: Vec<f64>,
    /// The Cholesky factor (l₁₁, l₂₁, l₂₂) of the interval's noise covariance W·G(n).
    chol: Vec<[f64; 3]>,
    /// With a drifting bias, the interval's transition Φ_i and the lower factor L_i of its
    /// accumulated noise Q_i, L_i·L_iᵀ = Q_i, of the whole error state (`None`: a constant bias).
    drift: Option<Vec<(StateMatrix, StateMatrix)>>,
}

/// The transition and the accumulated noise's lower factor of an interval of `n` steps of the
/// truth `truth`: Φ_n = Φⁿ, Q_n = Σ_{k<n} Φᵏ·Q·Φᵏᵀ (the filter's own recursion).
fn drift_interval(truth: &ErrorState, n: usize, dt_s: f64) -> (StateMatrix, StateMatrix) {
    let (phi, q) = (truth.transition(0.0, dt_s), truth.process_noise(0.0, dt_s));
    let (mut phi_n, mut q_n) = (StateMatrix::identity(), StateMatrix::zeros());
    for _ in 0..n {
        phi_n = phi * phi_n;
        q_n = phi * q_n * phi.transpose() + q;
    }
    (phi_n, scaled_root(&((q_n + q_n.transpose()) * 0.5)))
}

/// A lower factor L, L·Lᵀ = Q, of a covariance whose states have very different scales: the
/// factor of the correlation matrix, scaled back, so that no state's variance is taken for
/// rounding of another's. A state of zero variance gets a zero row.
fn scaled_root(q: &StateMatrix) -> StateMatrix {
    let d = q.diagonal().map(|v| if v > 0.0 { v.sqrt() } else { 0.0 });
    let inv = d.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 });
    let c = StateMatrix::from_diagonal(&inv) * q * StateMatrix::from_diagonal(&inv);
    StateMatrix::from_diagonal(&d) * super::linear::psd_root(&c)
}

/// The interval noise covariance (G_pp, G_pv, G_vv) of n steps of `dt_s` per unit W.
pub fn interval_noise(n: usize, dt_s: f64) -> [f64; 3] {
    let nf = n as f64;
    [
        dt_s.powi(4) * (nf.powi(3) / 3.0 - nf / 12.0),
        0.5 * nf * nf * dt_s.powi(3),
        nf * dt_s * dt_s,
    ]
}

struct Offsets(Vec<[f64; 2]>);

impl Observer for Offsets {
    fn fix(&mut self, f: &FixState) {
        self.0.push([
            f.delta_x[ErrorState::POSITION],
            f.delta_x[ErrorState::VELOCITY],
        ]);
    }
}

impl EpochPlan {
    /// The plan of `model`'s truth under the filter `schedule`.
    pub fn new(model: &Model, schedule: &FilterSchedule) -> Self {
        let mut offsets = Offsets(Vec::with_capacity(model.timeline.fixes()));
        run_noise_free(model, schedule, &mut offsets);
        let tl = &model.timeline;
        let w = model.truth_stats.accel_noise_var_m2_s4;
        let mut prev = 0;
        let (mut t_s, mut half_t2, mut tau_s, mut chol) = (vec![], vec![], vec![], vec![]);
        for &jf in &tl.fix_steps {
            let t = tl.time_s(jf);
            t_s.push(t);
            half_t2.push(0.5 * t * t);
            let n = jf - prev;
            tau_s.push(n as f64 * tl.dt_s);
            let [gpp, gpv, _] = interval_noise(n, tl.dt_s);
            let l11 = (w * gpp).sqrt();
            let l21 = if l11 > 0.0 { w * gpv / l11 } else { 0.0 };
            // The Schur complement G_vv − G_pv²/G_pp = Δt²·n(n² − 1)/(4n² − 1), free of
            // cancellation.
            let nf = n as f64;
            let schur = if n > 0 {
                tl.dt_s * tl.dt_s * nf * (nf * nf - 1.0) / (4.0 * nf * nf - 1.0)
            } else {
                0.0
            };
            chol.push([l11, l21, (w * schur).sqrt()]);
            prev = jf;
        }
        Self {
            offsets: offsets.0,
            t_s,
            half_t2,
            tau_s,
            chol,
            drift: drift_plan(model),
        }
    }
}

/// Every interval's (Φ_i, L_i) of `model`'s drifting bias, `None` for a constant bias. Intervals
/// of the same length share one computation.
fn drift_plan(model: &Model) -> Option<Vec<(StateMatrix, StateMatrix)>> {
    let truth = ErrorState {
        stats: model.truth_stats,
    };
    if !truth.stats.bias_model.drifts() {
        return None;
    }
    let tl = &model.timeline;
    let mut prev = 0;
    let mut last: Option<(usize, (StateMatrix, StateMatrix))> = None;
    let mut out = Vec::with_capacity(tl.fixes());
    for &jf in &tl.fix_steps {
        let n = jf - prev;
        let interval = match last {
            Some((m, v)) if m == n => v,
            _ => drift_interval(&truth, n, tl.dt_s),
        };
        last = Some((n, interval));
        out.push(interval);
        prev = jf;
    }
    Some(out)
}

impl EpochPlan {
    /// The same plan with the accelerometer noise's covariance over every interval multiplied by
    /// `factor`: a deliberately wrong engine, to show that the two-sample comparison with the
    /// per-sample engine can tell.
    pub fn with_noise_scaled(&self, factor: f64) -> Self {
        let mut p = self.clone();
        for l in &mut p.chol {
            *l = l.map(|v| v * factor.sqrt());
        }
        for (_, l) in p.drift.iter_mut().flatten() {
            *l *= factor.sqrt();
        }
        p
    }
}

/// A key for the epoch engine's streams, distinct from the per-sample engine's `key`, so that
/// the two engines' ensembles are independent samples.
pub fn epoch_key(key: u64) -> u64 {
    crate::random::splitmix64(key ^ 0x0E90_C4E9_0C4E_90C4)
}

/// The epoch-level simulation of realizations `first..first + LANES` (see
/// [`crate::lanes::LANES`]; only the first `active` count, the others zeroed at every fix).
pub struct EpochGroup<'a> {
    plan: &'a EpochPlan,
    rng: LaneStreams,
    mask: Lanes,
    /// δp(0), δv(0), b.
    dp0: Lanes,
    dv0: Lanes,
    b: Lanes,
    eta_sigma: [f64; ErrorState::MEAS],
    /// The accumulated accelerometer noise (N_p, N_v).
    noise: [Lanes; 2],
    /// With a drifting bias, the random part x = δx − D of the error state.
    drifting: [Lanes; ErrorState::DIM],
    estimate: [Lanes; ErrorState::DIM],
}

impl<'a> EpochGroup<'a> {
    /// The group of realizations `first..` of the epoch streams `key`, its initial values drawn.
    #[inline(always)]
    pub fn new(plan: &'a EpochPlan, model: &Model, key: u64, first: u64, active: usize) -> Self {
        let ts = &model.truth_stats;
        let mut rng = LaneStreams::new(key, first);
        let s = Lanes::splat;
        let dp0 = s(ts.initial_position_sigma_m) * rng.normal();
        let dv0 = s(ts.initial_velocity_sigma_m_s) * rng.normal();
        let b = s(ts.bias_var_m2_s4.sqrt()) * rng.normal();
        Self {
            plan,
            rng,
            mask: lane_mask(active),
            dp0,
            dv0,
            b,
            eta_sigma: [ts.gps_position_sigma_m, ts.gps_velocity_sigma_m_s],
            noise: [Lanes::default(); 2],
            drifting: [dp0, dv0, b],
            estimate: [Lanes::default(); ErrorState::DIM],
        }
    }
}

impl EpochGroup<'_> {
    /// The random part of the error state moved through one interval with a drifting bias:
    /// x ← Φ_i·x + L_i·u, u three standard normals.
    #[inline(always)]
    fn next_drifting(&mut self, (phi, l): &(StateMatrix, StateMatrix)) -> [Lanes; ErrorState::DIM] {
        let s = Lanes::splat;
        let u = [self.rng.normal(), self.rng.normal(), self.rng.normal()];
        let x = self.drifting;
        let row = |r: usize| {
            (s(phi[(r, 0)]) * x[0] + s(phi[(r, 1)]) * x[1] + s(phi[(r, 2)]) * x[2])
                + (s(l[(r, 0)]) * u[0] + s(l[(r, 1)]) * u[1] + s(l[(r, 2)]) * u[2])
        };
        self.drifting = [row(0), row(1), row(2)];
        self.drifting
    }
}

impl LaneGroup for EpochGroup<'_> {
    #[inline(always)]
    fn next_fix(&mut self, i: usize, fix: &FixCovariance) -> LaneFix {
        let plan = self.plan;
        let s = Lanes::splat;
        let [op, ov] = plan.offsets[i];
        let (dp, dv, b) = if let Some(drift) = &plan.drift {
            let x = self.next_drifting(&drift[i]);
            (
                s(op) + x[ErrorState::POSITION],
                s(ov) + x[ErrorState::VELOCITY],
                x[ErrorState::BIAS],
            )
        } else {
            let [l11, l21, l22] = plan.chol[i];
            let (u1, u2) = (self.rng.normal(), self.rng.normal());
            let [mut np, mut nv] = self.noise;
            np += s(plan.tau_s[i]) * nv + s(l11) * u1;
            nv += s(l21) * u1 + s(l22) * u2;
            self.noise = [np, nv];
            let b = self.b;
            let dp = s(op) + self.dp0 + self.dv0 * s(plan.t_s[i]) - b * s(plan.half_t2[i]) - np;
            let dv = s(ov) + self.dv0 - b * s(plan.t_s[i]) - nv;
            (dp, dv, b)
        };
        let mask = self.mask;
        let delta_x = [dp * mask, dv * mask, b * mask];
        let eta = [
            s(self.eta_sigma[ErrorState::GPS_POSITION]) * self.rng.normal(),
            s(self.eta_sigma[ErrorState::GPS_VELOCITY]) * self.rng.normal(),
        ];
        let dz = [
            (dp + eta[ErrorState::GPS_POSITION]) * mask,
            (dv + eta[ErrorState::GPS_VELOCITY]) * mask,
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

/// The interval noise of `n` steps summed step by step, for tests: Σ_k g_k·g_kᵀ with
/// g_k = (Δt²/2 + (n − 1 − k)·Δt², Δt).
pub fn interval_noise_by_steps(n: usize, dt_s: f64) -> [f64; 3] {
    let mut g = [0.0; 3];
    for k in 0..n {
        let gp = 0.5 * dt_s * dt_s + (n - 1 - k) as f64 * dt_s * dt_s;
        g[0] += gp * gp;
        g[1] += gp * dt_s;
        g[2] += dt_s * dt_s;
    }
    g
}
