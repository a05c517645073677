//! The loosely coupled GNSS measurement: the antenna's position (and velocity, where the fix has
//! it) against the INS's, through the lever arm from the IMU to the antenna.
//!
//! With the lever arm l^b in body axes, the antenna is at r^n + C_b^n l^b and moves at
//! v^n + C_b^n(ω_ib^b × l^b) − ω_in^n × C_b^n l^b (Groves §14.3.1, the local-navigation-frame
//! form). The measurement is the INS's prediction of the antenna minus the fix, in NED metres
//! (m/s); to first order in the error state (estimate minus truth, `error_state`'s conventions):
//!
//! - position: z_r = δr − \[(Cl)×\]δψ − w_r;
//! - velocity: z_v = δv − \[(C(ω_ib × l))×\]δψ + \[ω_in×\]\[(Cl)×\]δψ + C\[l×\]δb_g − w_v,
//!
//! where δω_ib^b = −δb_g because the gyros are compensated by the estimated bias (and
//! −δb_g − diag(ω_ib^b)δs_g with the scale factors: the velocity row then has C\[l×\]diag(ω_ib^b)
//! in δs_g's columns).

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::earth::{self, Geodetic};
use super::error_state::{ATTITUDE, GYRO_BIAS, POSITION, STATES, VELOCITY, offset_of};
use super::measurement::{At, Measurement, Rows};
use super::mech::{Pva, skew};
use super::names::MEASUREMENTS;
use super::state::Block;
use crate::state::Variable;

/// One GNSS fix: the antenna's position and, when measured, its velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fix {
    /// Time, s.
    pub t_s: f64,
    /// The antenna's position.
    pub position: Geodetic,
    /// The antenna's velocity in NED, m/s, when the fix has it.
    pub velocity_ned_m_s: Option<Vector3<f64>>,
    /// The position's σ in north, east and down, m.
    pub position_sigma_m: Vector3<f64>,
    /// The velocity's σ per component, m/s.
    pub velocity_sigma_m_s: Vector3<f64>,
}

/// The INS's antenna position and velocity from `pva`, lever arm `lever_b_m` and the
/// compensated angular rate `omega_ib_b`.
pub fn antenna(
    pva: &Pva,
    lever_b_m: &Vector3<f64>,
    omega_ib_b: &Vector3<f64>,
) -> (Geodetic, Vector3<f64>) {
    let p = &pva.position;
    let arm_n = pva.attitude * lever_b_m;
    let position = earth::offset(p, &arm_n);
    let w_in =
        earth::earth_rate_ned(p.lat_rad) + earth::transport_rate_ned(p, &pva.velocity_ned_m_s);
    let velocity =
        pva.velocity_ned_m_s + pva.attitude * omega_ib_b.cross(lever_b_m) - w_in.cross(&arm_n);
    (position, velocity)
}

/// `a − b` in NED metres at `a`: ((L_a − L_b)(R_N + h), (λ_a − λ_b)(R_E + h)cos L, −(h_a − h_b)),
/// λ_a − λ_b the shorter way round.
pub fn ned_difference_m(a: &Geodetic, b: &Geodetic) -> Vector3<f64> {
    let (rn, re) = earth::radii_m(a.lat_rad);
    Vector3::new(
        (a.lat_rad - b.lat_rad) * (rn + a.height_m),
        earth::longitude_difference(a.lon_rad, b.lon_rad) * (re + a.height_m) * a.lat_rad.cos(),
        -(a.height_m - b.height_m),
    )
}

/// The rows of H for the antenna's position (3) and velocity (3).
pub fn observation(
    pva: &Pva,
    lever_b_m: &Vector3<f64>,
    omega_ib_b: &Vector3<f64>,
) -> SMatrix<f64, 6, STATES> {
    observation_of(pva, lever_b_m, omega_ib_b)
}

/// [`observation`] over an error state of `N`: with the scale factors, the antenna velocity's
/// lever-arm term C_b^n(ω̂_ib^b × l^b) moves with δs_g as with δb_g, times diag(ω_ib^b).
pub fn observation_of<const N: usize>(
    pva: &Pva,
    lever_b_m: &Vector3<f64>,
    omega_ib_b: &Vector3<f64>,
) -> SMatrix<f64, 6, N> {
    let mut h = SMatrix::<f64, 6, N>::zeros();
    let c = *pva.attitude.to_rotation_matrix().matrix();
    let (position, velocity) = (
        position_blocks(&c, lever_b_m),
        velocity_blocks::<N>(pva, &c, lever_b_m, omega_ib_b),
    );
    for (row, blocks) in [(0, &position[..]), (3, velocity.as_slice())] {
        for (col, m) in blocks {
            h.fixed_view_mut::<3, 3>(row, *col).copy_from(m);
        }
    }
    h
}

