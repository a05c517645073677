//! A simulated realization's logs read back: the IMU's and the receiver's noise as configured,
//! over the true increments and the true antenna.

use nalgebra::Vector3;

use crate::config::ins::InsConfig;
use crate::ins::drive::Drive;
use crate::ins::gnss;
use crate::ins::setup::Scenario;
use crate::ins::simulated_logs::{GNSS_HEADER, IMU_HEADER, TRUTH_HEADER, write_realization};
use crate::ins::truth::{self, Truth};
use crate::stats::{Tail, chi_squared_quantile};

fn rows(text: &[u8]) -> (String, Vec<Vec<f64>>) {
    let text = String::from_utf8(text.to_vec()).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// Two-sided 1 % band of χ²(dof).
fn band(dof: usize) -> (f64, f64) {
    let d = dof as f64;
    (
        chi_squared_quantile(d, 0.005, Tail::Lower),
        chi_squared_quantile(d, 0.005, Tail::Upper),
    )
}

#[test]
fn the_logs_carry_the_configured_noise_over_the_truth() {
    let mut config = InsConfig::default();
    config.drive.duration_s = 120.0;
    let scenario = Scenario::from_config(&config).unwrap();
    let (mut imu, mut gnss_log, mut truth_log) = (Vec::new(), Vec::new(), Vec::new());
    let written = write_realization(&scenario, 3, &mut imu, &mut gnss_log, &mut truth_log).unwrap();
    let (imu_header, imu_rows) = rows(&imu);
    let (gnss_header, gnss_rows) = rows(&gnss_log);
    let (truth_header, truth_rows) = rows(&truth_log);
    assert_eq!(
        (
            imu_header.as_str(),
            gnss_header.as_str(),
            truth_header.as_str()
        ),
        (IMU_HEADER, GNSS_HEADER, TRUTH_HEADER)
    );
    assert_eq!((written.samples, written.fixes), (24_000, 120));
    assert_eq!((imu_rows.len(), gnss_rows.len()), (24_000, 120));

    // IMU: (logged rate − true rate − true bias)·√Δt / ARW (or VRW) is standard normal.
    let drive = Drive::default_drive();
    let dt = 1.0 / scenario.imu_rate_hz;
    let truth = Truth::new(&drive, scenario.start, dt).until(scenario.duration_s);
    let m = &scenario.truth_imu;
    let (mut gyro, mut accel) = (0.0, 0.0);
    let mut states = Vec::new();
    for (k, (inc, pva)) in truth.enumerate() {
        let (r, t) = (&imu_rows[k], &truth_rows[k]);
        for i in 0..3 {
            let a = (r[1 + i] - inc.dvel_m_s[i] / dt - t[13 + i]) * dt.sqrt();
            let g = (r[4 + i] - inc.dtheta_rad[i] / dt - t[10 + i]) * dt.sqrt();
            accel += (a / m.accel_vrw_m_s_per_sqrt_s).powi(2);
            gyro += (g / m.gyro_arw_rad_per_sqrt_s).powi(2);
        }
        states.push(pva);
    }
    let (lo, hi) = band(3 * 24_000);
    assert!(
        lo < accel && accel < hi,
        "accelerometer noise χ² {accel} outside [{lo}, {hi}]"
    );
    assert!(
        lo < gyro && gyro < hi,
        "gyro noise χ² {gyro} outside [{lo}, {hi}]"
    );

    // GNSS: the fix minus the true antenna, in units of its σ.
    let g = &scenario.truth_gnss;
    let mut chi2 = 0.0;
    for row in &gnss_rows {
        let k = (row[0] * scenario.imu_rate_hz).round() as usize - 1;
        let (omega, _) = truth::imu_rates(&states[k].position, &drive.motion(row[0]));
        let (p, v) = gnss::antenna(&states[k], &g.lever_arm_b_m, &omega);
        let fix = crate::ins::earth::Geodetic {
            lat_rad: row[1].to_radians(),
            lon_rad: row[2].to_radians(),
            height_m: row[3],
        };
        let dp = gnss::ned_difference_m(&fix, &p).component_div(&g.position_sigma_m);
        let dv = (Vector3::new(row[4], row[5], row[6]) - v).component_div(&g.velocity_sigma_m_s);
        chi2 += dp.norm_squared() + dv.norm_squared();
    }
    let (lo, hi) = band(6 * 120);
    assert!(
        lo < chi2 && chi2 < hi,
        "GNSS noise χ² {chi2} outside [{lo}, {hi}]"
    );
}
