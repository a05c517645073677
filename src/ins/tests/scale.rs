//! The 21-state form's scale-factor columns: F's and H's against finite differences of the
//! compensated sensors they linearize, the block-sparse products over 21 states against the
//! dense ones, and the 15 states of the 21-state F equal to the 15-state F.

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::ins::discrete;
use crate::ins::earth::{self, Geodetic};
use crate::ins::error_state::{
    self, ATTITUDE, BiasDecay, Motion, STATES, STATES_WITH_SCALE, Square, VELOCITY,
};
use crate::ins::gnss;
use crate::ins::mech::{Pva, skew};
use crate::ins::state::Block;

/// Where the scale factors start in the 21-state layout.
const GYRO_SCALE: usize = error_state::start_of::<STATES_WITH_SCALE>(Block::GyroScale);
const ACCEL_SCALE: usize = error_state::start_of::<STATES_WITH_SCALE>(Block::AccelScale);
type Matrix21 = Square<STATES_WITH_SCALE>;

/// A moving, turning, climbing vehicle: its solution, the true specific force and rate, the
/// sensors' scale factors and biases.
struct Scene {
    pva: Pva,
    f: Vector3<f64>,
    w: Vector3<f64>,
    scale_a: Vector3<f64>,
    scale_g: Vector3<f64>,
    bias_a: Vector3<f64>,
    bias_g: Vector3<f64>,
}

fn scene() -> Scene {
    Scene {
        pva: Pva {
            position: Geodetic {
                lat_rad: 37.4_f64.to_radians(),
                lon_rad: -122.1_f64.to_radians(),
                height_m: 480.0,
            },
            velocity_ned_m_s: Vector3::new(15.0, -8.0, 0.7),
            attitude: crate::ins::attitude_from_euler(0.09, -0.05, 2.1),
        },
        f: Vector3::new(1.2, -0.8, -9.7),
        w: Vector3::new(0.02, -0.05, 0.3),
        scale_a: Vector3::new(1e-3, -2e-3, 5e-4),
        scale_g: Vector3::new(-1e-3, 3e-3, 2e-3),
        bias_a: Vector3::new(0.02, -0.03, 0.01),
        bias_g: Vector3::new(2e-4, -1e-4, 3e-4),
    }
}

/// What a sensor with scale factor `s` and bias `b` reads of `x`, compensated by the estimates
/// `s_hat`, `b_hat`: ((1 + s)x + b − b̂)/(1 + ŝ) per axis (the filter's compensation).
fn compensated(
    x: &Vector3<f64>,
    s: &Vector3<f64>,
    b: &Vector3<f64>,
    s_hat: &Vector3<f64>,
    b_hat: &Vector3<f64>,
) -> Vector3<f64> {
    let read = x + x.component_mul(s) + b;
    (read - b_hat).component_div(&(Vector3::repeat(1.0) + s_hat))
}

fn c_of(pva: &Pva) -> Matrix3<f64> {
    *pva.attitude.to_rotation_matrix().matrix()
}

/// F's scale columns, by central differences of the navigation rates (Groves §5.4: v̇ = Cf̂ + …,
/// Ċ = C\[ω̂×\] − …) in each estimated scale factor, the biases exact.
fn numeric_scale_columns(s: &Scene) -> (Matrix3<f64>, Matrix3<f64>) {
    let c = c_of(&s.pva);
    let h = 1e-4;
    let (mut dv, mut dpsi) = (Matrix3::zeros(), Matrix3::zeros());
    for i in 0..3 {
        let mut e = Vector3::zeros();
        e[i] = h;
        let f_at = |d: &Vector3<f64>| {
            c * compensated(&s.f, &s.scale_a, &s.bias_a, &(s.scale_a + d), &s.bias_a)
        };
        dv.set_column(i, &((f_at(&e) - f_at(&-e)) / (2.0 * h)));
        // Ĉ = C at this instant; Ċ̂Cᵀ − ĊCᵀ = C[(ω̂ − ω)×]Cᵀ = [C(ω̂ − ω)×].
        let w_at = |d: &Vector3<f64>| {
            let w = compensated(&s.w, &s.scale_g, &s.bias_g, &(s.scale_g + d), &s.bias_g);
            let m = c * skew(&w) * c.transpose();
            Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
        };
        dpsi.set_column(i, &((w_at(&e) - w_at(&-e)) / (2.0 * h)));
    }
    (dv, dpsi)
}

