//! The exact covariance of the actual error of a filter whose assumed statistics differ from the
//! truth's: the classic covariance (sensitivity) analysis of a suboptimal filter.
//!
//! The actual error e = δx − δx̂ obeys ē = Φ·e + Γ·w between fixes and e⁺ = (I − K·H)·ē − K·η at a
//! fix, with the filter's gains K and the truth's noise. Its covariance therefore follows the same
//! recursion as the filter's own, with the filter's K and the truth's W, R and P(0); the Joseph
//! form holds for any gain. No random numbers are involved.

use crate::filter::{ErrorStateModel, FilterSchedule};
use crate::model::{NoiseStats, Timeline};
use crate::state::{MeasMatrix, StateMatrix};

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
/// P_a ← Φ·P_a·Φᵀ + Γ·W_truth·Γᵀ at every sample from P_a(0) = P_truth(0);
/// P_a⁺ = (I − K·H)·P_a⁻·(I − K·H)ᵀ + K·R_truth·Kᵀ at every fix.
pub fn actual_covariance(
    timeline: &Timeline,
    schedule: &FilterSchedule,
    truth: &NoiseStats,
) -> Vec<ActualFix> {
    let world = ErrorStateModel::new(timeline.dt_s, truth);
    let h = &schedule.model.h;
    let mut p = world.p0;
    let mut j = 0;
    let mut out = Vec::with_capacity(schedule.fixes.len());
    for (&jf, fix) in timeline.fix_steps.iter().zip(&schedule.fixes) {
        while j < jf {
            p = world.propagate(&p);
            j += 1;
        }
        let prior = p;
        let i_kh = StateMatrix::identity() - fix.gain * h;
        let post = i_kh * prior * i_kh.transpose() + fix.gain * world.r * fix.gain.transpose();
        let post = (post + post.transpose()) * 0.5;
        out.push(ActualFix {
            time_s: fix.time_s,
            prior,
            post,
            innovation: h * prior * h.transpose() + world.r,
        });
        p = post;
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
    let (mut claimed, mut actual) = (filter.p0, world.p0);
    let mut fixes = timeline.fix_steps.iter().zip(&schedule.fixes).peekable();
    for j in 0..=timeline.steps {
        if j > 0 {
            claimed = filter.propagate(&claimed);
            actual = world.propagate(&actual);
        }
        if let Some((_, fix)) = fixes.next_if(|(jf, _)| **jf == j) {
            let i_kh = StateMatrix::identity() - fix.gain * h;
            let post = i_kh * actual * i_kh.transpose() + fix.gain * world.r * fix.gain.transpose();
            actual = (post + post.transpose()) * 0.5;
            claimed = fix.p_post;
        }
        visit(SampleCovariance {
            sample: j,
            time_s: timeline.time_s(j),
            claimed,
            actual,
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
