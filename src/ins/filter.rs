//! The INS/GNSS error-state extended Kalman filter, closed loop: the mechanization carries the
//! navigation solution, the filter its 15 errors (21 with the sensors' scale factors: `Ekf<21>`);
//! each fix corrects the solution, the biases (and the scale factors)
//! and resets the error state to zero (Groves §14.1.1, closed-loop correction; the arrangement of
//! KF-GINS's `GIEngine`).
//!
//! The update is the Joseph form P⁺ = (I − KH)P(I − KH)ᵀ + KRKᵀ with the gain from a Cholesky
//! factor of the innovation covariance S = HPHᵀ + R (no explicit inverse).

use nalgebra::{DMatrix, DVector, Matrix3, SVector, UnitQuaternion, Vector3};
use thiserror::Error;

use crate::state::Variable;

use super::discrete::{self, NoiseDensities};
use super::error_state::{self, BiasDecay, Motion, STATES, Square, holds, start_of};
use super::gnss::{Fix, FixUpdate};
use super::mech::{self, Increment, Pva};
use super::state::Block;

mod correct;
mod parts;
mod update;

pub use correct::apply_correction;
pub use parts::{LinearView, NOISE_GROUPS};

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

/// What one update saw: the innovation, its covariance and the normalized squared innovation
/// (NIS).
#[derive(Clone, Debug, PartialEq)]
pub struct Innovation<const N: usize = STATES> {
    /// The measurement's time, s.
    pub t_s: f64,
    /// The innovation ν (position NED m, then velocity NED m/s where measured).
    pub residual: DVector<f64>,
    /// Its covariance S.
    pub covariance: DMatrix<f64>,
    /// νᵀS⁻¹ν.
    pub nis: f64,
    /// The estimated errors K·ν the update took out of the solution (zero when rejected).
    pub correction: SVector<f64, N>,
    /// Each component's name, in the residual's order.
    pub components: Vec<&'static Variable>,
    /// Whether the update was applied: false when the χ² gate rejected the innovation.
    pub accepted: bool,
}

/// How the filter carries its covariance from one IMU step to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Propagation {
    /// P ← ΦPΦᵀ + Q_d at every IMU step with F at the step's start, Φ to second order and Q_d by
    /// the trapezoid ([`discrete::transition`], [`discrete::process_noise`]), dense 15×15
    /// products: the reference.
    Dense,
    /// P ← ΦPΦᵀ + Q_d once per interval of about `interval_s` seconds (a whole number of IMU
    /// steps), F averaged over the interval's steps, Φ to third order and Q_d by the series of
    /// Van Loan's integral ([`discrete::transition_third_order`],
    /// [`discrete::process_noise_series`]). The Kalman filter's system propagation at a lower
    /// rate than the navigation equations, which the slowly varying error dynamics allow:
    /// Groves (2013) §3.4.2 (algorithm design); high-rate sums between fixes, the covariance
    /// propagated at the fix: Schimelevich & Naor, ION GPS 1995, pp. 1869–1873.
    Interval {
        /// The interval, s.
        interval_s: f64,
    },
}

/// The covariance interval [`Ekf::new`] takes: 0.2 s (40 steps at 200 Hz), 5 intervals per fix
/// at 1 Hz (at most: the largest divisor of the steps between fixes; before the first fix, each
/// step). P at every fix of the default drive stays within 1.4·10⁻³ (whitened Frobenius) of the
/// per-step reference, a third of the bound `tests/propagation.rs` derives.
pub const DEFAULT_COVARIANCE_INTERVAL_S: f64 = 0.2;

/// What a covariance interval has gathered of its IMU steps: F's entries are linear in C_b^n and
/// f^n, so their sums give F's mean.
#[derive(Clone, Debug, PartialEq)]
struct Pending {
    /// Steps gathered.
    steps: usize,
    /// Steps in the interval.
    target: usize,
    /// Their total time, s.
    t_s: f64,
    /// Σ C_b^n at the steps' starts.
    c_sum: Matrix3<f64>,
    /// Σ C_b^n f^b (m/s²).
    f_n_sum: Vector3<f64>,
    /// Σ C_b^n diag(f^b) (m/s²), for the accelerometer scale factors.
    c_f_sum: Matrix3<f64>,
    /// Σ C_b^n diag(ω_ib^b) (rad/s), for the gyro scale factors.
    c_w_sum: Matrix3<f64>,
    /// The solution at the interval's middle step, for F's position and velocity blocks.
    middle: Pva,
}