fn analytic_f(s: &Scene) -> Matrix21 {
    let c = c_of(&s.pva);
    let decay = BiasDecay {
        gyro_per_s: 1.0 / 3600.0,
        accel_per_s: 1.0 / 1800.0,
    };
    error_state::dynamics_of::<STATES_WITH_SCALE>(
        &s.pva,
        &Motion::of(&c, &s.f, &s.w),
        &decay,
        earth::ROTATION_RATE_RAD_S,
    )
}

#[test]
fn f_s_scale_columns_are_the_jacobian_of_the_compensated_sensors() {
    let s = scene();
    let big_f = analytic_f(&s);
    let (dv, dpsi) = numeric_scale_columns(&s);
    let a = big_f.fixed_view::<3, 3>(VELOCITY, ACCEL_SCALE).into_owned();
    let g = big_f.fixed_view::<3, 3>(ATTITUDE, GYRO_SCALE).into_owned();
    // To first order in the scale factors (10⁻³ here): the difference is of their size.
    assert!((a - dv).norm() < 3e-3 * dv.norm(), "{a} vs {dv}");
    assert!((g - dpsi).norm() < 3e-3 * dpsi.norm(), "{g} vs {dpsi}");
    // Negative control: the transpose (diag(f)·C instead of C·diag(f)) is caught.
    let wrong = -Matrix3::from_diagonal(&s.f) * c_of(&s.pva);
    assert!((wrong - dv).norm() > 0.1 * dv.norm());
    // The first 15 states are the 15-state F's, and the scale factors' rows are zero.
    let c = c_of(&s.pva);
    let decay = BiasDecay {
        gyro_per_s: 1.0 / 3600.0,
        accel_per_s: 1.0 / 1800.0,
    };
    let f15 = error_state::dynamics_with(&s.pva, &c, &(c * s.f), &decay);
    assert_eq!(big_f.fixed_view::<STATES, STATES>(0, 0).into_owned(), f15);
    assert_eq!(big_f.fixed_rows::<6>(STATES).norm(), 0.0);
}

#[test]
fn h_s_gyro_scale_columns_are_the_jacobian_of_the_antenna_s_velocity() {
    let s = scene();
    let lever = Vector3::new(0.4, -0.2, -0.9);
    let h = gnss::observation_of::<STATES_WITH_SCALE>(&s.pva, &lever, &s.w);
    let step = 1e-4;
    let mut numeric = Matrix3::zeros();
    for i in 0..3 {
        let mut e = Vector3::zeros();
        e[i] = step;
        let v_at = |d: &Vector3<f64>| {
            let w = compensated(&s.w, &s.scale_g, &s.bias_g, &(s.scale_g + d), &s.bias_g);
            gnss::antenna(&s.pva, &lever, &w).1
        };
        numeric.set_column(i, &((v_at(&e) - v_at(&-e)) / (2.0 * step)));
    }
    let analytic = h.fixed_view::<3, 3>(3, GYRO_SCALE).into_owned();
    assert!(
        (analytic - numeric).norm() < 5e-3 * numeric.norm(),
        "{analytic} vs {numeric}"
    );
    // The position rows do not see the scale factors; the 15 columns are the 15-state H's.
    assert_eq!(h.fixed_view::<3, 6>(0, STATES).norm(), 0.0);
    let h15 = gnss::observation(&s.pva, &lever, &s.w);
    assert_eq!(h.fixed_columns::<STATES>(0).into_owned(), h15);
}

