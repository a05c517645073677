//! The filter over simulated realizations of the default drive: its errors against its own
//! covariance.

use nalgebra::{SVector, Vector3};
use rayon::prelude::*;

use crate::ins::discrete::NoiseDensities;
use crate::ins::drive::Drive;
use crate::ins::earth::Geodetic;
use crate::ins::error_state::{
    ACCEL_BIAS, ATTITUDE, BiasDecay, GYRO_BIAS, Matrix15, POSITION, STATES, VELOCITY,
};
use crate::ins::filter::Ekf;
use crate::ins::gnss::{self, Fix};
use crate::ins::mech::Pva;
use crate::ins::sensors::{BiasProcess, Imu, ImuModel, offset};
use crate::ins::truth::{self, Truth};
use crate::stats::{Tail, chi_squared_quantile};

/// An ADIS16465-class IMU: ARW 0.1°/√h, VRW 0.1 m/s/√h (the datasheet's 0.15°/√h and
/// 0.012 m/s/√h rounded to a conservative class), gyro bias 50°/h and accelerometer bias
/// 0.25 mg as Gauss–Markov with τ = 1 h.
pub(super) fn adis_class() -> ImuModel {
    ImuModel {
        gyro_arw_rad_per_sqrt_s: 0.1_f64.to_radians() / 60.0,
        accel_vrw_m_s_per_sqrt_s: 0.1 / 60.0,
        gyro_bias: BiasProcess::GaussMarkov {
            sigma: (50.0_f64 / 3600.0).to_radians(),
            correlation_time_s: 3600.0,
        },
        accel_bias: BiasProcess::GaussMarkov {
            sigma: 0.25e-3 * 9.80665,
            correlation_time_s: 3600.0,
        },
    }
}

/// The start of every realization.
fn start() -> Geodetic {
    Geodetic {
        lat_rad: 37.4_f64.to_radians(),
        lon_rad: -122.1_f64.to_radians(),
        height_m: 30.0,
    }
}

/// The error of `ekf` against the truth `pva` and true biases, in the error state's coordinates.
fn error(ekf: &Ekf, pva: &Pva, bg: &Vector3<f64>, ba: &Vector3<f64>) -> SVector<f64, STATES> {
    let mut e = SVector::<f64, STATES>::zeros();
    e.fixed_rows_mut::<3>(POSITION)
        .copy_from(&gnss::ned_difference_m(&ekf.pva.position, &pva.position));
    e.fixed_rows_mut::<3>(VELOCITY)
        .copy_from(&(ekf.pva.velocity_ned_m_s - pva.velocity_ned_m_s));
    e.fixed_rows_mut::<3>(ATTITUDE)
        .copy_from(&(ekf.pva.attitude * pva.attitude.inverse()).scaled_axis());
    e.fixed_rows_mut::<3>(GYRO_BIAS)
        .copy_from(&(ekf.gyro_bias_rad_s - bg));
    e.fixed_rows_mut::<3>(ACCEL_BIAS)
        .copy_from(&(ekf.accel_bias_m_s2 - ba));
    e
}

