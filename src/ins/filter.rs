//! The INS/GNSS error-state extended Kalman filter, closed loop: the mechanization carries the
//! navigation solution, the filter its 15 errors; each fix corrects the solution and the biases
//! and resets the error state to zero (Groves §14.1.1, closed-loop correction; the arrangement of
//! KF-GINS's `GIEngine`).
//!
//! The update is the Joseph form P⁺ = (I − KH)P(I − KH)ᵀ + KRKᵀ with the gain from a Cholesky
//! factor of the innovation covariance S = HPHᵀ + R (no explicit inverse).

use nalgebra::{Cholesky, DMatrix, DVector, SMatrix, UnitQuaternion, Vector3};
use thiserror::Error;

use super::discrete::{self, NoiseDensities};
use super::error_state::{
    self, ACCEL_BIAS, ATTITUDE, BiasDecay, GYRO_BIAS, Matrix15, POSITION, STATES, VELOCITY,
};
use super::gnss::{self, Fix};
use super::mech::{self, Increment, Pva};

/// A filter step that cannot go on.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FilterError {
    /// The innovation covariance is not positive definite.
    #[error("the innovation covariance at t = {t_s} s is not positive definite")]
    Innovation {
        /// The fix's time, s.
        t_s: f64,
    },
    /// The error state's covariance is not positive definite.
    #[error("the error state's covariance is not positive definite")]
    Covariance,
}

/// What one fix's update saw: the innovation, its covariance and the normalized squared
/// innovation (NIS).
#[derive(Clone, Debug, PartialEq)]
pub struct Innovation {
    /// The fix's time, s.
    pub t_s: f64,
    /// The innovation ν (position NED m, then velocity NED m/s where measured).
    pub residual: DVector<f64>,
    /// Its covariance S.
    pub covariance: DMatrix<f64>,
    /// νᵀS⁻¹ν.
    pub nis: f64,
}

/// The filter: the navigation solution, the bias estimates, and the covariance of their errors.
#[derive(Clone, Debug, PartialEq)]
pub struct Ekf {
    /// The navigation solution at the last step.
    pub pva: Pva,
    /// The gyro bias estimate, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer bias estimate, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The error state's covariance P.
    pub covariance: Matrix15,
    /// The noise densities the filter assumes.
    pub noise: NoiseDensities,
    /// The biases' decay rates the filter assumes.
    pub decay: BiasDecay,
    /// The antenna's lever arm in body axes, m.
    pub lever_arm_b_m: Vector3<f64>,
    /// The previous step's compensated increments (for sculling and coning).
    before: Option<Increment>,
}

impl Ekf {
    /// A filter starting at `pva` with zero bias estimates and covariance `p0`.
    pub fn new(
        pva: Pva,
        p0: Matrix15,
        noise: NoiseDensities,
        decay: BiasDecay,
        lever_arm_b_m: Vector3<f64>,
    ) -> Self {
        Ekf {
            pva,
            gyro_bias_rad_s: Vector3::zeros(),
            accel_bias_m_s2: Vector3::zeros(),
            covariance: p0,
            noise,
            decay,
            lever_arm_b_m,
            before: None,
        }
    }

    /// The increments `raw` compensated by the bias estimates.
    fn compensate(&self, raw: &Increment) -> Increment {
        Increment {
            dtheta_rad: raw.dtheta_rad - self.gyro_bias_rad_s * raw.dt_s,
            dvel_m_s: raw.dvel_m_s - self.accel_bias_m_s2 * raw.dt_s,
            dt_s: raw.dt_s,
        }
    }

    /// One IMU step: the mechanization with the compensated increments, the bias estimates'
    /// decay, and P ← ΦPΦᵀ + Q_d with F at the step's start.
    pub fn propagate(&mut self, raw: &Increment) {
        let now = self.compensate(raw);
        let before = self.before.unwrap_or(now);
        let f_b = now.dvel_m_s / now.dt_s;
        let big_f = error_state::dynamics(&self.pva, &f_b, &self.decay);
        let phi = discrete::transition(&big_f, now.dt_s);
        let q = discrete::process_noise(&phi, &self.noise, now.dt_s);
        self.pva = mech::step(&self.pva, &before, &now);
        self.gyro_bias_rad_s *= (-self.decay.gyro_per_s * now.dt_s).exp();
        self.accel_bias_m_s2 *= (-self.decay.accel_per_s * now.dt_s).exp();
        self.covariance = phi * self.covariance * phi.transpose() + q;
        self.before = Some(now);
    }

