//! The exact covariance of the actual error of a filter whose assumed statistics differ from the
//! truth's: the classic covariance (sensitivity) analysis of a suboptimal filter.
//!
//! The actual error e = δx − δx̂ obeys ē = Φ·e + Γ·w between fixes and e⁺ = (I − K·H)·ē − K·η at a
//! fix, with the filter's gains K and the truth's noise. Its covariance therefore follows the same
//! recursion as the filter's own, with the filter's K and the truth's W, R and P(0); the Joseph
//! form holds for any gain. No random numbers are involved.

use nalgebra::SMatrix;

use crate::filter::{ErrorStateModel, FilterModel, FilterSchedule};
use crate::model::{NoiseStats, Timeline};
use crate::state::{ErrorState, MeasMatrix, StateMatrix};

/// A matrix of the joint state (e, δx̂).
type JointMatrix = SMatrix<f64, { 2 * ErrorState::DIM }, { 2 * ErrorState::DIM }>;

/// The actual error's covariance through the run: of the error e alone when the filter's Φ is the
/// truth's, else of the joint state (e, δx̂), because e then moves as
/// e ← Φ_t·e + (Φ_t − Φ_f)·δx̂ + w and depends on the estimate (a Gauss–Markov bias assumed with
/// another τ_b or another model).
enum Actual {
    /// P_a of e.
    Error(StateMatrix),
    /// The joint covariance of (e, δx̂) and the step's transition A = [[Φ_t, Φ_t − Φ_f], [0, Φ_f]].
    Joint(Box<(JointMatrix, JointMatrix)>),
}

impl Actual {
    /// P_a(0) = P_truth(0), the estimate starting at zero.
    fn new(world: &ErrorStateModel, filter: &FilterModel) -> Self {
        if world.phi == filter.phi {
            return Actual::Error(world.p0);
        }
        const N: usize = ErrorState::DIM;
        let mut a = JointMatrix::zeros();
        a.fixed_view_mut::<N, N>(0, 0).copy_from(&world.phi);
        a.fixed_view_mut::<N, N>(0, N)
            .copy_from(&(world.phi - filter.phi));
        a.fixed_view_mut::<N, N>(N, N).copy_from(&filter.phi);
        let mut c = JointMatrix::zeros();
        c.fixed_view_mut::<N, N>(0, 0).copy_from(&world.p0);
        Actual::Joint(Box::new((c, a)))
    }

    /// One accelerometer step with the truth's noise.
    fn propagate(&mut self, world: &ErrorStateModel) {
        match self {
            Actual::Error(p) => *p = world.propagate(p),
            Actual::Joint(joint) => {
                let (c, a) = &mut **joint;
                let mut next = *a * *c * a.transpose();
                let mut q = next.fixed_view_mut::<{ ErrorState::DIM }, { ErrorState::DIM }>(0, 0);
                q += world.q;
                *c = (next + next.transpose()) * 0.5;
            }
        }
    }

    /// The update at a fix with the filter's gain K and the truth's R: e ← (I − K·H)·e − K·η,
    /// δx̂ ← δx̂ + K·H·e + K·η.
    fn update(&mut self, i_kh: &StateMatrix, krk: &StateMatrix) {
        match self {
            Actual::Error(p) => {
                let post = i_kh * *p * i_kh.transpose() + krk;
                *p = (post + post.transpose()) * 0.5;
            }
            Actual::Joint(joint) => {
                let c = &mut joint.0;
                const N: usize = ErrorState::DIM;
                let mut b = JointMatrix::identity();
                b.fixed_view_mut::<N, N>(0, 0).copy_from(i_kh);
                b.fixed_view_mut::<N, N>(N, 0)
                    .copy_from(&(StateMatrix::identity() - i_kh));
                let mut noise = JointMatrix::zeros();
                noise.fixed_view_mut::<N, N>(0, 0).copy_from(krk);
                noise.fixed_view_mut::<N, N>(0, N).copy_from(&(-krk));
                noise.fixed_view_mut::<N, N>(N, 0).copy_from(&(-krk));
                noise.fixed_view_mut::<N, N>(N, N).copy_from(krk);
                let post = b * *c * b.transpose() + noise;
                *c = (post + post.transpose()) * 0.5;
            }
        }
    }

    /// The covariance of the error e.
    fn error(&self) -> StateMatrix {
        match self {
            Actual::Error(p) => *p,
            Actual::Joint(joint) => joint
                .0
                .fixed_view::<{ ErrorState::DIM }, { ErrorState::DIM }>(0, 0)
                .into_owned(),
        }
    }
}

