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

/// A 2-vector: a GPS measurement or residual (m, m/s).
pub type Vector2 = SVector<f64, 2>;
/// A 3-vector of the error state (m, m/s, m/s²).
pub type Vector3 = SVector<f64, 3>;
/// A 2×2 matrix: measurement-space covariance.
pub type Matrix2 = SMatrix<f64, 2, 2>;
/// A 3×3 matrix: state-space covariance or transition.
pub type Matrix3 = SMatrix<f64, 3, 3>;
/// Measurement matrix H, 2×3.
pub type Matrix2x3 = SMatrix<f64, 2, 3>;
/// Kalman gain K, 3×2.
pub type Matrix3x2 = SMatrix<f64, 3, 2>;

/// A component of the error state δx = (δp, δv, b); the first two are also the components of a
/// GPS measurement and of a residual.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Component {
    /// Position error δp, m.
    Position,
    /// Velocity error δv, m/s.
    Velocity,
    /// Accelerometer bias b, m/s².
    Bias,
}

impl Component {
    /// The state components, in state order.
    pub const STATE: [Component; 3] = [Component::Position, Component::Velocity, Component::Bias];
    /// The measured components, in measurement order.
    pub const MEASURED: [Component; 2] = [Component::Position, Component::Velocity];

    /// Index in the state vector.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The unit of the component.
    pub fn unit(self) -> &'static str {
        match self {
            Component::Position => "m",
            Component::Velocity => "m/s",
            Component::Bias => "m/s²",
        }
    }
}

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

/// Transition Φ(τ) of the error state over τ seconds, eq. (5) composed over τ/Δt steps.
///
/// # Formula
/// ```text
/// Φ(τ) = [1  τ  −τ²/2]
///        [0  1  −τ   ]
///        [0  0   1   ]
/// ```
/// Φ is unipotent (Φ − I is nilpotent), so Φ(Δt)ⁿ = Φ(n·Δt) exactly.
///
/// # Examples
/// ```
/// use accelcal::filter::transition;
/// let phi = transition(0.005);
/// let phi40 = transition(0.2);
/// assert!((phi.pow(40) - phi40).norm() < 1e-12);
/// ```
pub fn transition(tau_s: f64) -> Matrix3 {
    Matrix3::new(
        1.0,
        tau_s,
        -0.5 * tau_s * tau_s,
        0.0,
        1.0,
        -tau_s,
        0.0,
        0.0,
        1.0,
    )
}

/// Process noise covariance Q(τ) = Γ·W·Γᵀ of one accelerometer step of τ seconds, (m, m/s, m/s²)².
///
/// # Formula
/// Γ = −(τ²/2, τ, 0)ᵀ (eq. 5: the noise enters position with −τ²/2 and velocity with −τ), W the
/// accelerometer's white-noise variance `accel_noise_var_m2_s4`.
pub fn process_noise(tau_s: f64, accel_noise_var_m2_s4: f64) -> Matrix3 {
    let gamma = Vector3::new(-0.5 * tau_s * tau_s, -tau_s, 0.0);
    gamma * gamma.transpose() * accel_noise_var_m2_s4
}

/// The linear Gaussian error-state system of eqs. (5) and (6), for one set of noise statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorStateModel {
    /// The nominal accelerometer step Δt that [`ErrorStateModel::phi`] and
    /// [`ErrorStateModel::q`] are computed for, s.
    pub dt_s: f64,
    /// Accelerometer white-noise variance W the filter assumes, (m/s²)²; gives Q for any step.
    pub accel_noise_var_m2_s4: f64,
    /// One-step transition Φ(Δt).
    pub phi: Matrix3,
    /// Process noise covariance per step, Q = Γ·W·Γᵀ with Γ = −(Δt²/2, Δt, 0)ᵀ, (m, m/s, m/s²)².
    pub q: Matrix3,
    /// Measurement matrix H: GPS sees position and velocity errors.
    pub h: Matrix2x3,
    /// Measurement noise covariance R = diag(σ_p², σ_v²), (m, m/s)².
    pub r: Matrix2,
    /// Initial covariance P(0) = diag(σ_p0², σ_v0², σ_b²).
    pub p0: Matrix3,
}

