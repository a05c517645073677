//! The three-axis scenario as the configuration describes it: the drive, the true sensors and the
//! sensors the filter assumes, in the navigation layer's types.

use nalgebra::{UnitQuaternion, Vector3};

use super::discrete::NoiseDensities;
use super::drive::Drive;
use super::earth::Geodetic;
use super::error_state::{ACCEL_BIAS, BiasDecay, GYRO_BIAS, Matrix15, Square, holds, start_of};
use super::sensors::{BiasProcess, Imu, ImuModel, Mounting};
use super::state::{Block, Layout};
use crate::config::BiasModelKind;
use crate::config::ins::{GnssConfig, ImuConfig, InsConfig, VehicleConfig};
use crate::error::ConfigError;

/// A GNSS receiver: its antenna and white noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssModel {
    /// The antenna from the IMU in body axes, m.
    pub lever_arm_b_m: Vector3<f64>,
    /// Position σ north, east, down, m.
    pub position_sigma_m: Vector3<f64>,
    /// Velocity σ per component, m/s.
    pub velocity_sigma_m_s: Vector3<f64>,
}

/// A car: the mounting its filter assumes and the non-holonomic constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vehicle {
    /// The mounting the filter assumes, q_b^v (the truth's is in [`ImuModel::mounting`]).
    pub filter_mounting: UnitQuaternion<f64>,
    /// The filter's prior σ of the mounting's small angles, rad.
    pub mounting_sigma_rad: f64,
    /// The true slip σ of the lateral and vertical velocity, m/s.
    pub nhc_sigma_m_s: f64,
    /// The slip σ the filter assumes, m/s.
    pub filter_nhc_sigma_m_s: f64,
    /// The constraint's rate, Hz.
    pub nhc_rate_hz: f64,
    /// The speed above which the constraint is applied, m/s.
    pub nhc_min_speed_m_s: f64,
}

/// q_b^v of a configured roll, pitch and yaw (ZYX), degrees.
fn rotation_of(rpy_deg: [f64; 3]) -> UnitQuaternion<f64> {
    let [r, p, y] = rpy_deg.map(f64::to_radians);
    super::attitude_from_euler(r, p, y)
}

/// The validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The drive's length, s.
    pub duration_s: f64,
    /// Where it starts.
    pub start: Geodetic,
    /// The IMU's rate, Hz.
    pub imu_rate_hz: f64,
    /// IMU steps between fixes.
    pub imu_steps_per_fix: usize,
    /// The IMU as it is.
    pub truth_imu: ImuModel,
    /// The receiver as it is.
    pub truth_gnss: GnssModel,
    /// The IMU the filter assumes.
    pub filter_imu: ImuModel,
    /// The receiver the filter assumes.
    pub filter_gnss: GnssModel,
    /// The prior σ's of position (m), velocity (m/s) and attitude (rad: roll, pitch, yaw).
    pub initial_sigma: [f64; 9],
    /// Seed of the random streams.
    pub seed: u64,
    /// Realizations of the ensemble.
    pub realizations: u64,
    /// The study-wide false-alarm rate of the checks.
    pub false_alarm_rate: f64,
    /// Largest lag of the residual whiteness check, in fixes (`None`: the default rule).
    pub residual_max_lag: Option<usize>,
    /// The Earth's rotation rate the filter's mechanization uses, rad/s: the true one, or 0 in
    /// the negative control of a filter that leaves it out.
    pub filter_earth_rotation_rad_s: f64,
    /// The filter's error states: 15, 21 with the scale factors, or 18 with a car's mounting.
    pub error_states: usize,
    /// The car, when the IMU is mounted in one.
    pub vehicle: Option<Vehicle>,
}

impl Scenario {
    /// The filter's error state: its blocks (validated with the configuration).
    pub fn layout(&self) -> Layout {
        Layout::with_states(self.error_states).expect("a validated error-state size")
    }
}

