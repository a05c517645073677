//! What a likelihood linearized about one run of the filter needs of it (Mehra 1970's
//! likelihood of a linear model, evaluated at other noise statistics without rerunning the
//! mechanization): Q_d between fixes split by noise group, each at unit density, and the
//! observation with the rate at which the predicted measurement moves.
//!
//! Q_d is linear in the white-noise densities: each interval's Van Loan series
//! ([`discrete::process_noise_series`]) and the trapezoid ([`discrete::process_noise`]) are, and
//! so is their sum carried through Φ (Groves §3.2.3), so Q_d(θ) = Σ_g d_g(θ)·Q_g with Q_g the
//! process noise of group g at unit density.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::Ekf;
use crate::ins::discrete::{self, NoiseDensities};
use crate::ins::earth;
use crate::ins::error_state::{STATES, Square};
use crate::ins::gnss;

/// The noise groups whose densities Q_d is linear in: the accelerometers' VRW², the gyros'
/// ARW², the gyro biases' and the accelerometer biases' driving densities
/// ([`NoiseDensities::groups`]).
pub const NOISE_GROUPS: usize = 4;

impl NoiseDensities {
    /// The four densities Q_d is linear in, in [`NOISE_GROUPS`]' order: VRW² ((m/s²)²/Hz), ARW²
    /// ((rad/s)²/Hz), the gyro biases' and the accelerometer biases' driving densities.
    pub fn groups(&self) -> [f64; NOISE_GROUPS] {
        [
            self.accel_vrw_m_s_per_sqrt_s.powi(2),
            self.gyro_arw_rad_per_sqrt_s.powi(2),
            self.gyro_bias_density,
            self.accel_bias_density,
        ]
    }

    /// The densities of group `g` alone at unit density.
    fn unit(g: usize) -> Self {
        let one = |i| if i == g { 1.0 } else { 0.0 };
        NoiseDensities {
            accel_vrw_m_s_per_sqrt_s: one(0),
            gyro_arw_rad_per_sqrt_s: one(1),
            gyro_bias_density: one(2),
            accel_bias_density: one(3),
        }
    }
}

/// The filter's view of a fix before its update, for a likelihood linearized about the run.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearView<const N: usize = STATES> {
    /// H of the antenna's position (3) and velocity (3) at the solution.
    pub observation: SMatrix<f64, 6, N>,
    /// The antenna's velocity, NED, m/s: the rate of its predicted position.
    pub antenna_velocity_ned_m_s: Vector3<f64>,
    /// C_b^n at the fix.
    pub c_bn: Matrix3<f64>,
    /// The velocity's rate besides the specific force, γ − (2Ω_ie + Ω_en)×v (Groves eq. 5.54),
    /// NED, m/s².
    pub field_acceleration_ned_m_s2: Vector3<f64>,
    /// The accelerometer bias estimate before the update, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The accelerometer scale factor estimates before the update (zero without the scale
    /// states).
    pub accel_scale: Vector3<f64>,
}

impl<const N: usize> Ekf<N> {
    /// The same filter keeping Q_d from each update to the next split by noise group
    /// ([`Ekf::take_noise_parts`]).
    #[must_use]
    pub fn with_noise_parts(mut self) -> Self {
        self.flush();
        self.noise_parts = Some(Box::new([Square::<N>::zeros(); NOISE_GROUPS]));
        self
    }

    /// Q_d of each noise group at unit density from the last update (or the start) to the last
    /// covariance propagation, restarted at zero; `None` unless tracked.
    pub fn take_noise_parts(&mut self) -> Option<[Square<N>; NOISE_GROUPS]> {
        self.noise_parts
            .as_mut()
            .map(|p| std::mem::replace(&mut **p, [Square::<N>::zeros(); NOISE_GROUPS]))
    }

    /// Each tracked part carried through one dense step Φ over `dt`.
    pub(super) fn propagate_parts_dense(&mut self, phi: &Square<N>, dt: f64) {
        if let Some(parts) = self.noise_parts.as_mut() {
            for (g, q) in parts.iter_mut().enumerate() {
                *q = phi * *q * phi.transpose()
                    + discrete::process_noise(phi, &NoiseDensities::unit(g), dt);
            }
        }
    }

    /// Each tracked part carried through one interval's Φ (dynamics `f`, length `t`).
    pub(super) fn propagate_parts_interval(&mut self, phi: &Square<N>, f: &Square<N>, t: f64) {
        if let Some(parts) = self.noise_parts.as_mut() {
            for (g, q) in parts.iter_mut().enumerate() {
                *q = discrete::transition_congruence(phi, q)
                    + discrete::process_noise_series(f, &NoiseDensities::unit(g), t);
            }
        }
    }

    /// H and what the predicted measurement's motion needs at the fix now (the last step's
    /// compensated rate for the lever arm's terms).
    pub fn linear_view(&self) -> LinearView<N> {
        let omega = self
            .before
            .map_or(Vector3::zeros(), |b| b.dtheta_rad / b.dt_s);
        let observation = gnss::observation_of::<N>(&self.pva, &self.lever_arm_b_m, &omega);
        let (_, velocity) = gnss::antenna(&self.pva, &self.lever_arm_b_m, &omega);
        let p = &self.pva.position;
        let v = self.pva.velocity_ned_m_s;
        let w_ie = earth::earth_rate_ned(p.lat_rad)
            * (self.earth_rotation_rad_s / earth::ROTATION_RATE_RAD_S);
        let w_en = earth::transport_rate_ned(p, &v);
        LinearView {
            observation,
            antenna_velocity_ned_m_s: velocity,
            c_bn: *self.pva.attitude.to_rotation_matrix().matrix(),
            field_acceleration_ned_m_s2: earth::gravity_ned(p) - (2.0 * w_ie + w_en).cross(&v),
            accel_bias_m_s2: self.accel_bias_m_s2,
            accel_scale: self.accel_scale,
        }
    }
}