impl ErrorStateModel {
    /// The system for sample period `dt_s` and the statistics `stats`.
    pub fn new(dt_s: f64, stats: &NoiseStats) -> Self {
        Self {
            dt_s,
            accel_noise_var_m2_s4: stats.accel_noise_var_m2_s4,
            phi: transition(dt_s),
            q: process_noise(dt_s, stats.accel_noise_var_m2_s4),
            h: Matrix2x3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0),
            r: Matrix2::new(
                stats.gps_position_sigma_m.powi(2),
                0.0,
                0.0,
                stats.gps_velocity_sigma_m_s.powi(2),
            ),
            p0: Matrix3::from_diagonal(&Vector3::new(
                stats.initial_position_sigma_m.powi(2),
                stats.initial_velocity_sigma_m_s.powi(2),
                stats.bias_var_m2_s4,
            )),
        }
    }

    /// One propagation step P ← Φ·P·Φᵀ + Q, kept symmetric.
    pub fn propagate(&self, p: &Matrix3) -> Matrix3 {
        symmetrize(self.phi * p * self.phi.transpose() + self.q)
    }

    /// One propagation step over a step of its own length `tau_s`, as a log with irregular time
    /// stamps needs: P ← Φ(τ)·P·Φ(τ)ᵀ + Q(τ), kept symmetric.
    pub fn propagate_over(&self, p: &Matrix3, tau_s: f64) -> Matrix3 {
        let phi = transition(tau_s);
        symmetrize(phi * p * phi.transpose() + process_noise(tau_s, self.accel_noise_var_m2_s4))
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
        p_prior: &Matrix3,
        time_s: f64,
        phi_from_previous: Matrix3,
    ) -> Result<FixCovariance, FilterError> {
        update_covariance(self, p_prior, time_s, phi_from_previous)
    }

    /// Measurement update of the estimate with the gain of `fix`: returns the a posteriori
    /// estimate δx̂⁺ = δx̂⁻ + K·r and the residual r = δz − H·δx̂⁻.
    #[inline]
    pub fn update_estimate(
        &self,
        fix: &FixCovariance,
        prior: &Vector3,
        dz: &Vector2,
    ) -> (Vector3, Vector2) {
        let residual = dz - self.h * prior;
        (prior + fix.gain * residual, residual)
    }
}

/// The filter's covariances and gain at one GPS fix.
#[derive(Clone, Debug, PartialEq)]
pub struct FixCovariance {
    /// Time of the fix, s.
    pub time_s: f64,
    /// Transition of the estimate from the previous fix (or from t = 0) to this one.
    pub phi_from_previous: Matrix3,
    /// A priori covariance P(t_i⁻).
    pub p_prior: Matrix3,
    /// A posteriori covariance P(t_i⁺).
    pub p_post: Matrix3,
    /// Kalman gain K = P⁻·Hᵀ·S⁻¹.
    pub gain: Matrix3x2,
    /// Innovation covariance S = H·P⁻·Hᵀ + R.
    pub s: Matrix2,
    /// S⁻¹, for the normalized innovation squared.
    pub s_inv: Matrix2,
    /// (P⁻)⁻¹, for the a priori normalized estimation error squared.
    pub p_prior_inv: Matrix3,
    /// (P⁺)⁻¹, for the a posteriori normalized estimation error squared.
    pub p_post_inv: Matrix3,
}