/// The antenna position's nonzero 3×3 blocks of H, each at its first column (`c` = C_b^n).
fn position_blocks(c: &Matrix3<f64>, lever_b_m: &Vector3<f64>) -> [(usize, Matrix3<f64>); 2] {
    let arm_n = c * lever_b_m;
    [(POSITION, Matrix3::identity()), (ATTITUDE, -skew(&arm_n))]
}

/// The antenna velocity's nonzero 3×3 blocks of H over an error state of `N`.
fn velocity_blocks<const N: usize>(
    pva: &Pva,
    c: &Matrix3<f64>,
    lever_b_m: &Vector3<f64>,
    omega_ib_b: &Vector3<f64>,
) -> Blocks {
    let arm_n = c * lever_b_m;
    let w_in = earth::earth_rate_ned(pva.position.lat_rad)
        + earth::transport_rate_ned(&pva.position, &pva.velocity_ned_m_s);
    let mut blocks = Blocks::default();
    blocks.push((VELOCITY, Matrix3::identity()));
    blocks.push((
        ATTITUDE,
        -skew(&(c * omega_ib_b.cross(lever_b_m))) + skew(&w_in) * skew(&arm_n),
    ));
    blocks.push((GYRO_BIAS, c * skew(lever_b_m)));
    if let Some(at) = const { offset_of::<N>(Block::GyroScale) } {
        blocks.push((at, c * skew(lever_b_m) * Matrix3::from_diagonal(omega_ib_b)));
    }
    blocks
}

/// At most four 3×3 blocks of a row of H, each at its first column.
#[derive(Default)]
struct Blocks {
    items: [(usize, Matrix3<f64>); 4],
    len: usize,
}

impl Blocks {
    fn push(&mut self, block: (usize, Matrix3<f64>)) {
        self.items[self.len] = block;
        self.len += 1;
    }

    fn as_slice(&self) -> &[(usize, Matrix3<f64>)] {
        &self.items[..self.len]
    }
}

/// The position components' names.
fn position_names() -> &'static [Variable; 3] {
    MEASUREMENTS[..3]
        .try_into()
        .expect("three position components")
}

/// The velocity components' names.
fn velocity_names() -> &'static [Variable; 3] {
    MEASUREMENTS[3..]
        .try_into()
        .expect("three velocity components")
}

/// A fix's antenna position as a measurement: z_r = r̂_a − r̃_a in NED metres, R = diag(σ_r²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Position(pub Fix);

impl<const N: usize> Measurement<N> for Position {
    fn t_s(&self) -> f64 {
        self.0.t_s
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        let omega = &at.rate_ib_b_rad_s;
        let (position, _) = antenna(at.pva, &at.lever_arm_b_m, omega);
        let z = ned_difference_m(&position, &self.0.position);
        let s = &self.0.position_sigma_m;
        let c = *at.pva.attitude.to_rotation_matrix().matrix();
        rows.push3(
            (&z, &s.component_mul(s)),
            &position_blocks(&c, &at.lever_arm_b_m),
            position_names(),
            [true; 3],
        );
    }
}

/// A fix's antenna velocity as a measurement, the components `measured` keeps (a receiver
/// that reports no vertical velocity, or none): z_v = v̂_a − ṽ_a, R = diag(σ_v²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Velocity {
    /// The fix (its velocity `None`: no rows).
    pub fix: Fix,
    /// North, east, down: which components are measured.
    pub measured: [bool; 3],
}

impl<const N: usize> Measurement<N> for Velocity {
    fn t_s(&self) -> f64 {
        self.fix.t_s
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        let Some(v) = self.fix.velocity_ned_m_s else {
            return;
        };
        let omega = &at.rate_ib_b_rad_s;
        let (_, velocity) = antenna(at.pva, &at.lever_arm_b_m, omega);
        let s = &self.fix.velocity_sigma_m_s;
        let c = *at.pva.attitude.to_rotation_matrix().matrix();
        let blocks = velocity_blocks::<N>(at.pva, &c, &at.lever_arm_b_m, omega);
        rows.push3(
            (&(velocity - v), &s.component_mul(s)),
            blocks.as_slice(),
            velocity_names(),
            self.measured,
        );
    }
}

/// A GNSS fix as one update: its position and, where measured, its velocity, stacked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixUpdate {
    /// The fix.
    pub fix: Fix,
    /// Which velocity components it measures (north, east, down).
    pub measured: [bool; 3],
}

impl FixUpdate {
    /// The update by every component `fix` has.
    pub fn whole(fix: Fix) -> Self {
        FixUpdate {
            fix,
            measured: [true; 3],
        }
    }
}

impl<const N: usize> Measurement<N> for FixUpdate {
    fn t_s(&self) -> f64 {
        self.fix.t_s
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        Measurement::<N>::rows(&Position(self.fix), at, rows);
        let v = Velocity {
            fix: self.fix,
            measured: self.measured,
        };
        Measurement::<N>::rows(&v, at, rows);
    }
}
