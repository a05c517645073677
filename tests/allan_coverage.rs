//! The fit's intervals cover: over 100 synthetic static logs of 10⁶ samples at 100 Hz (white
//! noise N = 2·10⁻³ m/s/√s plus a random walk of the bias K = 10⁻⁴ m/s²/√s on a 1 g offset),
//! the 95 % intervals of N and K contain the truth a number of times inside the binomial band at
//! a 1 % false-alarm rate, Bin(100, 0.95) → [89, 100] (at n = 100 the upper end is 100: an
//! interval too wide cannot fail this test, only one too narrow). The negative control: the
//! weighted fit's nominal standard errors, taken at face value with the same interval
//! construction, cover below the band.
//!
//! Both sides: the mean squared error of N̂² and K̂² over the mean variance the fit claims must lie
//! in the band of χ²(100)/100 at 1 % ([0.673, 1.402]), which an interval too wide fails as well
//! as one too narrow; the nominal variance of K̂² falls outside it.

use accelcal::allan::section::{binomial_band, coverage};
use accelcal::allan::simulate::StaticLog;
use accelcal::stats::chi_squared_band;

const SEEDS: u64 = 100;

const LOG: StaticLog = StaticLog {
    sample_period_s: 0.01,
    velocity_random_walk_m_s_per_sqrt_s: 2e-3,
    acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
    offset_m_s2: 9.80665,
};

#[test]
fn the_report_simulates_this_log() {
    assert_eq!(accelcal::allan::section::REPORT_LOG, LOG);
}

#[test]
fn the_band_is_the_binomial_one() {
    // Bin(100, 0.95): P(X ≤ 88) = 0.0043 ≤ 0.005 < P(X ≤ 89) = 0.0115; P(X = 100) = 0.0059.
    assert_eq!(binomial_band(100, 0.95, 0.01), (89, 100));
    // Bin(1000, 0.5) (scipy.stats.binom): P(X ≤ 458) = 0.00432, P(X ≤ 459) = 0.00519, and
    // symmetrically P(X ≥ 542) = 0.00432.
    assert_eq!(binomial_band(1000, 0.5, 0.01), (459, 541));
}

#[test]
fn intervals_of_n_and_k_cover_and_nominal_errors_do_not() {
    let c = coverage(&LOG, SEEDS, 1_000_000, 0.95, 0.01).unwrap();
    eprintln!("{c:?}");
    let inside = |k: u64| (c.band.0..=c.band.1).contains(&k);
    assert_eq!(c.band, (89, 100));
    assert_eq!(c.k_unresolved, 0, "K unresolved in {} logs", c.k_unresolved);
    assert!(inside(c.n_covered), "N covered {} of 100", c.n_covered);
    assert!(inside(c.k_covered), "K covered {} of 100", c.k_covered);
    let (lo, hi) = chi_squared_band(SEEDS as f64, SEEDS as f64, 0.01);
    assert!(
        (0.672..0.674).contains(&lo) && (1.401..1.403).contains(&hi),
        "{lo} {hi}"
    );
    let ratio_inside = |r: f64| (lo..=hi).contains(&r);
    assert!(ratio_inside(c.n_scatter_ratio), "N²: {}", c.n_scatter_ratio);
    assert!(ratio_inside(c.k_scatter_ratio), "K²: {}", c.k_scatter_ratio);
    assert!(
        !ratio_inside(c.k_nominal_scatter_ratio),
        "nominal K²: {}",
        c.k_nominal_scatter_ratio
    );
    assert!(
        !inside(c.n_nominal_covered) || !inside(c.k_nominal_covered),
        "the negative control passed: nominal N {} K {} of 100",
        c.n_nominal_covered,
        c.k_nominal_covered
    );
}