/// One realization at 200 Hz with 1 Hz GNSS: the error at the end, P there, and the NIS sum
/// with its degrees of freedom.
pub(super) fn realization(
    seed: u64,
    model: &ImuModel,
    lever_b_m: Vector3<f64>,
) -> (SVector<f64, STATES>, Matrix15, f64, usize) {
    let rate_hz = 200.0;
    let drive = Drive::default_drive();
    let truth = Truth::new(&drive, start(), 1.0 / rate_hz);
    let pva0 = truth.pva();
    let mut imu = Imu::new(*model, seed);
    let sigma0 = [
        1.0,
        1.0,
        1.0,
        0.1,
        0.1,
        0.1,
        0.5_f64.to_radians(),
        0.5_f64.to_radians(),
        2.0_f64.to_radians(),
    ];
    let dx0 = imu.normals(&Vector3::new(sigma0[0], sigma0[1], sigma0[2]));
    let dv0 = imu.normals(&Vector3::new(sigma0[3], sigma0[4], sigma0[5]));
    let dpsi0 = imu.normals(&Vector3::new(sigma0[6], sigma0[7], sigma0[8]));
    let start_pva = Pva {
        position: offset(&pva0.position, &dx0),
        velocity_ned_m_s: pva0.velocity_ned_m_s + dv0,
        attitude: nalgebra::UnitQuaternion::from_scaled_axis(dpsi0) * pva0.attitude,
    };
    let mut p0 = Matrix15::zeros();
    for (i, s) in sigma0.iter().enumerate() {
        p0[(i, i)] = s * s;
    }
    for i in 0..3 {
        p0[(GYRO_BIAS + i, GYRO_BIAS + i)] = model.gyro_bias.initial_sigma().powi(2);
        p0[(ACCEL_BIAS + i, ACCEL_BIAS + i)] = model.accel_bias.initial_sigma().powi(2);
    }
    let noise = NoiseDensities {
        accel_vrw_m_s_per_sqrt_s: model.accel_vrw_m_s_per_sqrt_s,
        gyro_arw_rad_per_sqrt_s: model.gyro_arw_rad_per_sqrt_s,
        gyro_bias_density: model.gyro_bias.density(),
        accel_bias_density: model.accel_bias.density(),
    };
    let decay = BiasDecay {
        gyro_per_s: model.gyro_bias.decay_per_s(),
        accel_per_s: model.accel_bias.decay_per_s(),
    };
    let mut ekf = Ekf::new(start_pva, p0, noise, decay, lever_b_m);
    let (pos_sigma, vel_sigma) = (Vector3::new(1.0, 1.0, 2.0), Vector3::repeat(0.05));
    let per_fix = rate_hz as usize;
    let (mut nis, mut dof) = (0.0, 0);
    let mut last = pva0;
    for (k, (inc, pva)) in truth.enumerate() {
        let raw = imu.read(&inc);
        ekf.propagate(&raw);
        last = pva;
        if (k + 1) % per_fix == 0 {
            let t = (k + 1) as f64 / rate_hz;
            let (omega, _) = truth::imu_rates(&pva.position, &drive.motion(t));
            let (p, v) = gnss::antenna(&pva, &lever_b_m, &omega);
            let fix = Fix {
                t_s: t,
                position: offset(&p, &imu.normals(&pos_sigma)),
                velocity_ned_m_s: Some(v + imu.normals(&vel_sigma)),
                position_sigma_m: pos_sigma,
                velocity_sigma_m_s: vel_sigma,
            };
            let innovation = ekf.update(&fix).expect("S positive definite");
            nis += innovation.nis;
            dof += innovation.residual.len();
        }
    }
    let e = error(&ekf, &last, &imu.gyro_bias_rad_s, &imu.accel_bias_m_s2);
    (e, ekf.covariance, nis, dof)
}

/// The sums of NEES at the end (χ²(15N)) and of NIS over every fix (χ² of the fixes' rows)
/// inside their two-sided 1 % bands: a first check of the filter, before the ensemble's.
#[test]
fn the_filter_is_consistent_over_realizations_of_the_default_drive() {
    let n = 8;
    let runs: Vec<_> = (0..n as u64)
        .into_par_iter()
        .map(|seed| realization(seed, &adis_class(), Vector3::new(0.4, -0.2, -0.9)))
        .collect();
    let mut nees = 0.0;
    let (mut nis, mut nis_dof) = (0.0, 0);
    for (e, p, s, d) in &runs {
        let chol = p.cholesky().expect("P positive definite");
        let z = chol.solve(e);
        nees += e.dot(&z);
        nis += s;
        nis_dof += d;
    }
    let dof = (STATES * n) as f64;
    let (lo, hi) = (
        chi_squared_quantile(dof, 0.005, Tail::Lower),
        chi_squared_quantile(dof, 0.005, Tail::Upper),
    );
    let (nlo, nhi) = (
        chi_squared_quantile(nis_dof as f64, 0.005, Tail::Lower),
        chi_squared_quantile(nis_dof as f64, 0.005, Tail::Upper),
    );
    // Measured: NEES 115.6 in [83.9, 163.6], NIS 27 671 in [26 761, 27 966]; the gyro biases'
    // σ at the end 5.2, 5.2 and 12.7 °/h from a 50 °/h prior.
    assert!(nees > lo && nees < hi, "NEES {nees} outside [{lo}, {hi}]");
    assert!(nis > nlo && nis < nhi, "NIS {nis} outside [{nlo}, {nhi}]");
}