impl FixCovariance {
    /// The estimate through this fix, for one realization (`f64`) or a lane group: the a priori
    /// estimate δx̂⁻ = Φ·δx̂⁺(previous), the residual r = δz − H·δx̂⁻ and the a posteriori estimate
    /// δx̂⁺ = δx̂⁻ + K·r, returned as (prior, post, residual). Written once over [`Real`] so that
    /// every engine performs the same operations in the same order.
    #[inline(always)]
    pub fn step<T: Real>(&self, estimate: &[T; 3], dz: &[T; 2]) -> ([T; 3], [T; 3], [T; 2]) {
        let phi = &self.phi_from_previous;
        // Written out row by row (no `std::array::from_fn`), so that every operation is inlined
        // into the vectorized callers.
        let row = |r: usize| {
            T::splat(phi[(r, 0)]) * estimate[0]
                + T::splat(phi[(r, 1)]) * estimate[1]
                + T::splat(phi[(r, 2)]) * estimate[2]
        };
        let prior: [T; 3] = [row(0), row(1), row(2)];
        // H selects (δp, δv).
        let residual = [dz[0] - prior[0], dz[1] - prior[1]];
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
pub struct FilterSchedule {
    /// The system the filter assumes.
    pub model: ErrorStateModel,
    /// One entry per GPS fix.
    pub fixes: Vec<FixCovariance>,
}

impl FilterSchedule {
    /// Runs the covariance recursion over `timeline` for the statistics `stats`: propagation at
    /// every accelerometer sample, a Joseph-form update at every fix.
    ///
    /// # Errors
    /// [`FilterError`] when S or P stops being positive definite.
    pub fn new(timeline: &Timeline, stats: &NoiseStats) -> Result<Self, FilterError> {
        let model = ErrorStateModel::new(timeline.dt_s, stats);
        let mut p = model.p0;
        let mut j = 0;
        let mut fixes = Vec::with_capacity(timeline.fixes());
        for &jf in &timeline.fix_steps {
            let phi_from_previous = transition((jf - j) as f64 * timeline.dt_s);
            while j < jf {
                p = model.propagate(&p);
                j += 1;
            }
            let time_s = timeline.time_s(jf);
            let p_prior = p;
            let fix = update_covariance(&model, &p_prior, time_s, phi_from_previous)?;
            p = fix.p_post;
            fixes.push(fix);
        }
        Ok(Self { model, fixes })
    }

    /// Measurement update of the estimate at fix `i`: returns the a posteriori estimate and the
    /// residual r = δz − H·δx̂⁻.
    #[inline]
    pub fn update(&self, i: usize, prior: &Vector3, dz: &Vector2) -> (Vector3, Vector2) {
        self.model.update_estimate(&self.fixes[i], prior, dz)
    }
}

/// (M + Mᵀ)/2: removes the asymmetry rounding leaves in a covariance.
fn symmetrize<const D: usize>(m: SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    (m + m.transpose()) * 0.5
}

/// The measurement update of the covariance at one fix.
fn update_covariance(
    model: &ErrorStateModel,
    p_prior: &Matrix3,
    time_s: f64,
    phi_from_previous: Matrix3,
) -> Result<FixCovariance, FilterError> {
    let h = &model.h;
    let s = symmetrize(h * p_prior * h.transpose() + model.r);
    let s_chol = s
        .cholesky()
        .ok_or(FilterError::InnovationNotPositiveDefinite { time_s })?;
    // K = P⁻Hᵀ S⁻¹, from the Cholesky solve S·Kᵀ = H·P⁻ (P⁻ symmetric).
    let gain: Matrix3x2 = s_chol.solve(&(h * p_prior)).transpose();
    // Joseph form: P⁺ = (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ, positive definite by construction.
    let i_kh = Matrix3::identity() - gain * h;
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

    #[test]
    fn composed_transition_is_exact() {
        let phi = transition(0.005);
        let mut acc = Matrix3::identity();
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
        let short = (Matrix3::identity() - k * h) * f.p_prior;
        assert!((short - f.p_post).norm() < 1e-9 * f.p_post.norm());
    }
}
