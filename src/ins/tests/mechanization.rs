//! The navigation layer against independent values: WGS-84's published constants, the explicit
//! ZYX direction cosine matrix, and a stationary IMU on the rotating Earth.

use approx::assert_relative_eq;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::ins::earth::{self, Geodetic};
use crate::ins::mech::{self, Increment, Pva};
use crate::ins::{attitude_from_euler, euler_of};

/// Normal gravity at the pole γ_p, m/s² (NIMA TR8350.2 table 3.4): not used by the code, which
/// takes γ_e and k.
const GRAVITY_POLE_M_S2: f64 = 9.832_184_937_8;

#[test]
fn radii_and_gravity_match_the_published_wgs84_values() {
    // R_N at the equator is b²/a, R_E at the pole a²/b, with the published semi-minor axis
    // b = 6 356 752.3142 m (TR8350.2 table 3.3), given to 0.1 mm.
    let b = 6_356_752.314_2;
    let a = earth::SEMI_MAJOR_AXIS_M;
    let (rn, re) = earth::radii_m(0.0);
    assert_relative_eq!(rn, b * b / a, epsilon = 1e-3);
    assert_relative_eq!(re, earth::SEMI_MAJOR_AXIS_M, epsilon = 1e-9);
    let (rn, re) = earth::radii_m(std::f64::consts::FRAC_PI_2);
    assert_relative_eq!(rn, re, epsilon = 1e-6);
    assert_relative_eq!(re, a * a / b, epsilon = 1e-3);
    let at = |lat_deg: f64, height_m| {
        earth::normal_gravity_m_s2(&Geodetic {
            lat_rad: lat_deg.to_radians(),
            lon_rad: 0.0,
            height_m,
        })
    };
    assert_relative_eq!(at(0.0, 0.0), earth::GRAVITY_EQUATOR_M_S2, epsilon = 1e-12);
    assert_relative_eq!(at(90.0, 0.0), GRAVITY_POLE_M_S2, epsilon = 1e-9);
    // The free-air gradient near the ground is about −3.086·10⁻⁶ s⁻² at 45°.
    let gradient = (at(45.0, 100.0) - at(45.0, 0.0)) / 100.0;
    assert_relative_eq!(gradient, -3.086e-6, epsilon = 2e-9);
}

#[test]
fn the_nav_frame_follows_the_ellipsoid() {
    for &(lat_deg, lon_deg) in &[(0.0, 0.0), (37.4, -122.1), (-33.9, 151.2), (89.0, 179.9)] {
        let (lat, lon) = (f64::to_radians(lat_deg), f64::to_radians(lon_deg));
        let q = earth::nav_to_earth(lat, lon);
        // Down is minus the ellipsoid's normal; north points up the meridian (dz/dL > 0).
        let down = q * Vector3::z();
        let normal = Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
        assert_relative_eq!(down, -normal, epsilon = 1e-15);
        let p = |dl: f64| {
            earth::ecef_m(&Geodetic {
                lat_rad: lat + dl,
                lon_rad: lon,
                height_m: 0.0,
            })
        };
        let meridian = (p(1e-7) - p(-1e-7)).normalize();
        assert_relative_eq!(q * Vector3::x(), meridian, epsilon = 1e-8);
        let (l2, o2) = earth::lat_lon_of(&q);
        assert_relative_eq!(l2, lat, epsilon = 1e-14);
        assert_relative_eq!(o2, lon, epsilon = 1e-14);
    }
}

#[test]
fn euler_angles_are_the_zyx_sequence() {
    let (roll, pitch, yaw) = (0.3_f64, -0.2_f64, 2.5_f64);
    let rx = Matrix3::new(
        1.0,
        0.0,
        0.0,
        0.0,
        roll.cos(),
        -roll.sin(),
        0.0,
        roll.sin(),
        roll.cos(),
    );
    let ry = Matrix3::new(
        pitch.cos(),
        0.0,
        pitch.sin(),
        0.0,
        1.0,
        0.0,
        -pitch.sin(),
        0.0,
        pitch.cos(),
    );
    let rz = Matrix3::new(
        yaw.cos(),
        -yaw.sin(),
        0.0,
        yaw.sin(),
        yaw.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    );
    let q = attitude_from_euler(roll, pitch, yaw);
    assert_relative_eq!(
        *q.to_rotation_matrix().matrix(),
        rz * ry * rx,
        epsilon = 1e-15
    );
    let (r2, p2, y2) = euler_of(&q);
    assert_relative_eq!(r2, roll, epsilon = 1e-14);
    assert_relative_eq!(p2, pitch, epsilon = 1e-14);
    assert_relative_eq!(y2, yaw, epsilon = 1e-14);
    // Hamilton, scalar first: a yaw of ψ alone is (cos ψ/2, 0, 0, sin ψ/2).
    let q = attitude_from_euler(0.0, 0.0, yaw);
    assert_relative_eq!(q.w, (yaw / 2.0).cos(), epsilon = 1e-15);
    assert_relative_eq!(q.k, (yaw / 2.0).sin(), epsilon = 1e-15);
}

