//! Multi-position sessions drawn from the model: an IMU of known intrinsics turned by hand into
//! poses, still in each, with white noise, a random walk and the Earth's rate — the truth the
//! calibration's coverage is proven against.
//!
//! # Formula
//! The sensor reads f̃ = M_a⁻¹ f + b_a + n and ω̃ = M_g⁻¹ ω + b_g + n (the calibration's model
//! inverted), f and ω in the accelerometer's corrected frame. Between poses the attitude turns
//! about one axis, C_nb(t) = C_nb,a · exp(s(t)[φ×]) with s = 3x² − 2x³ (x = t/T), so the rate over
//! a step is exactly Δs/τ · φ; the Earth's rate ω_ie^n = Ω(cos L, 0, −sin L) is added, and
//! f = −C_bn g^n at each step's middle (NED, g^n = (0, 0, g)).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::SixAxisLog;
use super::gyro::EARTH_RATE_RAD_S;
use crate::random::Stream;

/// An IMU's true intrinsics, in the calibration's convention.
#[derive(Clone, Copy, Debug)]
pub struct TrueIntrinsics {
    /// The accelerometers' bias, m/s².
    pub accel_bias: Vector3<f64>,
    /// The accelerometers' matrix (lower triangular).
    pub accel_matrix: Matrix3<f64>,
    /// The gyros' bias, rad/s.
    pub gyro_bias: Vector3<f64>,
    /// The gyros' matrix.
    pub gyro_matrix: Matrix3<f64>,
}

/// How a session is recorded.
#[derive(Clone, Debug)]
pub struct Session {
    /// The poses, as attitudes C_nb.
    pub poses: Vec<UnitQuaternion<f64>>,
    /// Time still in each pose, s.
    pub static_s: f64,
    /// Time of each turn between poses, s.
    pub turn_s: f64,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Accelerometer white noise, m/s/√s.
    pub accel_white: f64,
    /// Accelerometer bias random walk, m/s²/√s.
    pub accel_walk: f64,
    /// Gyro white noise, rad/√s.
    pub gyro_white: f64,
    /// Gyro bias random walk, rad/s/√s.
    pub gyro_walk: f64,
    /// A drift of the accelerometers' bias the model lacks (as a temperature's), m/s² per s.
    pub accel_drift: Vector3<f64>,
    /// Gravity, m/s².
    pub gravity_m_s2: f64,
    /// Latitude, rad.
    pub latitude_rad: f64,
}

impl Session {
    /// A consumer MEMS at 100 Hz in `poses`, 6 s still in each, 3 s turns.
    pub fn consumer(poses: Vec<UnitQuaternion<f64>>) -> Self {
        Self {
            poses,
            static_s: 6.0,
            turn_s: 3.0,
            rate_hz: 100.0,
            accel_white: 1.5e-3,
            accel_walk: 5e-6,
            gyro_white: 1.7e-4,
            gyro_walk: 1e-7,
            accel_drift: Vector3::zeros(),
            gravity_m_s2: 9.806_65,
            latitude_rad: 49.0_f64.to_radians(),
        }
    }
}

/// A uniform number in [−1, 1).
fn symmetric(rng: &mut Stream) -> f64 {
    ((rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)) * 2.0 - 1.0
}

