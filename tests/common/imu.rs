//! Shared helpers of the three-axis calibration's tests: the assumptions that match a simulated
//! scenario, and the binomial band of a coverage count.

use accelcal::calibrate::imu::{CONSUMER, Settings};
use accelcal::ins::setup::Scenario;
use statrs::distribution::{Binomial, DiscreteCDF};

/// The assumptions that match the simulated sensors: the scenario's own statistics.
pub fn settings_of(scenario: &Scenario) -> Settings {
    let imu = &scenario.filter_imu;
    let gnss = &scenario.filter_gnss;
    let tau = |b: accelcal::ins::sensors::BiasProcess| {
        let d = b.decay_per_s();
        (d > 0.0).then(|| 1.0 / d)
    };
    Settings {
        gyro_arw_rad_per_sqrt_s: imu.gyro_arw_rad_per_sqrt_s,
        accel_vrw_m_s_per_sqrt_s: imu.accel_vrw_m_s_per_sqrt_s,
        gyro_bias_sigma_rad_s: imu.gyro_bias.initial_sigma(),
        gyro_bias_random_walk_rad_s_per_sqrt_s: 0.0,
        gyro_bias_correlation_time_s: tau(imu.gyro_bias),
        accel_bias_sigma_m_s2: imu.accel_bias.initial_sigma(),
        accel_bias_random_walk_m_s2_per_sqrt_s: 0.0,
        accel_bias_correlation_time_s: tau(imu.accel_bias),
        gnss_position_sigma_m: gnss.position_sigma_m.into(),
        gnss_velocity_sigma_m_s: gnss.velocity_sigma_m_s.x,
        gnss_lever_arm_m: gnss.lever_arm_b_m.into(),
        ..CONSUMER
    }
}

/// The counts of n trials with success probability `p` outside which a two-sided test at
/// false-alarm rate `alpha` rejects: (lowest accepted, highest accepted).
pub fn band(n: u64, p: f64, alpha: f64) -> (u64, u64) {
    let b = Binomial::new(p, n).expect("valid");
    let lo = (0..=n).find(|&k| b.cdf(k) > alpha / 2.0).expect("some k");
    let hi = (0..=n)
        .find(|&k| b.cdf(k) >= 1.0 - alpha / 2.0)
        .expect("some k");
    (lo, hi)
}