/// An IMU at rest on the rotating Earth for `hours`, at `rate_hz`, fed its exact increments:
/// the position error, m, and the attitude error, rad, at the end.
fn stationary(hours: f64, rate_hz: f64) -> (f64, f64) {
    let start = Pva {
        position: Geodetic {
            lat_rad: 37.4_f64.to_radians(),
            lon_rad: -122.1_f64.to_radians(),
            height_m: 30.0,
        },
        velocity_ned_m_s: Vector3::zeros(),
        attitude: attitude_from_euler(-0.02, 0.035, 0.52),
    };
    let dt = 1.0 / rate_hz;
    let c_nb = start.attitude.inverse();
    // At rest, f^b = −C_n^b g^n and ω_ib^b = C_n^b ω_ie^n, both constant in body axes.
    let f = c_nb * -earth::gravity_ned(&start.position);
    let w = c_nb * earth::earth_rate_ned(start.position.lat_rad);
    let inc = Increment {
        dtheta_rad: w * dt,
        dvel_m_s: f * dt,
        dt_s: dt,
    };
    let steps = (hours * 3600.0 * rate_hz).round() as usize;
    let mut pva = start;
    for _ in 0..steps {
        pva = mech::step(&pva, &inc, &inc);
    }
    let moved = (earth::ecef_m(&pva.position) - earth::ecef_m(&start.position)).norm();
    let turned = (pva.attitude.inverse() * start.attitude).angle();
    (moved, turned)
}

#[test]
fn a_stationary_imu_on_the_rotating_earth_stays_put_for_an_hour() {
    let (moved, turned) = stationary(1.0, 200.0);
    // Measured: 3.1·10⁻⁵ m (the (I − ½[ζ×]) projection's second-order term, grown by the vertical
    // channel's instability) and 7·10⁻¹¹ rad.
    assert!(moved < 1e-3, "moved {moved} m in an hour");
    assert!(turned < 1e-6, "turned {turned} rad in an hour");
}

#[test]
fn leaving_out_earth_rate_makes_the_stationary_imu_drift() {
    // Negative control: the same IMU with its gyros fed nothing drifts by Earth's rate.
    let start = Pva {
        position: Geodetic {
            lat_rad: 0.65,
            lon_rad: 0.0,
            height_m: 0.0,
        },
        velocity_ned_m_s: Vector3::zeros(),
        attitude: attitude_from_euler(0.0, 0.0, 0.0),
    };
    let dt = 0.005;
    let inc = Increment {
        dtheta_rad: Vector3::zeros(),
        dvel_m_s: -earth::gravity_ned(&start.position) * dt,
        dt_s: dt,
    };
    let mut pva = start;
    for _ in 0..(60.0 / dt) as usize {
        pva = mech::step(&pva, &inc, &inc);
    }
    let turned = (pva.attitude.inverse() * start.attitude).angle();
    // A minute of Earth's rate: 4.4 mrad.
    assert_relative_eq!(
        turned,
        earth::ROTATION_RATE_RAD_S * 60.0,
        max_relative = 1e-3
    );
}

/// The mechanization fed the default drive's exact increments at `rate_hz` from the true start:
/// the largest position error over the drive, m, and the largest attitude error, rad.
fn follow_the_truth(rate_hz: f64) -> (f64, f64) {
    let drive = crate::ins::drive::Drive::default_drive();
    let start = Geodetic {
        lat_rad: 37.4_f64.to_radians(),
        lon_rad: -122.1_f64.to_radians(),
        height_m: 30.0,
    };
    let truth = crate::ins::truth::Truth::new(&drive, start, 1.0 / rate_hz);
    let mut pva = truth.pva();
    let mut before = None;
    let (mut worst_m, mut worst_rad) = (0.0_f64, 0.0_f64);
    for (inc, exact) in truth {
        pva = mech::step(&pva, before.as_ref().unwrap_or(&inc), &inc);
        before = Some(inc);
        let e = (earth::ecef_m(&pva.position) - earth::ecef_m(&exact.position)).norm();
        worst_m = worst_m.max(e);
        worst_rad = worst_rad.max((pva.attitude.inverse() * exact.attitude).angle());
    }
    (worst_m, worst_rad)
}

#[test]
fn fed_the_exact_increments_the_mechanization_follows_the_drive() {
    let errors: Vec<(f64, f64)> = [100.0, 200.0, 400.0]
        .iter()
        .map(|&r| follow_the_truth(r))
        .collect();
    // Measured: 1.90·10⁻², 4.75·10⁻³, 1.18·10⁻³ m and 2.1·10⁻⁹, 5.0·10⁻¹⁰, 1.2·10⁻¹⁰ rad at 100,
    // 200, 400 Hz: second order, as the two-sample algorithms are.
    assert!(errors[1].0 < 0.01, "position error at 200 Hz: {errors:?}");
    for pair in errors.windows(2) {
        let (position, attitude) = (pair[0].0 / pair[1].0, pair[0].1 / pair[1].1);
        assert!(
            (3.6..4.4).contains(&position),
            "halving the step: {errors:?}"
        );
        assert!(
            (3.6..4.4).contains(&attitude),
            "halving the step: {errors:?}"
        );
    }
}

