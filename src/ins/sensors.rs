//! The sensors of one simulated realization: an IMU that reads the truth's increments with a
//! drifting bias and white noise, and a GNSS receiver that reads the antenna's position and
//! velocity with white noise.
//!
//! Each gyro and accelerometer bias is a first-order Gauss–Markov process (or a constant, or a
//! random walk) discretized exactly per step, b_{k+1} = e^(−Δt/τ)·b_k + η with
//! η ~ N(0, σ²(1 − e^(−2Δt/τ))); the white noise adds N(0, ARW²·Δt) to each Δθ and
//! N(0, VRW²·Δt) to each Δv (angle and velocity random walk: Groves §4.4.3). Each axis also has
//! a scale factor s, a constant drawn once from N(0, σ_s²): the sensor reads (1 + s)·x + b·Δt +
//! noise of the true increment x (Groves §4.4.2, the scale-factor error; cross-coupling left
//! out). The scale factors come from a stream of their own, so a study without them draws the
//! same numbers as before they existed.
//!
//! A car's IMU is mounted in the vehicle by a rotation C_b^v: the drive's truth is the vehicle's,
//! and the IMU reads its increments in its own axes, x^b = C_v^b·x^v (a constant rotation: the
//! increments rotate as the rates do). The rotation is the configured one times small angles
//! ε ~ N(0, σ²) per axis in the vehicle's axes, exp(\[ε×\])·C_nominal, drawn once per
//! realization from a stream of its own.

use nalgebra::{UnitQuaternion, Vector3};

use super::mech::{Increment, Pva};
use crate::random::{Stream, splitmix64};

/// Key of the random streams of three-axis realizations.
const STREAM_KEY: u64 = 0x696e_735f_7265_616c;

/// Key of the scale factors' streams.
const SCALE_KEY: u64 = 0x696e_735f_7363_616c;

/// Key of the mounting angles' streams.
const MOUNTING_KEY: u64 = 0x696e_735f_6d6f_756e;

/// How the IMU sits in a vehicle: the configured rotation and the σ of the small angles about
/// it, drawn once per realization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mounting {
    /// The configured q_b^v (IMU axes to the vehicle's forward-right-down).
    pub nominal: UnitQuaternion<f64>,
    /// The small angles' σ per axis, rad.
    pub sigma_rad: f64,
}

/// How one sensor triad's bias moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BiasProcess {
    /// Drawn once from N(0, σ²) and held.
    Constant {
        /// σ, in the sensor's unit.
        sigma: f64,
    },
    /// Starts at zero and walks: b(t + τ) − b(t) ~ N(0, K²τ).
    RandomWalk {
        /// K, the sensor's unit per √s.
        k_per_sqrt_s: f64,
    },
    /// Stationary first-order Gauss–Markov of σ and correlation time τ.
    GaussMarkov {
        /// σ, in the sensor's unit.
        sigma: f64,
        /// τ, s.
        correlation_time_s: f64,
    },
}

impl BiasProcess {
    /// The bias's initial σ (what its estimate's prior variance is), in the sensor's unit.
    pub fn initial_sigma(self) -> f64 {
        match self {
            BiasProcess::Constant { sigma } | BiasProcess::GaussMarkov { sigma, .. } => sigma,
            BiasProcess::RandomWalk { .. } => 0.0,
        }
    }

    /// 1/τ: 0 unless Gauss–Markov.
    pub fn decay_per_s(self) -> f64 {
        match self {
            BiasProcess::GaussMarkov {
                correlation_time_s, ..
            } => 1.0 / correlation_time_s,
            _ => 0.0,
        }
    }

    /// The white-noise density that drives the bias, (unit)²/s: K², 2σ²/τ, or 0.
    pub fn density(self) -> f64 {
        match self {
            BiasProcess::Constant { .. } => 0.0,
            BiasProcess::RandomWalk { k_per_sqrt_s } => k_per_sqrt_s * k_per_sqrt_s,
            BiasProcess::GaussMarkov {
                sigma,
                correlation_time_s,
            } => 2.0 * sigma * sigma / correlation_time_s,
        }
    }

    /// (φ, σ_η) of the exact one-step discretization over `dt`.
    fn step(self, dt: f64) -> (f64, f64) {
        match self {
            BiasProcess::Constant { .. } => (1.0, 0.0),
            BiasProcess::RandomWalk { k_per_sqrt_s } => (1.0, k_per_sqrt_s * dt.sqrt()),
            BiasProcess::GaussMarkov {
                sigma,
                correlation_time_s,
            } => (
                (-dt / correlation_time_s).exp(),
                sigma * (-(-2.0 * dt / correlation_time_s).exp_m1()).sqrt(),
            ),
        }
    }
}

/// The IMU's error model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuModel {
    /// Angle random walk, rad/√s.
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// Velocity random walk, m/s/√s.
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// The gyro biases' process (rad/s).
    pub gyro_bias: BiasProcess,
    /// The accelerometer biases' process (m/s²).
    pub accel_bias: BiasProcess,
    /// The gyro scale factors' σ (dimensionless).
    pub gyro_scale_sigma: f64,
    /// The accelerometer scale factors' σ (dimensionless).
    pub accel_scale_sigma: f64,
    /// The IMU's mounting in a vehicle; `None`: the drive's truth is the IMU's own.
    pub mounting: Option<Mounting>,
}

/// What one step of a given length draws with: the white noises' σ's and the biases' (φ, σ_η),
/// computed once for the IMU's step rather than at every step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct StepScales {
    /// The step, s.
    dt_s: f64,
    /// ARW·√Δt, rad.
    angle_sigma: f64,
    /// VRW·√Δt, m/s.
    velocity_sigma: f64,
    /// The gyro biases' (φ, σ_η).
    gyro_bias: (f64, f64),
    /// The accelerometer biases' (φ, σ_η).
    accel_bias: (f64, f64),
}