    /// The update by `fix`: the innovation, the Joseph-form covariance, the closed-loop correction
    /// of the solution and the biases.
    ///
    /// # Errors
    /// [`FilterError::Innovation`] when S is not positive definite.
    pub fn update(&mut self, fix: &Fix) -> Result<Innovation, FilterError> {
        let omega = self
            .before
            .map_or(Vector3::zeros(), |b| b.dtheta_rad / b.dt_s);
        let (position, velocity) = gnss::antenna(&self.pva, &self.lever_arm_b_m, &omega);
        let h6 = gnss::observation(&self.pva, &self.lever_arm_b_m, &omega);
        let mut z = gnss::ned_difference_m(&position, &fix.position)
            .as_slice()
            .to_vec();
        let mut sigmas = fix.position_sigma_m.as_slice().to_vec();
        let rows = if let Some(v) = fix.velocity_ned_m_s {
            z.extend((velocity - v).iter());
            sigmas.extend(fix.velocity_sigma_m_s.iter());
            6
        } else {
            3
        };
        let h = DMatrix::from_fn(rows, STATES, |i, j| h6[(i, j)]);
        let r = DMatrix::from_diagonal(&DVector::from_iterator(rows, sigmas.iter().map(|s| s * s)));
        let nu = DVector::from_vec(z);
        let p = DMatrix::from_fn(STATES, STATES, |i, j| self.covariance[(i, j)]);
        let s = &h * &p * h.transpose() + &r;
        let chol = Cholesky::new(s.clone()).ok_or(FilterError::Innovation { t_s: fix.t_s })?;
        // K = P Hᵀ S⁻¹, from S Kᵀ = H P.
        let k = chol.solve(&(&h * &p)).transpose();
        let nis = nu.dot(&chol.solve(&nu));
        let dx = &k * &nu;
        let i_kh = DMatrix::identity(STATES, STATES) - &k * &h;
        let p_new = &i_kh * &p * i_kh.transpose() + &k * &r * k.transpose();
        let p_new = (&p_new + p_new.transpose()) * 0.5;
        self.covariance = Matrix15::from_fn(|i, j| p_new[(i, j)]);
        self.correct(&SMatrix::<f64, STATES, 1>::from_fn(|i, _| dx[i]));
        Ok(Innovation {
            t_s: fix.t_s,
            residual: nu,
            covariance: s,
            nis,
        })
    }

    /// The closed-loop correction by the estimated errors `dx` (estimate minus truth): each part
    /// of the solution has its error taken out, and the error state is zero again.
    fn correct(&mut self, dx: &SMatrix<f64, STATES, 1>) {
        let p = &mut self.pva.position;
        let (rn, re) = super::earth::radii_m(p.lat_rad);
        let dr = dx.fixed_rows::<3>(POSITION);
        p.lat_rad -= dr[0] / (rn + p.height_m);
        p.lon_rad -= dr[1] / ((re + p.height_m) * p.lat_rad.cos());
        p.height_m += dr[2];
        self.pva.velocity_ned_m_s -= dx.fixed_rows::<3>(VELOCITY);
        // Ĉ = exp([δψ×])C, so C = exp(−[δψ×])Ĉ.
        let psi = dx.fixed_rows::<3>(ATTITUDE).into_owned();
        self.pva.attitude = UnitQuaternion::from_scaled_axis(-psi) * self.pva.attitude;
        self.gyro_bias_rad_s -= dx.fixed_rows::<3>(GYRO_BIAS);
        self.accel_bias_m_s2 -= dx.fixed_rows::<3>(ACCEL_BIAS);
    }
}