/// The filter: the navigation solution, the bias estimates (and the scale factors' with `N` =
/// 21), and the covariance of their errors.
#[derive(Clone, Debug, PartialEq)]
pub struct Ekf<const N: usize = STATES> {
    /// The navigation solution at the last step.
    pub pva: Pva,
    /// The gyro bias estimate, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer bias estimate, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The gyro scale factor estimates (dimensionless; zero and held without the scale states).
    pub gyro_scale: Vector3<f64>,
    /// The accelerometer scale factor estimates (dimensionless), likewise.
    pub accel_scale: Vector3<f64>,
    /// The IMU's mounting in the vehicle, q_b^v (C_b^v: IMU axes to the vehicle's
    /// forward-right-down); corrected with the mounting block, else held as given.
    pub mounting: UnitQuaternion<f64>,
    /// The error state's covariance P: current after each update and after the step that ends a
    /// covariance interval. With [`Propagation::Interval`] the intervals divide the time between
    /// the last two fixes, so with evenly spaced fixes P is current at each; [`Ekf::flush`]
    /// brings it up to date anywhere.
    pub covariance: Square<N>,
    /// The noise densities the filter assumes.
    pub noise: NoiseDensities,
    /// The biases' decay rates the filter assumes.
    pub decay: BiasDecay,
    /// The antenna's lever arm in body axes, m.
    pub lever_arm_b_m: Vector3<f64>,
    /// The Earth's rotation rate the mechanization and F use, rad/s (0 in the negative control
    /// of a filter that leaves it out).
    pub earth_rotation_rad_s: f64,
    /// How the covariance is propagated.
    propagation: Propagation,
    /// The steps not yet in P.
    pending: Option<Pending>,
    /// IMU steps since the last update.
    steps_since_update: usize,
    /// IMU steps between the last two updates (from the start for the first).
    fix_period_steps: Option<usize>,
    /// The previous step's compensated increments (for sculling and coning).
    before: Option<Increment>,
    /// Φ from the last update to the last covariance propagation, when tracked (a smoother
    /// needs it; [`Ekf::with_transition`]).
    transition: Option<Square<N>>,
    /// Q_d from the last update split by noise group, each at unit density, when tracked (a
    /// likelihood linearized about the run needs it; [`Ekf::with_noise_parts`]).
    noise_parts: Option<Box<[Square<N>; NOISE_GROUPS]>>,
}

impl<const N: usize> Ekf<N> {
    /// A filter starting at `pva` with zero bias estimates and covariance `p0`, propagating its
    /// covariance every [`DEFAULT_COVARIANCE_INTERVAL_S`].
    pub fn new(
        pva: Pva,
        p0: Square<N>,
        noise: NoiseDensities,
        decay: BiasDecay,
        lever_arm_b_m: Vector3<f64>,
    ) -> Self {
        Ekf {
            pva,
            gyro_bias_rad_s: Vector3::zeros(),
            accel_bias_m_s2: Vector3::zeros(),
            gyro_scale: Vector3::zeros(),
            accel_scale: Vector3::zeros(),
            mounting: UnitQuaternion::identity(),
            covariance: p0,
            noise,
            decay,
            lever_arm_b_m,
            earth_rotation_rad_s: super::earth::ROTATION_RATE_RAD_S,
            propagation: Propagation::Interval {
                interval_s: DEFAULT_COVARIANCE_INTERVAL_S,
            },
            pending: None,
            steps_since_update: 0,
            fix_period_steps: None,
            before: None,
            transition: None,
            noise_parts: None,
        }
    }

    /// The same filter keeping Φ from each update to the next ([`Ekf::take_transition`]).
    #[must_use]
    pub fn with_transition(mut self) -> Self {
        self.flush();
        self.transition = Some(Square::<N>::identity());
        self
    }

