//! F against the navigation equations it linearizes: the rate of the error between a true and a
//! perturbed solution, by central differences over each error state.

use nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3};

use crate::ins::earth::{self, Geodetic};
use crate::ins::error_state::{
    self, ACCEL_BIAS, ATTITUDE, BiasDecay, GYRO_BIAS, Matrix15, POSITION, STATES, Square, VELOCITY,
};
use crate::ins::mech::{Pva, skew};

/// A navigation solution with its biases.
#[derive(Clone, Copy)]
struct State {
    p: Geodetic,
    v: Vector3<f64>,
    c: Matrix3<f64>,
    bg: Vector3<f64>,
    ba: Vector3<f64>,
}

/// The NED navigation equations (Groves §5.4): (ṗ curvilinear, v̇^n, Ċ_b^n) for the sensed
/// specific force and angular rate, compensated by the state's own biases.
fn nav_rates(
    s: &State,
    f_meas: &Vector3<f64>,
    w_meas: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>, Matrix3<f64>) {
    let (f, w) = (f_meas - s.ba, w_meas - s.bg);
    let w_ie = earth::earth_rate_ned(s.p.lat_rad);
    let w_en = earth::transport_rate_ned(&s.p, &s.v);
    let v_rate = s.c * f + earth::gravity_ned(&s.p) - (2.0 * w_ie + w_en).cross(&s.v);
    let c_rate = s.c * skew(&w) - skew(&(w_ie + w_en)) * s.c;
    (earth::geodetic_rate(&s.p, &s.v), v_rate, c_rate)
}

/// T = diag(R_N + h, (R_E + h)cos L, −1) at `p`: curvilinear position errors to NED metres.
fn t_of(p: &Geodetic) -> Vector3<f64> {
    let (rn, re) = earth::radii_m(p.lat_rad);
    Vector3::new(rn + p.height_m, (re + p.height_m) * p.lat_rad.cos(), -1.0)
}

/// `truth` with the error `dx` added (estimate = truth + error, in the error state's coordinates).
fn perturbed(truth: &State, dx: &SVector<f64, STATES>) -> State {
    let t = t_of(&truth.p);
    let dr = dx.fixed_rows::<3>(POSITION);
    State {
        p: Geodetic {
            lat_rad: truth.p.lat_rad + dr[0] / t.x,
            lon_rad: truth.p.lon_rad + dr[1] / t.y,
            height_m: truth.p.height_m + dr[2] / t.z,
        },
        v: truth.v + dx.fixed_rows::<3>(VELOCITY),
        c: *UnitQuaternion::from_scaled_axis(dx.fixed_rows::<3>(ATTITUDE).into_owned())
            .to_rotation_matrix()
            .matrix()
            * truth.c,
        bg: truth.bg + dx.fixed_rows::<3>(GYRO_BIAS),
        ba: truth.ba + dx.fixed_rows::<3>(ACCEL_BIAS),
    }
}

/// The rate of the error between `est` and `truth`, both driven by the same sensor readings.
fn error_rate(
    truth: &State,
    est: &State,
    f: &Vector3<f64>,
    w: &Vector3<f64>,
    decay: &BiasDecay,
) -> SVector<f64, STATES> {
    let (p_rate, v_rate, c_rate) = nav_rates(truth, f, w);
    let (p_rate_e, v_rate_e, c_rate_e) = nav_rates(est, f, w);
    let t = t_of(&truth.p);
    let (drn, dre) = earth::radii_rate_m_per_rad(truth.p.lat_rad);
    let (_, re) = earth::radii_m(truth.p.lat_rad);
    let (sl, cl) = truth.p.lat_rad.sin_cos();
    let t_rate = Vector3::new(
        drn * p_rate.x + p_rate.z,
        (dre * p_rate.x + p_rate.z) * cl - (re + truth.p.height_m) * sl * p_rate.x,
        0.0,
    );
    let dp = Vector3::new(
        est.p.lat_rad - truth.p.lat_rad,
        est.p.lon_rad - truth.p.lon_rad,
        est.p.height_m - truth.p.height_m,
    );
    // d/dt[T(p̂ − p)] = Ṫ(p̂ − p) + T(ṗ̂ − ṗ).
    let dr_rate = t_rate.component_mul(&dp) + t.component_mul(&(p_rate_e - p_rate));
    // Ĉ Cᵀ = exp([δψ×]): its rate's skew part is [δψ̇×] to first order (the symmetric rest is
    // second order and cancels in the central difference).
    let m = c_rate_e * truth.c.transpose() + est.c * c_rate.transpose();
    let psi_rate = Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) / 2.0;
    let mut out = SVector::<f64, STATES>::zeros();
    out.fixed_rows_mut::<3>(POSITION).copy_from(&dr_rate);
    out.fixed_rows_mut::<3>(VELOCITY)
        .copy_from(&(v_rate_e - v_rate));
    out.fixed_rows_mut::<3>(ATTITUDE).copy_from(&psi_rate);
    out.fixed_rows_mut::<3>(GYRO_BIAS)
        .copy_from(&(-decay.gyro_per_s * (est.bg - truth.bg)));
    out.fixed_rows_mut::<3>(ACCEL_BIAS)
        .copy_from(&(-decay.accel_per_s * (est.ba - truth.ba)));
    out
}

