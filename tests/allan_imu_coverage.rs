//! The gyro's intervals cover: over 100 synthetic static gyro logs of 10⁶ samples at 200 Hz
//! (angle random walk N = 0.3 °/√h = 8.73·10⁻⁵ rad/√s, rate random walk K = N·√(3/100 s), so that
//! the two cross at τ = 100 s, about 3.1 °/h/√h, on a 0.01 rad/s bias) the 95 % intervals of ARW
//! and RRW contain the truth a number of times inside the binomial band at a 1 % false-alarm
//! rate, Bin(100, 0.95) → [89, 100]. `allan --imu` analyses a gyro's column with the same
//! function as an accelerometer's (tests/allan_imu.rs: bit for bit), so this is the
//! accelerometer's coverage study (`allan::section::coverage`) at a gyro's scale and rate, where
//! the fit's τ₀, the crossover and the magnitudes differ.
//!
//! Both sides: the mean squared error of N̂² and K̂² over the mean variance the fit claims lies in
//! the band of χ²(100)/100 at 1 % ([0.673, 1.402]). The negative control: the fit's nominal
//! standard errors (the estimates taken as independent across τ) fail it.

use accelcal::allan::section::{binomial_band, coverage};
use accelcal::allan::simulate::StaticLog;
use accelcal::stats::chi_squared_band;

const SEEDS: u64 = 100;

/// 0.3 °/√h in rad/√s.
const ARW_RAD_PER_SQRT_S: f64 = 0.3 * std::f64::consts::PI / 180.0 / 60.0;

const GYRO: StaticLog = StaticLog {
    sample_period_s: 0.005,
    velocity_random_walk_m_s_per_sqrt_s: ARW_RAD_PER_SQRT_S,
    // K = N·√(3/τ_c) with τ_c = 100 s: K²τ/3 = N²/τ at τ_c.
    acceleration_random_walk_m_s2_per_sqrt_s: ARW_RAD_PER_SQRT_S * 0.173_205_080_756_887_72,
    offset_m_s2: 0.01,
};

#[test]
fn gyro_intervals_of_arw_and_rrw_cover_and_nominal_errors_do_not() {
    assert!((ARW_RAD_PER_SQRT_S - 8.726_646_259_971_648e-5).abs() < 1e-18);
    let c = coverage(&GYRO, SEEDS, 1_000_000, 0.95, 0.01).unwrap();
    eprintln!("{c:?}");
    assert_eq!(c.band, binomial_band(100, 0.95, 0.01));
    assert_eq!(c.band, (89, 100));
    let inside = |k: u64| (c.band.0..=c.band.1).contains(&k);
    assert_eq!(
        c.k_unresolved, 0,
        "RRW unresolved in {} logs",
        c.k_unresolved
    );
    assert!(inside(c.n_covered), "ARW covered {} of 100", c.n_covered);
    assert!(inside(c.k_covered), "RRW covered {} of 100", c.k_covered);
    let (lo, hi) = chi_squared_band(SEEDS as f64, SEEDS as f64, 0.01);
    let ratio_inside = |r: f64| (lo..=hi).contains(&r);
    assert!(
        ratio_inside(c.n_scatter_ratio),
        "ARW²: {}",
        c.n_scatter_ratio
    );
    assert!(
        ratio_inside(c.k_scatter_ratio),
        "RRW²: {}",
        c.k_scatter_ratio
    );
    // The negative control: the nominal errors, which ignore the correlation across τ.
    assert!(
        !ratio_inside(c.k_nominal_scatter_ratio) || !ratio_inside(c.n_nominal_scatter_ratio),
        "nominal scatter ratios inside the band: ARW² {} RRW² {}",
        c.n_nominal_scatter_ratio,
        c.k_nominal_scatter_ratio
    );
    assert!(
        !inside(c.n_nominal_covered) || !inside(c.k_nominal_covered),
        "the negative control passed: nominal ARW {} RRW {} of 100",
        c.n_nominal_covered,
        c.k_nominal_covered
    );
}