/// A sensor triad's bias process from its configured model.
fn bias(kind: BiasModelKind, sigma: f64, tau_s: f64, k: f64) -> BiasProcess {
    match kind {
        BiasModelKind::Constant => BiasProcess::Constant { sigma },
        BiasModelKind::RandomWalk => BiasProcess::RandomWalk { k_per_sqrt_s: k },
        BiasModelKind::GaussMarkov => BiasProcess::GaussMarkov {
            sigma,
            correlation_time_s: tau_s,
        },
    }
}

fn imu_model(c: &ImuConfig, vehicle: Option<&VehicleConfig>) -> ImuModel {
    ImuModel {
        mounting: vehicle.map(|v| Mounting {
            nominal: rotation_of(v.mounting_rpy_deg),
            sigma_rad: v.mounting_sigma_deg.to_radians(),
        }),
        gyro_arw_rad_per_sqrt_s: c.gyro_arw_rad_per_sqrt_s,
        accel_vrw_m_s_per_sqrt_s: c.accel_vrw_m_s_per_sqrt_s,
        gyro_bias: bias(
            c.gyro_bias_model,
            c.gyro_bias_sigma_rad_s,
            c.gyro_bias_correlation_time_s,
            c.gyro_bias_random_walk_rad_s_per_sqrt_s,
        ),
        accel_bias: bias(
            c.accel_bias_model,
            c.accel_bias_sigma_m_s2,
            c.accel_bias_correlation_time_s,
            c.accel_bias_random_walk_m_s2_per_sqrt_s,
        ),
        gyro_scale_sigma: c.gyro_scale_factor_sigma_ppm * 1e-6,
        accel_scale_sigma: c.accel_scale_factor_sigma_ppm * 1e-6,
    }
}

fn gnss_model(c: &GnssConfig) -> GnssModel {
    GnssModel {
        lever_arm_b_m: Vector3::from(c.gnss_lever_arm_m),
        position_sigma_m: Vector3::from(c.gnss_position_sigma_m),
        velocity_sigma_m_s: Vector3::repeat(c.gnss_velocity_sigma_m_s),
    }
}

impl Scenario {
    /// The scenario of a configuration, validated.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first field out of its range.
    pub fn from_config(c: &InsConfig) -> Result<Self, ConfigError> {
        c.validate()?;
        let assumed = c.assumed();
        let i = &c.initial;
        let (p, v) = (i.position_sigma_m, i.velocity_sigma_m_s);
        let (tilt, yaw) = (i.tilt_sigma_deg.to_radians(), i.yaw_sigma_deg.to_radians());
        Ok(Scenario {
            duration_s: c.drive.duration_s,
            start: Geodetic {
                lat_rad: c.drive.start_lat_deg.to_radians(),
                lon_rad: c.drive.start_lon_deg.to_radians(),
                height_m: c.drive.start_height_m,
            },
            imu_rate_hz: c.imu.imu_rate_hz,
            imu_steps_per_fix: (c.imu.imu_rate_hz / c.gnss.gnss_rate_hz).round() as usize,
            truth_imu: imu_model(&c.imu, c.vehicle().as_ref()),
            truth_gnss: gnss_model(&c.gnss),
            filter_imu: imu_model(&assumed.imu, None),
            filter_gnss: gnss_model(&assumed.gnss),
            initial_sigma: [p, p, p, v, v, v, tilt, tilt, yaw],
            seed: c.ensemble.seed,
            realizations: c.ensemble.realizations,
            false_alarm_rate: c.checks.false_alarm_rate,
            residual_max_lag: c.checks.residual_max_lag.map(|l| l as usize),
            filter_earth_rotation_rad_s: super::earth::ROTATION_RATE_RAD_S,
            error_states: c.error_states(),
            vehicle: c.vehicle().zip(c.assumed_vehicle()).map(|(v, f)| Vehicle {
                filter_mounting: rotation_of(f.mounting_rpy_deg),
                mounting_sigma_rad: f.mounting_sigma_deg.to_radians(),
                nhc_sigma_m_s: v.nhc_sigma_m_s,
                filter_nhc_sigma_m_s: f.nhc_sigma_m_s,
                nhc_rate_hz: v.nhc_rate_hz,
                nhc_min_speed_m_s: v.nhc_min_speed_m_s,
            }),
        })
    }

