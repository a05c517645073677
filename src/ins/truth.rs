//! The exact truth of a [`Drive`] on the rotating Earth: position, velocity and attitude at every
//! IMU time, and the increments Δθ, Δv an ideal IMU measures over each step, to round-off.
//!
//! Velocity, attitude and their rates are closed-form functions of time ([`Drive::motion`]); the
//! position follows from the velocity by the curvilinear equations (L̇ = v_N/(R_N + h), …),
//! integrated by the classical fourth-order Runge–Kutta method over each step (its error, of
//! order Δt⁵·v⁽⁴⁾/R per step, is below round-off at IMU rates). The IMU's rates are
//! ω_ib^b = ω_nb^b + C_n^b(ω_ie^n + ω_en^n) and f^b = C_n^b(v̇^n + (2ω_ie^n + ω_en^n) × v^n − g^n)
//! (the NED navigation equations of Groves §5.4 solved for the sensors), and the increments
//! their integrals over each step by five-point Gauss–Legendre quadrature (exact for polynomials
//! of degree 9; the segments begin and end on whole seconds, so every step lies within one
//! analytic piece when the rate divides a second).

use nalgebra::{UnitQuaternion, Vector3};

use super::drive::{Drive, Motion};
use super::earth::{self, Geodetic};
use super::mech::{Increment, Pva};

/// Gauss–Legendre nodes on [−1, 1] and their weights (Abramowitz & Stegun table 25.4).
const GAUSS_LEGENDRE: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Velocity in NED, its rate, the attitude q_b^n and the body's rate with respect to NED,
/// ω_nb^b, of a motion.
///
/// # Formula
/// v^n = s·u, u = (cos θ cos ψ, cos θ sin ψ, −sin θ) (the body x axis in NED), v̇^n = ṡu + s·u̇;
/// ω_nb^b = (φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, −θ̇ sin φ + ψ̇ cos φ cos θ) (the Euler rates
/// of the ZYX sequence in body axes, Titterton & Weston §3.6).
pub fn kinematics(
    m: &Motion,
) -> (
    Vector3<f64>,
    Vector3<f64>,
    UnitQuaternion<f64>,
    Vector3<f64>,
) {
    let (s, ds) = (m.speed.value, m.speed.rate);
    let (sy, cy) = m.yaw.value.sin_cos();
    let (sp, cp) = m.pitch.value.sin_cos();
    let (sr, cr) = m.roll_rad.sin_cos();
    let (dy, dp, dr) = (m.yaw.rate, m.pitch.rate, m.roll_rate_rad_s);
    let u = Vector3::new(cp * cy, cp * sy, -sp);
    let du = Vector3::new(
        -sp * dp * cy - cp * sy * dy,
        -sp * dp * sy + cp * cy * dy,
        -cp * dp,
    );
    let attitude = super::attitude_from_euler(m.roll_rad, m.pitch.value, m.yaw.value);
    let omega_nb = Vector3::new(
        dr - dy * sp,
        dp * cr + dy * sr * cp,
        -dp * sr + dy * cr * cp,
    );
    (s * u, ds * u + s * du, attitude, omega_nb)
}

/// The ideal IMU's angular rate ω_ib^b (rad/s) and specific force f^b (m/s²) at position `p`
/// during motion `m`.
pub fn imu_rates(p: &Geodetic, m: &Motion) -> (Vector3<f64>, Vector3<f64>) {
    let (v, dv, q_bn, omega_nb) = kinematics(m);
    let q_nb = q_bn.inverse();
    let w_ie = earth::earth_rate_ned(p.lat_rad);
    let w_en = earth::transport_rate_ned(p, &v);
    let omega_ib = omega_nb + q_nb * (w_ie + w_en);
    let f = q_nb * (dv + (2.0 * w_ie + w_en).cross(&v) - earth::gravity_ned(p));
    (omega_ib, f)
}

/// The drive's exact navigation state at every step of `step_s` and the increments between.
pub struct Truth<'a> {
    drive: &'a Drive,
    step_s: f64,
    steps: usize,
    k: usize,
    position: Geodetic,
}

impl<'a> Truth<'a> {
    /// The truth of `drive` starting at `start`, sampled every `step_s` seconds (the whole
    /// drive: ⌊duration/step⌋ steps).
    pub fn new(drive: &'a Drive, start: Geodetic, step_s: f64) -> Self {
        Truth {
            drive,
            step_s,
            steps: (drive.duration_s() / step_s + 1e-9).floor() as usize,
            k: 0,
            position: start,
        }
    }

    /// The truth over the drive's first `duration_s` seconds only.
    pub fn until(mut self, duration_s: f64) -> Self {
        self.steps = self
            .steps
            .min((duration_s / self.step_s + 1e-9).floor() as usize);
        self
    }

    /// The number of steps.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The state at step `k`'s time from the current position (k = the current step).
    pub fn pva(&self) -> Pva {
        let (v, _, attitude, _) = kinematics(&self.drive.motion(self.time(self.k)));
        Pva {
            position: self.position,
            velocity_ned_m_s: v,
            attitude,
        }
    }

    /// t_k = k·Δt, s.
    fn time(&self, k: usize) -> f64 {
        k as f64 * self.step_s
    }

    /// The position at `t1` from `p0` at `t0` (one Runge–Kutta 4 step).
    fn propagate(&self, p0: &Geodetic, t0: f64, t1: f64) -> Geodetic {
        let rate = |p: &Geodetic, t: f64| {
            let (v, ..) = kinematics(&self.drive.motion(t));
            earth::geodetic_rate(p, &v)
        };
        let moved = |p: &Geodetic, d: Vector3<f64>| Geodetic {
            lat_rad: p.lat_rad + d.x,
            lon_rad: p.lon_rad + d.y,
            height_m: p.height_m + d.z,
        };
        let h = t1 - t0;
        let k1 = rate(p0, t0);
        let k2 = rate(&moved(p0, k1 * (h / 2.0)), t0 + h / 2.0);
        let k3 = rate(&moved(p0, k2 * (h / 2.0)), t0 + h / 2.0);
        let k4 = rate(&moved(p0, k3 * h), t1);
        let p1 = moved(p0, (k1 + 2.0 * k2 + 2.0 * k3 + k4) * (h / 6.0));
        Geodetic {
            lon_rad: earth::wrap_longitude(p1.lon_rad),
            ..p1
        }
    }
}

impl Iterator for Truth<'_> {
    /// The increments over [t_{k−1}, t_k] and the state at t_k.
    type Item = (Increment, Pva);

    fn next(&mut self) -> Option<Self::Item> {
        if self.k >= self.steps {
            return None;
        }
        let (t0, t1) = (self.time(self.k), self.time(self.k + 1));
        let half = 0.5 * (t1 - t0);
        let mut dtheta = Vector3::zeros();
        let mut dvel = Vector3::zeros();
        for (x, w) in GAUSS_LEGENDRE {
            let t = t0 + (x + 1.0) * half;
            let p = self.propagate(&self.position, t0, t);
            let (omega, f) = imu_rates(&p, &self.drive.motion(t));
            dtheta += omega * (w * half);
            dvel += f * (w * half);
        }
        self.position = self.propagate(&self.position, t0, t1);
        self.k += 1;
        let inc = Increment {
            dtheta_rad: dtheta,
            dvel_m_s: dvel,
            dt_s: t1 - t0,
        };
        Some((inc, self.pva()))
    }
}
