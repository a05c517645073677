//! The covariance propagated once per interval against the per-step dense reference.

use crate::config::ins::InsConfig;
use crate::ins::ensemble::Track;
use crate::ins::error_state::Matrix15;
use crate::ins::filter::{DEFAULT_COVARIANCE_INTERVAL_S, Ekf, Propagation};
use crate::ins::setup::Scenario;
use crate::ins::simulated_logs::fix;

/// P before each update of realization `index`, its covariance propagated as `propagation` says.
fn covariances(
    scenario: &Scenario,
    track: &Track,
    index: u64,
    propagation: Propagation,
) -> Vec<Matrix15> {
    let drive = scenario.drive();
    let (mut imu, ekf) = crate::ins::ensemble::start::<15>(scenario, track, index);
    let mut ekf = ekf.with_propagation(propagation);
    let g = &scenario.filter_gnss;
    let dt = 1.0 / scenario.imu_rate_hz;
    let mut out = Vec::new();
    for (k, (inc, pva)) in track.steps.iter().enumerate() {
        ekf.propagate(&imu.read(inc));
        if (k + 1) % scenario.imu_steps_per_fix != 0 {
            continue;
        }
        let mut reading = fix(scenario, &drive, &mut imu, (k + 1) as f64 * dt, pva);
        reading.position_sigma_m = g.position_sigma_m;
        reading.velocity_sigma_m_s = g.velocity_sigma_m_s;
        out.push(ekf.covariance);
        ekf.update(&reading).unwrap();
    }
    out
}

/// ‖L⁻¹(P − P_ref)L⁻ᵀ‖_F with P_ref = LLᵀ: P's difference in the reference's own metric, the
/// one NEES reads (every state weighed alike, whatever its unit).
fn whitened_difference(p: &Matrix15, p_ref: &Matrix15) -> f64 {
    let l = p_ref.cholesky().unwrap().l();
    let a = l.solve_lower_triangular(&(p - p_ref)).unwrap();
    l.solve_lower_triangular(&a.transpose()).unwrap().norm()
}

/// The largest whitened difference over the fixes of realization 0 of the default drive.
fn worst(scenario: &Scenario, track: &Track, reference: &[Matrix15], interval_s: f64) -> f64 {
    let fast = covariances(scenario, track, 0, Propagation::Interval { interval_s });
    assert_eq!(fast.len(), reference.len());
    fast.iter()
        .zip(reference)
        .map(|(p, r)| whitened_difference(p, r))
        .fold(0.0, f64::max)
}

/// The bound: with P = P_ref^½(I + E)P_ref^½ᵀ, a realization's expected NEES moves by −tr E,
/// at most √15·‖E‖_F, so N realizations' sum by N√15‖E‖_F against its σ = √(30N). Keeping that
/// below a tenth of σ at N = 1 000 asks ‖E‖_F ≤ 0.1·√2/√N = 4.5·10⁻³: the checks then see the
/// faster filter as they see the reference.
const BOUND: f64 = 0.1 * std::f64::consts::SQRT_2 / 31.622_776_601_683_793;

#[test]
fn p_at_every_fix_stays_within_the_bound_of_the_per_step_reference() {
    let scenario = Scenario::from_config(&InsConfig::default()).unwrap();
    let track = Track::of(&scenario);
    let reference = covariances(&scenario, &track, 0, Propagation::Dense);
    assert_eq!(reference.len(), 600);
    // Measured: 3.5·10⁻⁴ at 0.1 s, 1.4·10⁻³ at 0.2 s, growing as T² (F's mean drops the
    // Magnus series' commutator term, −(T³/12)[F, Ḟ] per interval, T⁻¹ intervals per fix).
    let default = worst(&scenario, &track, &reference, DEFAULT_COVARIANCE_INTERVAL_S);
    assert!(default <= BOUND, "{default:e} beyond {BOUND:e}");
    // Negative control: one propagation per fix (1 s, measured 3.3·10⁻²) exceeds it.
    let per_fix = worst(&scenario, &track, &reference, 1.0);
    assert!(
        per_fix > BOUND,
        "the bound missed a 1 s interval: {per_fix:e}"
    );
}

/// At every fix of `duration_s` of the drive with fixes at `gnss_rate_hz`: whether P before the
/// update was current (flushing it changes nothing), and whether P `offset` steps after each fix
/// was.
fn current_at_fixes(gnss_rate_hz: f64, offset: usize) -> (bool, bool) {
    let mut c = InsConfig::default();
    c.drive.duration_s = 20.0;
    c.gnss.gnss_rate_hz = gnss_rate_hz;
    let scenario = Scenario::from_config(&c).unwrap();
    let track = Track::of(&scenario);
    let drive = scenario.drive();
    let mut imu = scenario.imu(0);
    let g = &scenario.filter_gnss;
    let mut ekf = Ekf::new(
        track.start,
        scenario.prior(),
        scenario.filter_noise(),
        scenario.filter_decay(),
        g.lever_arm_b_m,
    );
    let (mut at_fix, mut after) = (true, true);
    let current = |ekf: &Ekf| {
        let mut flushed = ekf.clone();
        flushed.flush();
        flushed.covariance == ekf.covariance
    };
    let per_fix = scenario.imu_steps_per_fix;
    for (k, (inc, pva)) in track.steps.iter().enumerate() {
        ekf.propagate(&imu.read(inc));
        if (k + 1) % per_fix == offset && k + 1 > per_fix {
            after &= current(&ekf);
        }
        if (k + 1) % per_fix != 0 {
            continue;
        }
        at_fix &= current(&ekf);
        let t = (k + 1) as f64 / scenario.imu_rate_hz;
        ekf.update(&fix(&scenario, &drive, &mut imu, t, pva))
            .unwrap();
    }
    (at_fix, after)
}

#[test]
fn p_is_current_at_every_fix_whatever_the_gnss_rate() {
    // 200, 100, 25 and 8 IMU steps between fixes: intervals of 40, 25, 25 and 8 steps.
    for rate in [1.0, 2.0, 8.0, 25.0] {
        assert!(current_at_fixes(rate, 0).0, "P stale at a {rate} Hz fix");
    }
    // Negative control: 7 steps after a 1 Hz fix an interval is pending, and flushing it
    // changes P.
    assert!(
        !current_at_fixes(1.0, 7).1,
        "the comparison missed a pending interval"
    );
}