/// A moving, turning, climbing vehicle with biases.
fn scene() -> (State, Vector3<f64>, Vector3<f64>, BiasDecay) {
    let q = crate::ins::attitude_from_euler(0.09, -0.05, 2.1);
    let truth = State {
        p: Geodetic {
            lat_rad: 37.4_f64.to_radians(),
            lon_rad: -122.1_f64.to_radians(),
            height_m: 480.0,
        },
        v: Vector3::new(15.0, -8.0, 0.7),
        c: *q.to_rotation_matrix().matrix(),
        bg: Vector3::new(2e-4, -1e-4, 3e-4),
        ba: Vector3::new(0.02, -0.03, 0.01),
    };
    let f = Vector3::new(1.2, -0.8, -9.7);
    let w = Vector3::new(0.02, -0.05, 0.3);
    let decay = BiasDecay {
        gyro_per_s: 1.0 / 3600.0,
        accel_per_s: 1.0 / 1800.0,
    };
    (truth, f, w, decay)
}

/// The finite-difference Jacobian of the error rate, column by column.
fn numeric_f(truth: &State, f: &Vector3<f64>, w: &Vector3<f64>, decay: &BiasDecay) -> Matrix15 {
    // Steps: 100 m (the attitude rate it causes, ~10⁻⁹ rad/s, must stand above the round-off of
    // rates of 0.3 rad/s), 1 mm/s, 10 µrad, small biases; second-order remainders cancel.
    let step = [
        100.0, 100.0, 100.0, 1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5, 1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4,
    ];
    let mut out = Matrix15::zeros();
    for i in 0..STATES {
        let mut dx = SVector::<f64, STATES>::zeros();
        dx[i] = step[i];
        let plus = error_rate(truth, &perturbed(truth, &dx), f, w, decay);
        let minus = error_rate(truth, &perturbed(truth, &-dx), f, w, decay);
        out.set_column(i, &((plus - minus) / (2.0 * step[i])));
    }
    out
}

/// The largest relative difference over the 3×3 blocks, ‖ΔF_block‖/‖F_block‖ (absolute for a
/// block that should be zero, against the matrix's scale).
fn worst_block_difference(a: &Matrix15, b: &Matrix15) -> (f64, usize, usize) {
    let mut worst = (0.0, 0, 0);
    for r in (0..STATES).step_by(3) {
        for c in (0..STATES).step_by(3) {
            let x = a.fixed_view::<3, 3>(r, c);
            let y = b.fixed_view::<3, 3>(r, c);
            let scale = x.norm().max(y.norm()).max(1e-12);
            let d = (x - y).norm() / scale;
            if d > worst.0 {
                worst = (d, r, c);
            }
        }
    }
    worst
}