    /// Φ from the last update (or the start) to the last covariance propagation, restarted at
    /// the identity; `None` unless tracked.
    pub fn take_transition(&mut self) -> Option<Square<N>> {
        self.transition.replace(Square::<N>::identity())
    }

    /// The same filter with the IMU mounted in the vehicle by `mounting` (q_b^v), its estimate
    /// or its given value.
    #[must_use]
    pub fn with_mounting(mut self, mounting: UnitQuaternion<f64>) -> Self {
        self.mounting = mounting;
        self
    }

    /// The same filter propagating its covariance as `propagation` says.
    #[must_use]
    pub fn with_propagation(mut self, propagation: Propagation) -> Self {
        self.flush();
        self.propagation = propagation;
        self
    }

    /// The same filter on an Earth turning at `rotation_rad_s` (0: it leaves the Earth's rate
    /// out of its mechanization and of F).
    #[must_use]
    pub fn with_earth_rotation(mut self, rotation_rad_s: f64) -> Self {
        self.flush();
        self.earth_rotation_rad_s = rotation_rad_s;
        self
    }

    /// The increments `raw` compensated by the bias estimates, and with the scale states by
    /// the scale factor estimates: x̂ = (x̃ − b̂Δt)/(1 + ŝ) per axis (KF-GINS's `imuCompensate`).
    fn compensate(&self, raw: &Increment) -> Increment {
        let dtheta_rad = raw.dtheta_rad - self.gyro_bias_rad_s * raw.dt_s;
        let dvel_m_s = raw.dvel_m_s - self.accel_bias_m_s2 * raw.dt_s;
        if !holds::<N>(Block::GyroScale) {
            return Increment {
                dtheta_rad,
                dvel_m_s,
                dt_s: raw.dt_s,
            };
        }
        let one = Vector3::repeat(1.0);
        Increment {
            dtheta_rad: dtheta_rad.component_div(&(one + self.gyro_scale)),
            dvel_m_s: dvel_m_s.component_div(&(one + self.accel_scale)),
            dt_s: raw.dt_s,
        }
    }

    /// One IMU step: the mechanization with the compensated increments, the bias estimates'
    /// decay, and the covariance: P ← ΦPΦᵀ + Q_d with F at the step's start
    /// ([`Propagation::Dense`]), or the step gathered into its interval, P propagated at the
    /// interval's end ([`Propagation::Interval`]).
    pub fn propagate(&mut self, raw: &Increment) {
        let now = self.compensate(raw);
        let before = self.before.unwrap_or(now);
        let f_b = now.dvel_m_s / now.dt_s;
        let w_b = now.dtheta_rad / now.dt_s;
        match self.propagation {
            Propagation::Dense => {
                let c = *self.pva.attitude.to_rotation_matrix().matrix();
                let big_f = error_state::dynamics_of::<N>(
                    &self.pva,
                    &Motion::of(&c, &f_b, &w_b),
                    &self.decay,
                    self.earth_rotation_rad_s,
                );
                let phi = discrete::transition(&big_f, now.dt_s);
                let q = discrete::process_noise(&phi, &self.noise, now.dt_s);
                self.covariance = phi * self.covariance * phi.transpose() + q;
                if let Some(t) = self.transition.as_mut() {
                    *t = phi * *t;
                }
                self.propagate_parts_dense(&phi, now.dt_s);
            }
            Propagation::Interval { interval_s } => {
                self.gather(&f_b, &w_b, now.dt_s, interval_s);
            }
        }
        self.pva = mech::step_rotating(&self.pva, &before, &now, self.earth_rotation_rad_s);
        self.gyro_bias_rad_s *= (-self.decay.gyro_per_s * now.dt_s).exp();
        self.accel_bias_m_s2 *= (-self.decay.accel_per_s * now.dt_s).exp();
        self.before = Some(now);
        self.steps_since_update += 1;
        if self.pending.as_ref().is_some_and(|p| p.steps == p.target) {
            self.flush();
        }
    }