impl StepScales {
    fn of(model: &ImuModel, dt: f64) -> Self {
        StepScales {
            dt_s: dt,
            angle_sigma: model.gyro_arw_rad_per_sqrt_s * dt.sqrt(),
            velocity_sigma: model.accel_vrw_m_s_per_sqrt_s * dt.sqrt(),
            gyro_bias: model.gyro_bias.step(dt),
            accel_bias: model.accel_bias.step(dt),
        }
    }
}

/// One realization's IMU: its random stream and its biases now.
pub struct Imu {
    model: ImuModel,
    stream: Stream,
    /// The last step's scales.
    scales: Option<StepScales>,
    /// The gyro biases now, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer biases now, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The gyro scale factors (dimensionless).
    pub gyro_scale: Vector3<f64>,
    /// The accelerometer scale factors (dimensionless).
    pub accel_scale: Vector3<f64>,
    /// The true q_b^v when mounted in a vehicle.
    pub mounting: Option<UnitQuaternion<f64>>,
}

impl Imu {
    /// The IMU of realization `index` under `seed`, its biases drawn from their initial
    /// distributions. Its stream depends on nothing else: results do not depend on the thread
    /// count.
    pub fn new(model: ImuModel, seed: u64, index: u64) -> Self {
        let mut stream = Stream::new(splitmix64(seed ^ STREAM_KEY), index);
        let mut draw = |sigma: f64| Vector3::from_fn(|_, _| sigma * stream.normal());
        let gyro_bias_rad_s = draw(model.gyro_bias.initial_sigma());
        let accel_bias_m_s2 = draw(model.accel_bias.initial_sigma());
        let mut scale = Stream::new(splitmix64(seed ^ SCALE_KEY), index);
        let mut draw = |sigma: f64| Vector3::from_fn(|_, _| sigma * scale.normal());
        let gyro_scale = draw(model.gyro_scale_sigma);
        let accel_scale = draw(model.accel_scale_sigma);
        let mounting = model.mounting.map(|m| {
            let mut small = Stream::new(splitmix64(seed ^ MOUNTING_KEY), index);
            let e = Vector3::from_fn(|_, _| m.sigma_rad * small.normal());
            UnitQuaternion::from_scaled_axis(e) * m.nominal
        });
        Imu {
            model,
            stream,
            scales: None,
            gyro_bias_rad_s,
            accel_bias_m_s2,
            gyro_scale,
            accel_scale,
            mounting,
        }
    }

    /// The IMU's true navigation state when the vehicle's is `vehicle`: the same position and
    /// velocity, the attitude C_b^n = C_v^n·C_b^v (the vehicle's itself without a mounting).
    pub fn pva_of(&self, vehicle: &Pva) -> Pva {
        match self.mounting {
            Some(q_bv) => Pva {
                attitude: vehicle.attitude * q_bv,
                ..*vehicle
            },
            None => *vehicle,
        }
    }

    /// A vector of the vehicle's axes in the IMU's, C_v^b·x (itself without a mounting).
    pub fn to_body(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.mounting.map_or(*x, |q| q.inverse_transform_vector(x))
    }

    /// What the IMU outputs for the true increments `truth` (the vehicle's, when mounted in
    /// one); its biases then step on.
    pub fn read(&mut self, vehicle: &Increment) -> Increment {
        let rotated;
        let truth = match self.mounting {
            Some(_) => {
                rotated = Increment {
                    dtheta_rad: self.to_body(&vehicle.dtheta_rad),
                    dvel_m_s: self.to_body(&vehicle.dvel_m_s),
                    dt_s: vehicle.dt_s,
                };
                &rotated
            }
            None => vehicle,
        };
        let dt = truth.dt_s;
        let k = match self.scales {
            Some(k) if k.dt_s == dt => k,
            _ => *self.scales.insert(StepScales::of(&self.model, dt)),
        };
        let s = &mut self.stream;
        let (arw, vrw) = (k.angle_sigma, k.velocity_sigma);
        let dtheta = truth.dtheta_rad
            + truth.dtheta_rad.component_mul(&self.gyro_scale)
            + self.gyro_bias_rad_s * dt
            + Vector3::from_fn(|_, _| arw * s.normal());
        let dvel = truth.dvel_m_s
            + truth.dvel_m_s.component_mul(&self.accel_scale)
            + self.accel_bias_m_s2 * dt
            + Vector3::from_fn(|_, _| vrw * s.normal());
        let (phi_g, eta_g) = k.gyro_bias;
        let (phi_a, eta_a) = k.accel_bias;
        self.gyro_bias_rad_s =
            self.gyro_bias_rad_s * phi_g + Vector3::from_fn(|_, _| eta_g * s.normal());
        self.accel_bias_m_s2 =
            self.accel_bias_m_s2 * phi_a + Vector3::from_fn(|_, _| eta_a * s.normal());
        Increment {
            dtheta_rad: dtheta,
            dvel_m_s: dvel,
            dt_s: dt,
        }
    }

    /// A draw of N(0, 1) from this realization's stream.
    pub fn normal(&mut self) -> f64 {
        self.stream.normal()
    }

    /// A draw of N(0, σ²) per component from this realization's stream (for the GNSS noise and
    /// the initial errors, in a fixed order).
    pub fn normals(&mut self, sigma: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from_fn(|i, _| sigma[i] * self.stream.normal())
    }
}
