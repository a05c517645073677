//! The error-state Kalman filter.
//!
//! State δx = (δp, δv, b): position error (m), velocity error (m/s), accelerometer bias (m/s²),
//! where δp = p − p_c and δv = v − v_c are the truth minus the integrated accelerometer.
//!
//! Its covariance and gains do not depend on the measurements, so [`FilterSchedule`] computes them
//! once for a time grid; every realization then only propagates and updates its estimate.

use nalgebra::{SMatrix, SVector};

use crate::error::FilterError;
use crate::lanes::Real;
use crate::model::{NoiseStats, Timeline};
use crate::state::{ErrorState, StateModel};

pub use crate::state::{process_noise, transition};

/// Before or after the measurement update at a fix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// A priori, t_i⁻: propagated from the previous fix.
    Prior,
    /// A posteriori, t_i⁺: after the update with the fix.
    Posterior,
}

impl Stage {
    /// Both stages, in time order.
    pub const ALL: [Stage; 2] = [Stage::Prior, Stage::Posterior];
}

/// The entries of `m`, row by row.
pub fn rows<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> [[f64; C]; R] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
}

/// The linear Gaussian system a filter runs (eqs. 5 and 6 for the error state), on a grid of
/// nominal step Δt, for one set of noise statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterModel<const N: usize = { ErrorState::DIM }, const M: usize = { ErrorState::MEAS }>
{
    /// The nominal step Δt that [`FilterModel::phi`] and [`FilterModel::q`] are computed for, s.
    pub dt_s: f64,
    /// One-step transition Φ(0, Δt) (the step at any time for a time-invariant model).
    pub phi: SMatrix<f64, N, N>,
    /// Process noise covariance of the step Q(0, Δt).
    pub q: SMatrix<f64, N, N>,
    /// Measurement matrix H.
    pub h: SMatrix<f64, M, N>,
    /// Measurement noise covariance R.
    pub r: SMatrix<f64, M, M>,
    /// Prior covariance P(0).
    pub p0: SMatrix<f64, N, N>,
}

/// The filter model of the accelerometer's error state.
pub type ErrorStateModel = FilterModel;

impl FilterModel {
    /// The error-state system for sample period `dt_s` and the statistics `stats`.
    pub fn new(dt_s: f64, stats: &NoiseStats) -> Self {
        Self::of(&ErrorState { stats: *stats }, dt_s)
    }
}

impl<const N: usize, const M: usize> FilterModel<N, M> {
    /// The matrices of `model` at the nominal step `dt_s`.
    pub fn of<S: StateModel<N, M>>(model: &S, dt_s: f64) -> Self {
        Self {
            dt_s,
            phi: model.transition(0.0, dt_s),
            q: model.process_noise(0.0, dt_s),
            h: model.observation(),
            r: model.measurement_noise(),
            p0: model.initial_covariance(),
        }
    }

    /// One propagation step P ← Φ·P·Φᵀ + Q, kept symmetric.
    pub fn propagate(&self, p: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
        symmetrize(self.phi * p * self.phi.transpose() + self.q)
    }

    /// The measurement update of the covariance at a fix at `time_s` whose a priori covariance is
    /// `p_prior`: Cholesky gain, Joseph-form P⁺, and the inverses the statistics use.
    /// `phi_from_previous` is stored with it: the transition of the estimate since the previous
    /// fix.
    ///
    /// # Errors
    /// [`FilterError`] when S, P⁻ or P⁺ is not positive definite.
    pub fn update_covariance(
        &self,
        p_prior: &SMatrix<f64, N, N>,
        time_s: f64,
        phi_from_previous: SMatrix<f64, N, N>,
    ) -> Result<FixCovariance<N, M>, FilterError> {
        update_covariance(self, p_prior, time_s, phi_from_previous)
    }

    /// Measurement update of the estimate with the gain of `fix`: returns the a posteriori
    /// estimate δx̂⁺ = δx̂⁻ + K·r and the residual r = δz − H·δx̂⁻.
    #[inline]
    pub fn update_estimate(
        &self,
        fix: &FixCovariance<N, M>,
        prior: &SVector<f64, N>,
        dz: &SVector<f64, M>,
    ) -> (SVector<f64, N>, SVector<f64, M>) {
        let residual = dz - self.h * prior;
        (prior + fix.gain * residual, residual)
    }
}

/// The filter's covariances and gain at one GPS fix.
#[derive(Clone, Debug, PartialEq)]
pub struct FixCovariance<
    const N: usize = { ErrorState::DIM },
    const M: usize = { ErrorState::MEAS },