    /// The step from the solution now with specific force `f_b` and rate `w_b` over `dt` added
    /// to the interval.
    fn gather(&mut self, f_b: &Vector3<f64>, w_b: &Vector3<f64>, dt: f64, interval_s: f64) {
        let c = *self.pva.attitude.to_rotation_matrix().matrix();
        let period = self.fix_period_steps;
        // Intervals of the nominal length, or of the fix period when that is shorter; one step
        // until the first fix has shown the period. A period the nominal interval divides is
        // tiled by whole intervals, so that P is current at each evenly spaced fix; otherwise
        // the update flushes the interval it cuts (a fix between two IMU samples makes the
        // period a count of steps with no useful divisor: 1 201 parts of steps between fixes
        // at 1 200 Hz, a prime, which the largest divisor turned into a propagation per step).
        let target = || {
            let nominal = ((interval_s / dt).round() as usize).max(1);
            period.map_or(1, |m| {
                if m % nominal == 0 || m < nominal {
                    nominal.min(m)
                } else {
                    (1..=nominal)
                        .rev()
                        .find(|d| m % d == 0 && 2 * d >= nominal)
                        .unwrap_or(nominal)
                }
            })
        };
        let pending = self.pending.get_or_insert_with(|| Pending {
            steps: 0,
            target: target(),
            t_s: 0.0,
            c_sum: Matrix3::zeros(),
            f_n_sum: Vector3::zeros(),
            c_f_sum: Matrix3::zeros(),
            c_w_sum: Matrix3::zeros(),
            middle: self.pva,
        });
        if pending.steps == pending.target / 2 {
            pending.middle = self.pva;
        }
        pending.steps += 1;
        pending.t_s += dt;
        pending.c_sum += c;
        pending.f_n_sum += c * f_b;
        if holds::<N>(Block::GyroScale) {
            pending.c_f_sum += c * Matrix3::from_diagonal(f_b);
            pending.c_w_sum += c * Matrix3::from_diagonal(w_b);
        }
    }

    /// P brought up to the last step: the pending interval's ΦPΦᵀ + Q_d with F at its steps'
    /// mean. Nothing to do with [`Propagation::Dense`] or no step pending.
    pub fn flush(&mut self) {
        let Some(p) = self.pending.take() else {
            return;
        };
        let n = p.steps as f64;
        let motion = Motion {
            c: p.c_sum / n,
            f_n: p.f_n_sum / n,
            c_f: p.c_f_sum / n,
            c_w: p.c_w_sum / n,
        };
        let big_f = error_state::dynamics_of::<N>(
            &p.middle,
            &motion,
            &self.decay,
            self.earth_rotation_rad_s,
        );
        let phi = discrete::transition_third_order(&big_f, p.t_s);
        let q = discrete::process_noise_series(&big_f, &self.noise, p.t_s);
        self.covariance = discrete::transition_congruence(&phi, &self.covariance) + q;
        if let Some(t) = self.transition.as_mut() {
            *t = phi * *t;
        }
        self.propagate_parts_interval(&phi, &big_f, p.t_s);
    }

    /// The update by every component of `fix`, ungated ([`Ekf::update_by`] with
    /// [`FixUpdate::whole`]).
    ///
    /// # Errors
    /// [`FilterError::Innovation`] when S is not positive definite.
    pub fn update(&mut self, fix: &Fix) -> Result<Innovation<N>, FilterError> {
        self.update_by(&FixUpdate::whole(*fix), None)
    }

    /// The closed-loop correction by the estimated errors `dx` ([`apply_correction`]).
    fn correct(&mut self, dx: &SVector<f64, N>) {
        apply_correction(
            &mut self.pva,
            &mut self.gyro_bias_rad_s,
            &mut self.accel_bias_m_s2,
            &dx.fixed_rows::<STATES>(0).into_owned(),
        );
        if holds::<N>(Block::GyroScale) {
            self.gyro_scale -= dx.fixed_rows::<3>(start_of::<N>(Block::GyroScale));
            self.accel_scale -= dx.fixed_rows::<3>(start_of::<N>(Block::AccelScale));
        }
        if holds::<N>(Block::Mounting) {
            // Ĉ_b^v = exp([δμ×])C_b^v, so C_b^v = exp(−[δμ×])Ĉ_b^v, as the attitude.
            let mu = dx
                .fixed_rows::<3>(start_of::<N>(Block::Mounting))
                .into_owned();
            self.mounting = UnitQuaternion::from_scaled_axis(-mu) * self.mounting;
        }
    }
}
