//! The non-holonomic constraint's H against the vehicle velocity it linearizes: central
//! differences of v̂^v over each error state of a car's 18, at a truth that obeys the
//! constraint (where H's mounting columns, taken at v^v = (v̂_x^v, 0, 0), are the exact ones).

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use crate::ins::attitude_from_euler;
use crate::ins::earth::Geodetic;
use crate::ins::error_state::{ATTITUDE, VELOCITY, start_of};
use crate::ins::measurement::{At, Measurement, Rows};
use crate::ins::mech::Pva;
use crate::ins::nhc::{Constraint, Nhc};
use crate::ins::state::{Block, Layout};

const N: usize = Layout::CAR.dim();

const NHC: Nhc = Nhc {
    sigma_m_s: 0.05,
    true_sigma_m_s: 0.0,
    rate_hz: 5.0,
    min_speed_m_s: 1.0,
};

/// A car at 14 m/s, banked and climbing, its IMU upside down and a few degrees off; the
/// vehicle moves along its own x axis (the constraint holds).
fn scene() -> (Pva, UnitQuaternion<f64>) {
    let mounting = attitude_from_euler(std::f64::consts::PI + 0.03, -0.02, 0.05);
    let attitude = attitude_from_euler(0.05, 0.04, 0.86);
    let pva = Pva {
        position: Geodetic {
            lat_rad: 0.65,
            lon_rad: -2.1,
            height_m: 40.0,
        },
        velocity_ned_m_s: attitude
            * mounting.inverse_transform_vector(&Vector3::new(14.0, 0.0, 0.0)),
        attitude,
    };
    (pva, mounting)
}

/// The constraint's rows at the solution `pva` with mounting `mounting`.
fn rows_at(pva: &Pva, mounting: &UnitQuaternion<f64>) -> Rows<N> {
    let at = At {
        pva,
        lever_arm_b_m: Vector3::zeros(),
        rate_ib_b_rad_s: Vector3::zeros(),
        mounting: *mounting,
    };
    let c = Constraint {
        t_s: 1.0,
        measured_m_s: [0.0, 0.0],
        nhc: NHC,
    };
    let mut rows = Rows::<N>::default();
    Measurement::<N>::rows(&c, &at, &mut rows);
    rows
}

/// The lateral and vertical velocity predicted with the error `dx` in the solution.
fn predicted(pva: &Pva, mounting: &UnitQuaternion<f64>, dx: &SVector<f64, N>) -> SVector<f64, 2> {
    let est = Pva {
        velocity_ned_m_s: pva.velocity_ned_m_s + dx.fixed_rows::<3>(VELOCITY),
        attitude: UnitQuaternion::from_scaled_axis(dx.fixed_rows::<3>(ATTITUDE).into_owned())
            * pva.attitude,
        ..*pva
    };
    let mu = dx
        .fixed_rows::<3>(start_of::<N>(Block::Mounting))
        .into_owned();
    let rows = rows_at(&est, &(UnitQuaternion::from_scaled_axis(mu) * mounting));
    assert_eq!(rows.len, 2);
    rows.innovation.fixed_rows::<2>(0).into_owned()
}

#[test]
fn h_is_the_jacobian_of_the_vehicle_s_lateral_and_vertical_velocity() {
    let (pva, mounting) = scene();
    let mut numeric = SMatrix::<f64, 2, N>::zeros();
    for i in 0..N {
        let mut dx = SVector::<f64, N>::zeros();
        dx[i] = 1e-5;
        let column = (predicted(&pva, &mounting, &dx) - predicted(&pva, &mounting, &-dx)) / 2e-5;
        numeric.set_column(i, &column);
    }
    let rows = rows_at(&pva, &mounting);
    let h = rows.observation.fixed_rows::<2>(0).into_owned();
    let worst = (h - numeric).norm() / h.norm();
    // Measured: 1.6·10⁻¹¹, the differences' round-off.
    assert!(
        worst < 1e-8,
        "H differs from the finite differences by {worst:e}"
    );
    // The mounting's yaw and pitch are seen, at about the speed; its roll is not.
    let mounting_at = start_of::<N>(Block::Mounting);
    assert!(h.column(mounting_at).norm() < 2.0, "{h}");
    assert!(h.column(mounting_at + 1).norm() > 10.0, "{h}");
    assert!(h.column(mounting_at + 2).norm() > 10.0, "{h}");
    // Negative control: H without the mounting's columns.
    let mut without = h;
    without.fixed_columns_mut::<3>(mounting_at).fill(0.0);
    let missed = (without - numeric).norm() / h.norm();
    assert!(
        missed > 0.1,
        "the comparison missed the mounting: {missed:e}"
    );
}

#[test]
fn the_constraint_waits_for_the_vehicle_to_move() {
    let (mut pva, mounting) = scene();
    pva.velocity_ned_m_s = Vector3::new(0.6, 0.7, 0.0);
    assert_eq!(rows_at(&pva, &mounting).len, 0);
    pva.velocity_ned_m_s *= 2.0;
    let rows = rows_at(&pva, &mounting);
    let names: Vec<_> = rows.names().iter().map(|v| v.key).collect();
    assert_eq!(names, ["vehicle_velocity_y", "vehicle_velocity_z"]);
}