/// Intrinsics of a consumer MEMS: scale factors within ±3 %, non-orthogonality and the gyros'
/// misalignment within ±2°, biases within ±0.3 m/s² and ±0.02 rad/s.
pub fn draw_intrinsics(rng: &mut Stream) -> TrueIntrinsics {
    let angle = 2.0_f64.to_radians();
    let mut rows = Matrix3::identity();
    for (r, c) in [(1, 0), (2, 0), (2, 1)] {
        rows[(r, c)] = angle * symmetric(rng);
    }
    for r in 0..3 {
        let norm = rows.row(r).norm();
        let gain = 1.0 + 0.03 * symmetric(rng);
        let scaled = rows.row(r) * (gain / norm);
        rows.set_row(r, &scaled);
    }
    let mut gyro = Matrix3::identity();
    for r in 0..3 {
        for c in 0..3 {
            gyro[(r, c)] = if r == c {
                1.0 + 0.03 * symmetric(rng)
            } else {
                angle * symmetric(rng)
            };
        }
    }
    TrueIntrinsics {
        accel_bias: Vector3::from_fn(|_, _| 0.3 * symmetric(rng)),
        accel_matrix: rows.try_inverse().expect("near the identity"),
        gyro_bias: Vector3::from_fn(|_, _| 0.02 * symmetric(rng)),
        gyro_matrix: gyro.try_inverse().expect("near the identity"),
    }
}

/// `count` attitudes drawn uniformly (Shoemake's normal quaternion).
pub fn random_poses(count: usize, rng: &mut Stream) -> Vec<UnitQuaternion<f64>> {
    (0..count)
        .map(|_| {
            let q =
                nalgebra::Quaternion::new(rng.normal(), rng.normal(), rng.normal(), rng.normal());
            UnitQuaternion::from_quaternion(q)
        })
        .collect()
}

/// Draws one session's log of the IMU `truth`.
pub fn simulate(truth: &TrueIntrinsics, session: &Session, rng: &mut Stream) -> SixAxisLog {
    let tau = 1.0 / session.rate_hz;
    let g_n = Vector3::new(0.0, 0.0, session.gravity_m_s2);
    let lat = session.latitude_rad;
    let earth_n = Vector3::new(lat.cos(), 0.0, -lat.sin()) * EARTH_RATE_RAD_S;
    let accel_raw = truth.accel_matrix.try_inverse().expect("invertible");
    let gyro_raw = truth.gyro_matrix.try_inverse().expect("invertible");
    let accel_sigma = session.accel_white / tau.sqrt();
    let gyro_sigma = session.gyro_white / tau.sqrt();
    let mut accel_walk = Vector3::zeros();
    let mut gyro_walk = Vector3::zeros();
    let mut log = SixAxisLog {
        sample_period_s: tau,
        specific_force: Vec::new(),
        angular_rate: Vec::new(),
    };
    let mut t = 0.0;
    let mut emit = |c_nb: &Rotation3<f64>, motion_rate: Vector3<f64>, rng: &mut Stream| {
        let f = -(c_nb.inverse() * g_n);
        let w = motion_rate + c_nb.inverse() * earth_n;
        let noise = |s: f64, rng: &mut Stream| Vector3::from_fn(|_, _| s * rng.normal());
        accel_walk += noise(session.accel_walk * tau.sqrt(), rng);
        gyro_walk += noise(session.gyro_walk * tau.sqrt(), rng);
        let drift = session.accel_drift * t;
        t += tau;
        log.specific_force
            .push(accel_raw * f + truth.accel_bias + accel_walk + drift + noise(accel_sigma, rng));
        log.angular_rate
            .push(gyro_raw * w + truth.gyro_bias + gyro_walk + noise(gyro_sigma, rng));
    };
    let still = (session.static_s / tau).round() as usize;
    let turn = (session.turn_s / tau).round() as usize;
    for (p, pose) in session.poses.iter().enumerate() {
        let c = pose.to_rotation_matrix();
        for _ in 0..still {
            emit(&c, Vector3::zeros(), rng);
        }
        let Some(next) = session.poses.get(p + 1) else {
            break;
        };
        let phi = (pose.inverse() * next).scaled_axis();
        let smooth = |x: f64| x * x * (3.0 - 2.0 * x);
        for k in 0..turn {
            let (a, b) = (k as f64 / turn as f64, (k + 1) as f64 / turn as f64);
            let mid = Rotation3::from_scaled_axis(phi * smooth(0.5 * (a + b)));
            emit(&(c * mid), phi * ((smooth(b) - smooth(a)) / tau), rng);
        }
    }
    log
}
