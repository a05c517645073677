//! The non-holonomic constraint of a land vehicle: it neither slides sideways nor leaves the road,
//! so its velocity in its own forward-right-down axes has zero lateral and vertical components, up
//! to the tyres' slip (Groves §15.4.2, the non-holonomic motion constraints; Shin 2001 §4.1).
//!
//! With the IMU mounted by C_b^v and at the vehicle's reference point, the vehicle's velocity is
//! v^v = C_b^v C_n^b v^n. The INS predicts it from its solution and its mounting estimate; to
//! first order in the error state (estimate minus truth, Ĉ_b^n = (I + \[δψ×\])C_b^n,
//! Ĉ_b^v = (I + \[δμ×\])C_b^v):
//!
//! v̂^v − v^v = C_n^v δv + C_n^v \[v^n×\] δψ − \[v^v×\] δμ,
//!
//! of which the constraint measures the y (lateral) and z (vertical) rows against zero. Forward
//! speed s makes the lateral row see the mounting's yaw (s·δμ_z) and the vertical one its pitch
//! (−s·δμ_y); the mounting's roll is not seen. The mounting's columns are taken at the
//! constraint's own v^v = (v̂_x^v, 0, 0), not at the estimate's: while the pitch and yaw are still
//! degrees off, v̂^v has lateral and vertical parts of s·δμ that would make the roll look seen and
//! draw false information into it (the EKF's inconsistency along an unobservable direction; Huang,
//! Mourikis & Roumeliotis 2010, the observability-constrained EKF). Measured over 1 000 car
//! drives: with the estimate's v̂^v the roll's error is 1.20× its σ at the end, with the
//! constraint's 1.0×. The constraint holds while the vehicle moves: its rows are written only when
//! the solution's speed is above a threshold.

use nalgebra::{Matrix3, Vector3};

use super::driver::{Context, Source};
use super::error_state::{ATTITUDE, VELOCITY, offset_of};
use super::measurement::{At, Measurement, Rows};
use super::mech::skew;
use super::state::Block;
use crate::state::Variable;

/// The vehicle's velocity components, its forward-right-down axes.
pub const COMPONENTS: [Variable; 3] = [
    Variable {
        key: "vehicle_velocity_x",
        name: "vehicle's forward velocity",
        symbol: "v_x^v",
        unit: "m/s",
    },
    Variable {
        key: "vehicle_velocity_y",
        name: "vehicle's lateral velocity",
        symbol: "v_y^v",
        unit: "m/s",
    },
    Variable {
        key: "vehicle_velocity_z",
        name: "vehicle's vertical velocity",
        symbol: "v_z^v",
        unit: "m/s",
    },
];

/// The constraint's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nhc {
    /// The slip σ the filter weighs the constraint with, m/s.
    pub sigma_m_s: f64,
    /// The true slip σ a simulation draws (0 on a log: the constraint is zero itself), m/s.
    pub true_sigma_m_s: f64,
    /// Updates per second.
    pub rate_hz: f64,
    /// The speed above which the constraint is applied, m/s.
    pub min_speed_m_s: f64,
}

/// One constraint: the lateral and vertical velocity measured as `measured_m_s` (zero, or a
/// simulation's slip) at `t_s`.
pub struct Constraint {
    /// Its time, s.
    pub t_s: f64,
    /// The lateral and vertical velocity measured, m/s.
    pub measured_m_s: [f64; 2],
    /// The settings it is weighed by.
    pub nhc: Nhc,
}

impl<const N: usize> Measurement<N> for Constraint {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        let v_n = at.pva.velocity_ned_m_s;
        if v_n.norm() <= self.nhc.min_speed_m_s {
            return;
        }
        let q_nv = at.mounting * at.pva.attitude.inverse();
        let c_nv: Matrix3<f64> = *q_nv.to_rotation_matrix().matrix();
        let v_v = c_nv * v_n;
        let z = v_v - Vector3::new(0.0, self.measured_m_s[0], self.measured_m_s[1]);
        let r = Vector3::repeat(self.nhc.sigma_m_s * self.nhc.sigma_m_s);
        let mounting = const { offset_of::<N>(Block::Mounting) };
        let blocks = [
            (VELOCITY, c_nv),
            (ATTITUDE, c_nv * skew(&v_n)),
            (mounting.unwrap_or(0), -skew(&Vector3::new(v_v.x, 0.0, 0.0))),
        ];
        let used = if mounting.is_some() { 3 } else { 2 };
        rows.push3((&z, &r), &blocks[..used], &COMPONENTS, [false, true, true]);
    }
}

/// The constraint's source: an update every 1/rate, half a period past each whole one (between
/// the fixes of a receiver at a rate dividing it), in (from, to].
pub struct NhcSource {
    nhc: Nhc,
    next_s: f64,
    to_s: f64,
}

impl NhcSource {
    /// The updates of `nhc` between `from_s` and `to_s`.
    pub fn between(nhc: Nhc, from_s: f64, to_s: f64) -> Self {
        let period = 1.0 / nhc.rate_hz;
        let first = ((from_s / period - 0.5).floor() + 1.5) * period;
        NhcSource {
            nhc,
            next_s: first,
            to_s,
        }
    }
}

impl<const N: usize, C: Context + ?Sized> Source<N, C> for NhcSource {
    fn next_time(&self) -> Option<f64> {
        (self.next_s <= self.to_s).then_some(self.next_s)
    }

    fn take(&mut self, imu: &mut C) -> Box<dyn Measurement<N>> {
        let t_s = self.next_s;
        self.next_s += 1.0 / self.nhc.rate_hz;
        let s = self.nhc.true_sigma_m_s;
        let measured_m_s = [s * imu.normal(), s * imu.normal()];
        Box::new(Constraint {
            t_s,
            measured_m_s,
            nhc: self.nhc,
        })
    }
}