#[test]
fn the_drive_s_rates_are_the_derivatives_of_its_velocity_and_attitude() {
    let drive = crate::ins::drive::Drive::default_drive();
    let h = 1e-4;
    let mut t = 0.5;
    while t < drive.duration_s() - 1.0 {
        // Segments meet on whole seconds, where the roll's second derivative jumps.
        if (t - t.round()).abs() < 10.0 * h {
            t += 1.7;
            continue;
        }
        let at = |t: f64| crate::ins::truth::kinematics(&drive.motion(t));
        let (_, dv, q, omega_nb) = at(t);
        let (v_minus, _, q_minus, _) = at(t - h);
        let (v_plus, _, q_plus, _) = at(t + h);
        let dv_fd = (v_plus - v_minus) / (2.0 * h);
        assert!(
            (dv_fd - dv).norm() < 1e-6,
            "t = {t}: v̇ {dv} against {dv_fd}"
        );
        // C_b^n(t)ᵀC_b^n(t ± h) turns by ±h·ω_nb^b to first order; the central difference is
        // second order.
        let turn = ((q.inverse() * q_plus).scaled_axis() - (q.inverse() * q_minus).scaled_axis())
            / (2.0 * h);
        assert!(
            (turn - omega_nb).norm() < 1e-6,
            "t = {t}: ω_nb {omega_nb} against {turn}"
        );
        t += 1.7;
    }
}

#[test]
fn the_default_drive_lasts_the_configuration_s_longest_drive() {
    let drive = crate::ins::drive::Drive::default_drive();
    assert_eq!(drive.duration_s(), crate::config::ins::LONGEST_DRIVE_S);
}

#[test]
fn the_small_rotation_series_equals_the_functions() {
    use crate::ins::mech::rotation;
    // Angles from the Earth's turn in one step (3.6·10⁻⁷ rad) to the series' limit and beyond.
    for (k, theta) in [3.6e-7, 1e-4, 2e-3, 9.9e-3, 2e-2].into_iter().enumerate() {
        let axis = Vector3::new(0.3, -0.5 + 0.1 * k as f64, 0.8).normalize();
        let q = rotation(&(axis * theta));
        let exact = UnitQuaternion::from_scaled_axis(axis * theta);
        let worst = (q.coords - exact.coords).amax();
        // Measured: 1.1·10⁻¹⁶ at most, the round-off of cos x near 1.
        assert!(worst <= 4.0 * f64::EPSILON, "θ = {theta}: {worst:e}");
        assert!((q.norm() - 1.0).abs() <= 4.0 * f64::EPSILON);
    }
    // Negative control: the first-order quaternion (1, v/2) is off by θ²/8 at 10⁻² rad.
    let v = Vector3::new(0.0, 0.0, 9.9e-3);
    let first = nalgebra::Quaternion::new(1.0, 0.0, 0.0, 0.5 * v.z);
    let exact = UnitQuaternion::from_scaled_axis(v);
    assert!((first.coords - exact.coords).amax() > 4.0 * f64::EPSILON);
}

#[test]
fn the_earth_at_a_point_equals_the_free_functions() {
    let v = Vector3::new(23.0, -17.0, 0.4);
    let gap = |p: &Geodetic, e: &earth::Local| {
        [
            (e.earth_rate_ned() - earth::earth_rate_ned(p.lat_rad)).norm()
                / earth::ROTATION_RATE_RAD_S,
            (e.transport_rate_ned(&v) - earth::transport_rate_ned(p, &v)).norm()
                / earth::transport_rate_ned(p, &v).norm(),
            (e.geodetic_rate(&v) - earth::geodetic_rate(p, &v)).norm()
                / earth::geodetic_rate(p, &v).norm(),
            (e.gravity_ned() - earth::gravity_ned(p)).norm() / earth::gravity_ned(p).norm(),
        ]
        .into_iter()
        .fold(0.0, f64::max)
    };
    for (lat_deg, height_m) in [(-80.0, 0.0), (-12.5, 300.0), (0.3, -50.0), (37.4, 1200.0)] {
        let p = Geodetic {
            lat_rad: f64::to_radians(lat_deg),
            lon_rad: 0.7,
            height_m,
        };
        // Measured: a few ulps (sin_cos against sin and cos, sin/cos against tan).
        assert!(gap(&p, &earth::Local::at(&p)) <= 1e-14, "at {lat_deg}°");
        // Negative control: the Earth 10⁻⁶ rad further north differs beyond that.
        let north = Geodetic {
            lat_rad: p.lat_rad + 1e-6,
            ..p
        };
        assert!(gap(&p, &earth::Local::at(&north)) > 1e-14);
    }
}