#[test]
fn f_is_the_jacobian_of_the_navigation_equations() {
    let (truth, f, w, decay) = scene();
    let pva = Pva {
        position: truth.p,
        velocity_ned_m_s: truth.v,
        attitude: UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_matrix_unchecked(truth.c),
        ),
    };
    let analytic = error_state::dynamics(&pva, &(f - truth.ba), &decay);
    let numeric = numeric_f(&truth, &f, &w, &decay);
    let (worst, r, c) = worst_block_difference(&analytic, &numeric);
    // Measured: 5.4·10⁻⁸ (block δψ–δv), the finite differences' round-off.
    assert!(
        worst < 1e-6,
        "F differs from the finite-difference Jacobian by {worst:e} in block ({r}, {c})"
    );
    // Negative control: F without the gravity gradient (a common simplification) is caught.
    let mut simplified = analytic;
    simplified[(VELOCITY + 2, POSITION + 2)] = 0.0;
    let (worst, ..) = worst_block_difference(&simplified, &numeric);
    assert!(
        worst > 1e-3,
        "the comparison missed the gravity gradient: {worst:e}"
    );
}

/// Van Loan's exact Φ and Q_d over `dt` for constant F and S over an error state of `N` (the
/// reference of the tests below and of the 21-state one).
pub(super) fn van_loan<const N: usize>(
    f: &Square<N>,
    s: &Square<N>,
    dt: f64,
) -> (Square<N>, Square<N>) {
    let mut m = nalgebra::DMatrix::<f64>::zeros(2 * N, 2 * N);
    m.view_mut((0, 0), (N, N)).copy_from(&(-f * dt));
    m.view_mut((0, N), (N, N)).copy_from(&(s * dt));
    m.view_mut((N, N), (N, N)).copy_from(&(f.transpose() * dt));
    let e = m.exp();
    let phi = Square::<N>::from_fn(|i, j| e[(N + j, N + i)]);
    let q = phi * Square::<N>::from_fn(|i, j| e[(i, N + j)]);
    (phi, q)
}

#[test]
fn phi_and_q_match_van_loan_over_one_step() {
    use crate::ins::discrete::{self, NoiseDensities};
    let (truth, f, _, decay) = scene();
    let pva = Pva {
        position: truth.p,
        velocity_ned_m_s: truth.v,
        attitude: UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_matrix_unchecked(truth.c),
        ),
    };
    let big_f = error_state::dynamics(&pva, &(f - truth.ba), &decay);
    // An ADIS16465-class IMU: ARW 0.1°/√h, VRW 0.1 m/s/√h; biases as Gauss–Markov.
    let noise = NoiseDensities {
        accel_vrw_m_s_per_sqrt_s: 0.1 / 60.0,
        gyro_arw_rad_per_sqrt_s: 0.1_f64.to_radians() / 60.0,
        gyro_bias_density: 2.0 * (50.0_f64 / 3600.0).to_radians().powi(2) / 3600.0,
        accel_bias_density: 2.0 * (0.25e-3 * 9.8_f64).powi(2) / 1800.0,
    };
    let s = Matrix15::from_diagonal(&nalgebra::SVector::from(noise.diagonal()));
    for dt in [0.005, 0.01] {
        let (phi_exact, q_exact) = van_loan(&big_f, &s, dt);
        let phi = discrete::transition(&big_f, dt);
        let q = discrete::process_noise(&phi, &noise, dt);
        // The remainders, a = ‖FΔt‖: Φ's is (FΔt)³/6 and beyond, ≤ a³e^a/6; Q_d's is the
        // trapezoid's (Δt³/12)·g″ with g(s) = Φ(s)SΦ(s)ᵀ, ‖g″‖ ≤ 4‖F‖²‖S‖e^(2a), against
        // ‖Q_d‖ ≈ ‖S‖Δt: relative ≤ a²e^(2a)/3.
        let a = (big_f * dt).norm();
        let phi_bound = a.powi(3) / 6.0 * a.exp();
        // Measured at 200 Hz: ‖FΔt‖ = 0.071, Φ error 2.9·10⁻⁷ against 6.4·10⁻⁵, Q_d 4.2·10⁻⁶.
        let phi_error = (phi - phi_exact).norm();
        let q_error = (q - q_exact).norm() / q_exact.norm();
        assert!(
            phi_error <= phi_bound,
            "Φ error {phi_error:e} beyond {phi_bound:e}"
        );
        let q_bound = a * a * (2.0 * a).exp() / 3.0;
        assert!(
            q_error <= q_bound,
            "Q_d relative error {q_error:e} beyond {q_bound:e}"
        );
        // Negative control: the first-order Φ = I + FΔt misses the second-order bound.
        let first_order = Matrix15::identity() + big_f * dt;
        let first_error = (first_order - phi_exact).norm();
        assert!(
            first_error > phi_bound,
            "the first-order Φ passed: {first_error:e}"
        );
    }
}