> {
    /// Time of the fix, s.
    pub time_s: f64,
    /// Transition of the estimate from the previous fix (or from t = 0) to this one.
    pub phi_from_previous: SMatrix<f64, N, N>,
    /// A priori covariance P(t_i⁻).
    pub p_prior: SMatrix<f64, N, N>,
    /// A posteriori covariance P(t_i⁺).
    pub p_post: SMatrix<f64, N, N>,
    /// Kalman gain K = P⁻·Hᵀ·S⁻¹.
    pub gain: SMatrix<f64, N, M>,
    /// Innovation covariance S = H·P⁻·Hᵀ + R.
    pub s: SMatrix<f64, M, M>,
    /// S⁻¹, for the normalized innovation squared.
    pub s_inv: SMatrix<f64, M, M>,
    /// (P⁻)⁻¹, for the a priori normalized estimation error squared.
    pub p_prior_inv: SMatrix<f64, N, N>,
    /// (P⁺)⁻¹, for the a posteriori normalized estimation error squared.
    pub p_post_inv: SMatrix<f64, N, N>,
}

impl FixCovariance {
    /// The estimate through this fix, for one realization (`f64`) or a lane group: the a priori
    /// estimate δx̂⁻ = Φ·δx̂⁺(previous), the residual r = δz − H·δx̂⁻ and the a posteriori estimate
    /// δx̂⁺ = δx̂⁻ + K·r, returned as (prior, post, residual). Written once over [`Real`] so that
    /// every engine performs the same operations in the same order.
    #[inline(always)]
    pub fn step<T: Real>(
        &self,
        estimate: &[T; ErrorState::DIM],
        dz: &[T; ErrorState::MEAS],
    ) -> (
        [T; ErrorState::DIM],
        [T; ErrorState::DIM],
        [T; ErrorState::MEAS],
    ) {
        // Written out for the error state's three states and two measured components.
        const _: () = assert!(
            ErrorState::DIM == 3 && ErrorState::MEAS == 2,
            "filter.rs: write FixCovariance::step's rows out for the new state or measurement"
        );
        let phi = &self.phi_from_previous;
        // Written out row by row (no `std::array::from_fn`), so that every operation is inlined
        // into the vectorized callers.
        let row = |r: usize| {
            T::splat(phi[(r, 0)]) * estimate[0]
                + T::splat(phi[(r, 1)]) * estimate[1]
                + T::splat(phi[(r, 2)]) * estimate[2]
        };
        let prior = [row(0), row(1), row(2)];
        // H selects (δp, δv).
        let residual = [
            dz[ErrorState::GPS_POSITION] - prior[ErrorState::POSITION],
            dz[ErrorState::GPS_VELOCITY] - prior[ErrorState::VELOCITY],
        ];
        let k = &self.gain;
        let gain = |r: usize| {
            prior[r] + (T::splat(k[(r, 0)]) * residual[0] + T::splat(k[(r, 1)]) * residual[1])
        };
        let post = [gain(0), gain(1), gain(2)];
        (prior, post, residual)
    }
}

/// Every covariance and gain of the filter over a time grid, computed once and shared.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSchedule<
    const N: usize = { ErrorState::DIM },
    const M: usize = { ErrorState::MEAS },
> {
    /// The system the filter assumes.
    pub model: FilterModel<N, M>,
    /// One entry per GPS fix.
    pub fixes: Vec<FixCovariance<N, M>>,
    /// Which states are constant between fixes (see [`StateModel::constant_states`]).
    pub constant: [bool; N],
}

impl FilterSchedule {
    /// Runs the covariance recursion of the error state over `timeline` for the statistics
    /// `stats`: propagation at every accelerometer sample, a Joseph-form update at every fix.
    ///
    /// # Errors
    /// [`FilterError`] when S or P stops being positive definite.
    pub fn new(timeline: &Timeline, stats: &NoiseStats) -> Result<Self, FilterError> {
        Self::of(&ErrorState { stats: *stats }, timeline)
    }
}

impl<const N: usize, const M: usize> FilterSchedule<N, M> {
    /// Runs the covariance recursion of `model` over `timeline`: P ← Φ(t_j, Δt)·P·Φᵀ + Q(t_j, Δt)
    /// at every accelerometer sample, a Joseph-form update at every fix. The estimate's transition
    /// between fixes is the product of the steps' Φ (the model's Φ over the whole interval when it
    /// does not depend on time and composes, [`StateModel::transition_composes`]).
    ///
    /// # Errors
    /// [`FilterError`] when S or P stops being positive definite.
    pub fn of<S: StateModel<N, M>>(model: &S, timeline: &Timeline) -> Result<Self, FilterError> {
        let system = FilterModel::of(model, timeline.dt_s);
        let mut p = system.p0;
        let mut j = 0;
        let mut fixes = Vec::with_capacity(timeline.fixes());
        let in_one_piece = S::TIME_INVARIANT && model.transition_composes();
        for &jf in &timeline.fix_steps {
            // A time-invariant model's transition over the interval in one piece when it composes
            // (exact for the error state with a constant or random-walk bias, whose Φ is
            // unipotent); otherwise the product of the steps.
            let mut phi_from_previous = if in_one_piece {
                model.transition(timeline.time_s(j), (jf - j) as f64 * timeline.dt_s)
            } else {
                SMatrix::identity()
            };
            while j < jf {
                if !in_one_piece {
                    phi_from_previous =
                        model.transition(timeline.time_s(j), timeline.dt_s) * phi_from_previous;
                }
                p = propagate_at(model, &system, &p, timeline.time_s(j));
                j += 1;
            }
            let time_s = timeline.time_s(jf);
            let fix = update_covariance(&system, &p, time_s, phi_from_previous)?;
            p = fix.p_post;
            fixes.push(fix);
        }
        Ok(Self {
            model: system,
            fixes,
            constant: model.constant_states(),
        })
    }
}