#[test]
fn the_block_sparse_products_over_21_states_equal_the_dense_ones() {
    let s = scene();
    let big_f = analytic_f(&s);
    let x = Matrix21::from_fn(|i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
    let p = x * x.transpose() + Matrix21::identity();
    let close = |a: &Matrix21, b: &Matrix21| (a - b).norm() <= 1e-13 * b.norm();
    assert!(close(&discrete::dynamics_times(&big_f, &x), &(big_f * x)));
    let phi = discrete::transition_third_order(&big_f, 0.2);
    let a = big_f * 0.2;
    let dense = Matrix21::identity() + a + a * a / 2.0 + a * a * a / 6.0;
    assert!(close(&phi, &dense));
    assert!(close(
        &discrete::transition_congruence(&phi, &p),
        &(phi * p * phi.transpose())
    ));
    // The series' process noise over 21 states leaves the undriven scale factors at zero.
    let noise = discrete::NoiseDensities {
        accel_vrw_m_s_per_sqrt_s: 1e-3,
        gyro_arw_rad_per_sqrt_s: 1e-4,
        gyro_bias_density: 1e-12,
        accel_bias_density: 1e-10,
    };
    let q: SMatrix<f64, 21, 21> = discrete::process_noise_series(&big_f, &noise, 0.2);
    assert_eq!(q.fixed_rows::<6>(STATES).norm(), 0.0);
    // Negative control: a block outside the pattern (scale factors that would move with the
    // attitude) is not multiplied.
    let mut outside = big_f;
    outside
        .fixed_view_mut::<3, 3>(GYRO_SCALE, ATTITUDE)
        .fill(1.0);
    assert!(!close(
        &discrete::dynamics_times(&outside, &x),
        &(outside * x)
    ));
}

#[test]
fn interval_phi_and_q_over_21_states_match_van_loan() {
    let s = scene();
    let big_f = analytic_f(&s);
    let noise = discrete::NoiseDensities {
        accel_vrw_m_s_per_sqrt_s: 0.1 / 60.0,
        gyro_arw_rad_per_sqrt_s: 0.1_f64.to_radians() / 60.0,
        gyro_bias_density: 2.0 * (50.0_f64 / 3600.0).to_radians().powi(2) / 3600.0,
        accel_bias_density: 2.0 * (0.25e-3 * 9.8_f64).powi(2) / 1800.0,
    };
    let big_s = Matrix21::from_diagonal(&noise.diagonal_of::<STATES_WITH_SCALE>());
    let t = crate::ins::filter::DEFAULT_COVARIANCE_INTERVAL_S;
    let (phi_exact, q_exact) = super::error_state::van_loan(&big_f, &big_s, t);
    let phi = discrete::transition_third_order(&big_f, t);
    let q = discrete::process_noise_series(&big_f, &noise, t);
    // The bounds of the 15-state test: Φ's remainder ‖A⁴‖e^a/24, Q_d's ‖M₅‖T⁶e^(2a)/720.
    let a_mat = big_f * t;
    let a = a_mat.norm();
    let phi_bound = (a_mat * a_mat * a_mat * a_mat).norm() * a.exp() / 24.0;
    let mut m = big_s;
    for _ in 0..5 {
        let fm = big_f * m;
        m = fm + fm.transpose();
    }
    let q_bound = m.norm() * t.powi(6) * (2.0 * a).exp() / 720.0 / q_exact.norm();
    let phi_error = (phi - phi_exact).norm();
    let q_error = (q - q_exact).norm() / q_exact.norm();
    assert!(
        phi_error <= phi_bound,
        "Φ {phi_error:e} beyond {phi_bound:e}"
    );
    assert!(q_error <= q_bound, "Q_d {q_error:e} beyond {q_bound:e}");
    // The scale factors' coupling is in Φ: δs_g reaches the attitude within the interval.
    let coupling = phi_exact.fixed_view::<3, 3>(ATTITUDE, GYRO_SCALE).norm();
    assert!(
        coupling > 0.0
            && (phi.fixed_view::<3, 3>(ATTITUDE, GYRO_SCALE).norm() - coupling).abs()
                < 1e-6 * coupling
    );
    // Negative control: the second-order Φ misses the bound.
    let second = discrete::transition(&big_f, t);
    assert!((second - phi_exact).norm() > phi_bound);
}