#[test]
fn h_is_the_jacobian_of_the_antenna_s_position_and_velocity() {
    use crate::ins::gnss;
    let (truth, _, w, _) = scene();
    let lever = Vector3::new(0.8, -0.3, -1.2);
    let pva = |s: &State| Pva {
        position: s.p,
        velocity_ned_m_s: s.v,
        attitude: UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_matrix_unchecked(s.c),
        ),
    };
    let antenna = |s: &State| gnss::antenna(&pva(s), &lever, &(w - s.bg));
    let (p_true, v_true) = antenna(&truth);
    let measure = |dx: &SVector<f64, STATES>| {
        let (p, v) = antenna(&perturbed(&truth, dx));
        let mut z = SVector::<f64, 6>::zeros();
        z.fixed_rows_mut::<3>(0)
            .copy_from(&gnss::ned_difference_m(&p, &p_true));
        z.fixed_rows_mut::<3>(3).copy_from(&(v - v_true));
        z
    };
    // Attitude steps of 1 mrad: the antenna then moves 1.5 mm, whose latitude difference
    // (2·10⁻¹⁰ rad) stands well above a latitude's round-off (10⁻¹⁶ rad).
    let step = [
        1.0, 1.0, 1.0, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4,
    ];
    let mut numeric = nalgebra::SMatrix::<f64, 6, STATES>::zeros();
    for i in 0..STATES {
        let mut dx = SVector::<f64, STATES>::zeros();
        dx[i] = step[i];
        numeric.set_column(i, &((measure(&dx) - measure(&-dx)) / (2.0 * step[i])));
    }
    let h = gnss::observation(&pva(&truth), &lever, &(w - truth.bg));
    let worst = (h - numeric).norm() / h.norm();
    // Measured: 1.8·10⁻⁷, the latitude differences' round-off.
    assert!(
        worst < 1e-6,
        "H differs from the finite-difference Jacobian by {worst:e}"
    );
    // Negative control: H without the lever arm's attitude terms.
    let mut no_lever = h;
    no_lever.fixed_view_mut::<6, 3>(0, ATTITUDE).fill(0.0);
    let missed = (no_lever - numeric).norm() / h.norm();
    assert!(
        missed > 1e-3,
        "the comparison missed the lever arm: {missed:e}"
    );
}