/// One propagation step of `model` over a step of its own length `tau_s` from `t_s`, as a log
/// with irregular time stamps needs: P ← Φ(t, τ)·P·Φ(t, τ)ᵀ + Q(t, τ), kept symmetric.
pub fn propagate_over<S: StateModel<N, M>, const N: usize, const M: usize>(
    model: &S,
    p: &SMatrix<f64, N, N>,
    t_s: f64,
    tau_s: f64,
) -> SMatrix<f64, N, N> {
    let phi = model.transition(t_s, tau_s);
    symmetrize(phi * p * phi.transpose() + model.process_noise(t_s, tau_s))
}

/// One propagation step from `t_s`: the nominal step when the model does not depend on time, so
/// that a time-invariant model costs no matrix construction per step.
fn propagate_at<S: StateModel<N, M>, const N: usize, const M: usize>(
    model: &S,
    system: &FilterModel<N, M>,
    p: &SMatrix<f64, N, N>,
    t_s: f64,
) -> SMatrix<f64, N, N> {
    if S::TIME_INVARIANT {
        system.propagate(p)
    } else {
        propagate_over(model, p, t_s, system.dt_s)
    }
}

/// (M + Mᵀ)/2: removes the asymmetry rounding leaves in a covariance.
fn symmetrize<const D: usize>(m: SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    (m + m.transpose()) * 0.5
}

/// The measurement update of the covariance at one fix.
fn update_covariance<const N: usize, const M: usize>(
    model: &FilterModel<N, M>,
    p_prior: &SMatrix<f64, N, N>,
    time_s: f64,
    phi_from_previous: SMatrix<f64, N, N>,
) -> Result<FixCovariance<N, M>, FilterError> {
    let h = &model.h;
    let s = symmetrize(h * p_prior * h.transpose() + model.r);
    let s_chol = s
        .cholesky()
        .ok_or(FilterError::InnovationNotPositiveDefinite { time_s })?;
    // K = P⁻Hᵀ S⁻¹, from the Cholesky solve S·Kᵀ = H·P⁻ (P⁻ symmetric).
    let gain: SMatrix<f64, N, M> = s_chol.solve(&(h * p_prior)).transpose();
    // Joseph form: P⁺ = (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ, positive definite by construction.
    let i_kh = SMatrix::<f64, N, N>::identity() - gain * h;
    let p_post = symmetrize(i_kh * p_prior * i_kh.transpose() + gain * model.r * gain.transpose());
    let p_prior_inv = p_prior
        .cholesky()
        .ok_or(FilterError::CovarianceNotPositiveDefinite {
            which: "a priori",
            time_s,
        })?
        .inverse();
    let p_post_inv = p_post
        .cholesky()
        .ok_or(FilterError::CovarianceNotPositiveDefinite {
            which: "a posteriori",
            time_s,
        })?
        .inverse();
    Ok(FixCovariance {
        time_s,
        phi_from_previous,
        p_prior: *p_prior,
        p_post,
        gain,
        s,
        s_inv: s_chol.inverse(),
        p_prior_inv,
        p_post_inv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::model::Model;
    use crate::state::StateMatrix;

    #[test]
    fn composed_transition_is_exact() {
        let phi = transition(0.005);
        let mut acc = StateMatrix::identity();
        for _ in 0..40 {
            acc = phi * acc;
        }
        assert!((acc - transition(0.2)).norm() < 1e-12);
    }

    #[test]
    fn gain_is_the_minimum_variance_gain() {
        let m = Model::new(&Config::default()).unwrap();
        let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
        let f = &s.fixes[3];
        // Optimal gain: K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹, then P⁺ = (I − KH)P⁻ (the short form).
        let h = s.model.h;
        let k = f.p_prior
            * h.transpose()
            * (h * f.p_prior * h.transpose() + s.model.r)
                .try_inverse()
                .unwrap();
        assert!((k - f.gain).norm() < 1e-12 * k.norm());
        let short = (StateMatrix::identity() - k * h) * f.p_prior;
        assert!((short - f.p_post).norm() < 1e-9 * f.p_post.norm());
    }
}