/// The actual error covariance at one fix, beside the filter's.
#[derive(Clone, Debug, PartialEq)]
pub struct ActualFix {
    /// Time of the fix, s.
    pub time_s: f64,
    /// Actual a priori covariance, (m, m/s, m/s²)².
    pub prior: StateMatrix,
    /// Actual a posteriori covariance.
    pub post: StateMatrix,
    /// Actual innovation covariance H·P_actual⁻·Hᵀ + R_truth, (m, m/s)².
    pub innovation: MeasMatrix,
}

/// The actual error covariance of the filter `schedule` when the truth has the statistics
/// `truth`, at every fix.
///
/// # Formula
/// P_a ← Φ·P_a·Φᵀ + Q_truth at every sample from P_a(0) = P_truth(0);
/// P_a⁺ = (I − K·H)·P_a⁻·(I − K·H)ᵀ + K·R_truth·Kᵀ at every fix. When the filter's Φ_f is not the
/// truth's Φ_t (a Gauss–Markov bias), the same recursion runs on the joint covariance of
/// (e, δx̂) with A = [[Φ_t, Φ_t − Φ_f], [0, Φ_f]] and, at a fix, B = [[I − K·H, 0], [K·H, I]]
/// and the noise K·R·Kᵀ with signs (+, −; −, +); P_a is its e block.
pub fn actual_covariance(
    timeline: &Timeline,
    schedule: &FilterSchedule,
    truth: &NoiseStats,
) -> Vec<ActualFix> {
    let world = ErrorStateModel::new(timeline.dt_s, truth);
    let h = &schedule.model.h;
    let mut actual = Actual::new(&world, &schedule.model);
    let mut j = 0;
    let mut out = Vec::with_capacity(schedule.fixes.len());
    for (&jf, fix) in timeline.fix_steps.iter().zip(&schedule.fixes) {
        while j < jf {
            actual.propagate(&world);
            j += 1;
        }
        let prior = actual.error();
        let i_kh = StateMatrix::identity() - fix.gain * h;
        actual.update(&i_kh, &(fix.gain * world.r * fix.gain.transpose()));
        out.push(ActualFix {
            time_s: fix.time_s,
            prior,
            post: actual.error(),
            innovation: h * prior * h.transpose() + world.r,
        });
    }
    out
}

/// The filter's claimed covariance and the actual error covariance at one accelerometer sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleCovariance {
    /// Sample index j.
    pub sample: usize,
    /// Time of the sample, s.
    pub time_s: f64,
    /// The filter's own covariance P, (m, m/s, m/s²)²: a posteriori at a fix.
    pub claimed: StateMatrix,
    /// The actual error covariance, likewise.
    pub actual: StateMatrix,
}

/// Visits the claimed and the actual covariance of the filter `schedule` at every accelerometer
/// sample j = 0, …, steps, in time order (a posteriori at a fix), when the truth has the
/// statistics `truth`. Memory does not grow with the run: nothing is kept between samples.
///
/// # Formula
/// As [`actual_covariance`], with the filter's own P propagated beside it by its assumed model
/// and set to its a posteriori P⁺ at every fix.
pub fn covariance_at_samples(
    timeline: &Timeline,
    schedule: &FilterSchedule,
    truth: &NoiseStats,
    mut visit: impl FnMut(SampleCovariance),
) {
    let world = ErrorStateModel::new(timeline.dt_s, truth);
    let filter = &schedule.model;
    let h = &filter.h;
    let mut claimed = filter.p0;
    let mut actual = Actual::new(&world, filter);
    let mut fixes = timeline.fix_steps.iter().zip(&schedule.fixes).peekable();
    for j in 0..=timeline.steps {
        if j > 0 {
            claimed = filter.propagate(&claimed);
            actual.propagate(&world);
        }
        if let Some((_, fix)) = fixes.next_if(|(jf, _)| **jf == j) {
            let i_kh = StateMatrix::identity() - fix.gain * h;
            actual.update(&i_kh, &(fix.gain * world.r * fix.gain.transpose()));
            claimed = fix.p_post;
        }
        visit(SampleCovariance {
            sample: j,
            time_s: timeline.time_s(j),
            claimed,
            actual: actual.error(),
        });
    }
}

/// tr(A⁻¹·B) and tr((A⁻¹·B)²) for symmetric positive definite A: the sum and the sum of squares
/// of the weights λ of a quadratic form xᵀA⁻¹x with x ~ N(0, B), which is Σ λ_k χ²(1).
pub fn weights<const D: usize>(
    a_inv: &nalgebra::SMatrix<f64, D, D>,
    b: &nalgebra::SMatrix<f64, D, D>,
) -> (f64, f64) {
    let m = a_inv * b;
    (m.trace(), (m * m).trace())
}