#[test]
fn interval_phi_and_q_match_van_loan_over_a_covariance_interval() {
    use crate::ins::discrete::{self, NoiseDensities};
    use crate::ins::filter::DEFAULT_COVARIANCE_INTERVAL_S;
    let (truth, f, _, decay) = scene();
    let pva = Pva {
        position: truth.p,
        velocity_ned_m_s: truth.v,
        attitude: UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_matrix_unchecked(truth.c),
        ),
    };
    let big_f = error_state::dynamics(&pva, &(f - truth.ba), &decay);
    let noise = NoiseDensities {
        accel_vrw_m_s_per_sqrt_s: 0.1 / 60.0,
        gyro_arw_rad_per_sqrt_s: 0.1_f64.to_radians() / 60.0,
        gyro_bias_density: 2.0 * (50.0_f64 / 3600.0).to_radians().powi(2) / 3600.0,
        accel_bias_density: 2.0 * (0.25e-3 * 9.8_f64).powi(2) / 1800.0,
    };
    let s = Matrix15::from_diagonal(&nalgebra::SVector::from(noise.diagonal()));
    for t in [
        DEFAULT_COVARIANCE_INTERVAL_S,
        2.0 * DEFAULT_COVARIANCE_INTERVAL_S,
    ] {
        let (phi_exact, q_exact) = van_loan(&big_f, &s, t);
        let phi = discrete::transition_third_order(&big_f, t);
        let q = discrete::process_noise_series(&big_f, &noise, t);
        // Remainders, A = FT, a = ‖A‖: Φ's, Σ_(k≥4) A^k/k!, is at most ‖A⁴‖e^a/24; Q_d's,
        // Σ_(k≥5) M_k·T^(k+1)/(k+1)! with ‖M_(k+1)‖ ≤ 2‖F‖‖M_k‖, at most ‖M₅‖T⁶e^(2a)/720.
        let a_mat = big_f * t;
        let a = a_mat.norm();
        let a2 = a_mat * a_mat;
        let phi_bound = (a2 * a2).norm() * a.exp() / 24.0;
        let mut m = s;
        for _ in 0..5 {
            let fm = big_f * m;
            m = fm + fm.transpose();
        }
        let q_bound = m.norm() * t.powi(6) * (2.0 * a).exp() / 720.0 / q_exact.norm();
        // Measured at 0.1 s: ‖FT‖ = 1.4, Φ 1.8·10⁻⁸ against 7.5·10⁻⁸ (second order: 2.3·10⁻³),
        // Q_d 1.8·10⁻¹⁰ against 3.1·10⁻⁹ (the trapezoid: 1.7·10⁻³).
        let phi_error = (phi - phi_exact).norm();
        let q_error = (q - q_exact).norm() / q_exact.norm();
        assert!(
            phi_error <= phi_bound,
            "Φ {phi_error:e} beyond {phi_bound:e}"
        );
        assert!(q_error <= q_bound, "Q_d {q_error:e} beyond {q_bound:e}");
        // Negative controls: the second-order Φ and the trapezoidal Q_d over the interval.
        let second = discrete::transition(&big_f, t);
        let second_error = (second - phi_exact).norm();
        assert!(
            second_error > phi_bound,
            "second order passed: {second_error:e}"
        );
        let trapezoid = discrete::process_noise(&phi, &noise, t);
        let trapezoid_error = (trapezoid - q_exact).norm() / q_exact.norm();
        assert!(
            trapezoid_error > q_bound,
            "the trapezoid passed: {trapezoid_error:e}"
        );
    }
}

#[test]
fn the_block_sparse_products_equal_the_dense_ones() {
    use crate::ins::discrete::{self, DYNAMICS_BLOCKS};
    let (truth, f, _, decay) = scene();
    let pva = Pva {
        position: truth.p,
        velocity_ned_m_s: truth.v,
        attitude: UnitQuaternion::from_rotation_matrix(
            &nalgebra::Rotation3::from_matrix_unchecked(truth.c),
        ),
    };
    let big_f = error_state::dynamics(&pva, &(f - truth.ba), &decay);
    // F holds nothing outside the pattern.
    for (r, row) in (0..STATES).step_by(3).enumerate() {
        for column in (0..STATES).step_by(3) {
            let listed = DYNAMICS_BLOCKS[r].1.contains(&column);
            let block = big_f.fixed_view::<3, 3>(row, column).norm();
            assert!(
                listed || block == 0.0,
                "F({row}, {column}) outside the pattern"
            );
        }
    }
    let x = Matrix15::from_fn(|i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
    let p = x * x.transpose() + Matrix15::identity();
    let close = |a: &Matrix15, b: &Matrix15| (a - b).norm() <= 1e-13 * b.norm();
    assert!(close(&discrete::dynamics_times(&big_f, &x), &(big_f * x)));
    let phi = discrete::transition_third_order(&big_f, 0.2);
    let dense = Matrix15::identity()
        + big_f * 0.2
        + (big_f * 0.2).pow(2) / 2.0
        + (big_f * 0.2).pow(3) / 6.0;
    assert!(close(&phi, &dense));
    assert!(close(
        &discrete::transition_congruence(&phi, &p),
        &(phi * p * phi.transpose())
    ));
    // Negative control: a block outside the pattern is not multiplied.
    let mut outside = big_f;
    outside.fixed_view_mut::<3, 3>(0, ATTITUDE).fill(1.0);
    assert!(!close(
        &discrete::dynamics_times(&outside, &x),
        &(outside * x)
    ));
}