    /// The drive (the default drive; [`Self::duration_s`] says how much of it).
    pub fn drive(&self) -> Drive {
        Drive::default_drive()
    }

    /// The true IMU of realization `index`.
    pub fn imu(&self, index: u64) -> Imu {
        Imu::new(self.truth_imu, self.seed, index)
    }

    /// The IMU's mounting in the vehicle the filter assumes, q_b^v (identity without one).
    pub fn filter_mounting(&self) -> UnitQuaternion<f64> {
        self.vehicle
            .map_or_else(UnitQuaternion::identity, |v| v.filter_mounting)
    }

    /// The aids beside GNSS: a car's constraint.
    pub fn aids(&self) -> super::extra::Aids {
        super::extra::Aids {
            nhc: self.vehicle.map(|v| super::nhc::Nhc {
                sigma_m_s: v.filter_nhc_sigma_m_s,
                true_sigma_m_s: v.nhc_sigma_m_s,
                rate_hz: v.nhc_rate_hz,
                min_speed_m_s: v.nhc_min_speed_m_s,
            }),
        }
    }

    /// The noise densities the filter assumes.
    pub fn filter_noise(&self) -> NoiseDensities {
        let m = &self.filter_imu;
        NoiseDensities {
            accel_vrw_m_s_per_sqrt_s: m.accel_vrw_m_s_per_sqrt_s,
            gyro_arw_rad_per_sqrt_s: m.gyro_arw_rad_per_sqrt_s,
            gyro_bias_density: m.gyro_bias.density(),
            accel_bias_density: m.accel_bias.density(),
        }
    }

    /// The bias decay the filter assumes.
    pub fn filter_decay(&self) -> BiasDecay {
        BiasDecay {
            gyro_per_s: self.filter_imu.gyro_bias.decay_per_s(),
            accel_per_s: self.filter_imu.accel_bias.decay_per_s(),
        }
    }

    /// The filter's prior covariance P(0): the navigation σ's and each bias's initial σ.
    pub fn prior(&self) -> Matrix15 {
        self.prior_of::<{ super::error_state::STATES }>()
    }

    /// P(0) over an error state of `N`: with the scale factors, each one's σ besides.
    pub fn prior_of<const N: usize>(&self) -> Square<N> {
        let mut p = Square::<N>::zeros();
        for (i, s) in self.initial_sigma.iter().enumerate() {
            p[(i, i)] = s * s;
        }
        let (g, a) = (
            self.filter_imu.gyro_bias.initial_sigma(),
            self.filter_imu.accel_bias.initial_sigma(),
        );
        for i in 0..3 {
            p[(GYRO_BIAS + i, GYRO_BIAS + i)] = g * g;
            p[(ACCEL_BIAS + i, ACCEL_BIAS + i)] = a * a;
        }
        if holds::<N>(Block::GyroScale) {
            let (g, a) = (
                self.filter_imu.gyro_scale_sigma,
                self.filter_imu.accel_scale_sigma,
            );
            for i in 0..3 {
                p[(
                    start_of::<N>(Block::GyroScale) + i,
                    start_of::<N>(Block::GyroScale) + i,
                )] = g * g;
                p[(
                    start_of::<N>(Block::AccelScale) + i,
                    start_of::<N>(Block::AccelScale) + i,
                )] = a * a;
            }
        }
        if holds::<N>(Block::Mounting) {
            let m = self.vehicle.map_or(0.0, |v| v.mounting_sigma_rad);
            for i in 0..3 {
                let k = start_of::<N>(Block::Mounting) + i;
                p[(k, k)] = m * m;
            }
        }
        p
    }
}
