//! Strapdown mechanization in the local-level NED frame on the WGS-84 ellipsoid: one step from
//! the IMU's increments Δv, Δθ over [t_{k−1}, t_k] and the previous step's, in the order velocity,
//! position, attitude (each update uses the ones before it at the interval's midpoint).
//!
//! The algorithm is the two-sample one of Savage, "Strapdown inertial navigation integration
//! algorithm design", J. Guidance, Control and Dynamics 21(1) (attitude: coning) and 21(2)
//! (velocity: rotation and sculling; position: the Earth-to-navigation frame update), 1998, in the
//! local-level form of Shin, *Estimation Techniques for Low-Cost Inertial Navigation* (UCGE
//! report 20219, 2005), §2.2, with Groves (2013) §5.4–5.5 for the frame rates.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::earth::{
    self, Geodetic, earth_rate_ned, geodetic_rate, gravity_ned, nav_to_earth, transport_rate_ned,
};

/// The navigation state: position, velocity and attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pva {
    /// Latitude, longitude and ellipsoidal height.
    pub position: Geodetic,
    /// Velocity with respect to the Earth in NED, m/s.
    pub velocity_ned_m_s: Vector3<f64>,
    /// Attitude q_b^n: a vector's body components (forward-right-down) to its NED components
    /// (Hamilton product, scalar first).
    pub attitude: UnitQuaternion<f64>,
}

/// What the IMU measured over one step ending at t_k: the integrals of its angular rate and of
/// its specific force in body axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Increment {
    /// Δθ = ∫ω_ib^b dt, rad.
    pub dtheta_rad: Vector3<f64>,
    /// Δv = ∫f^b dt, m/s.
    pub dvel_m_s: Vector3<f64>,
    /// t_k − t_{k−1}, s.
    pub dt_s: f64,
}

/// The skew-symmetric matrix \[a×\] with \[a×\]b = a × b.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// The rotation of the NED frame with respect to inertial space, ω_in^n = ω_ie^n + ω_en^n, rad/s.
fn nav_rate(p: &Geodetic, v: &Vector3<f64>) -> Vector3<f64> {
    earth_rate_ned(p.lat_rad) + transport_rate_ned(p, v)
}

/// One mechanization step from `pva` at t_{k−1} with the increments `now` over [t_{k−1}, t_k] and
/// `before` over the step before (on the first step, `now` again: exact for constant rates).
pub fn step(pva: &Pva, before: &Increment, now: &Increment) -> Pva {
    let velocity = velocity_update(pva, before, now);
    let (position, zeta) = position_update(pva, &velocity, now.dt_s);
    let attitude = attitude_update(pva, &zeta, before, now);
    Pva {
        position,
        velocity_ned_m_s: velocity,
        attitude,
    }
}

/// The velocity at t_k.
///
/// # Formula
/// Δv_f^b = Δv_k + ½Δθ_k × Δv_k + (Δθ_{k−1} × Δv_k + Δv_{k−1} × Δθ_k)/12 (rotation and two-sample
/// sculling for equal steps, Savage 1998 part 2);
/// v_k = v_{k−1} + (I − ½\[ζ×\])C_b^n(t_{k−1})Δv_f^b + (g^n − (2ω_ie^n + ω_en^n) × v)·Δt with
/// ζ = ω_in^n·Δt and the frame rates, g and v at the interval's midpoint (extrapolated from
/// t_{k−1}, then recomputed once; Shin 2005 §2.2).
fn velocity_update(pva: &Pva, before: &Increment, now: &Increment) -> Vector3<f64> {
    let dt = now.dt_s;
    let (dth, dv) = (now.dtheta_rad, now.dvel_m_s);
    let rotation = 0.5 * dth.cross(&dv);
    let sculling = (before.dtheta_rad.cross(&dv) + before.dvel_m_s.cross(&dth)) / 12.0;
    let dv_nav = pva.attitude * (dv + rotation + sculling);
    let v0 = pva.velocity_ned_m_s;
    let increment = |p: &Geodetic, v: &Vector3<f64>| {
        // ω_ie^n and ω_en^n once each for both the frame's turn and the Coriolis term.
        let (w_ie, w_en) = (earth_rate_ned(p.lat_rad), transport_rate_ned(p, v));
        let zeta = (w_ie + w_en) * dt;
        let specific = dv_nav - 0.5 * zeta.cross(&dv_nav);
        let coriolis = (2.0 * w_ie + w_en).cross(v);
        specific + (gravity_ned(p) - coriolis) * dt
    };
    // The midpoint extrapolated with the frame rates at t_{k−1}, then the increment again there.
    let v_mid = v0 + 0.5 * increment(&pva.position, &v0);
    let p_mid = advance(&pva.position, &v_mid, 0.5 * dt);
    v0 + increment(&p_mid, &v_mid)
}

/// The position at t_k from the mean velocity over the step, and the navigation frame's turn
/// ζ = ω_in^n·Δt over the step (at the midpoint, for the attitude update too).
///
/// # Formula
/// C_n^e(t_k) = C_e(k−1)^e(k)·C_n^e(t_{k−1})·C_n(k)^n(k−1): the Earth frame turned by −ω_ie·Δt
/// about its z axis, the navigation frame by ζ = ω_in^n·Δt (the rates at the midpoint); h_k =
/// h_{k−1} − v̄_D·Δt (Savage 1998 part 2, the position update; Shin 2005 §2.2).
fn position_update(pva: &Pva, v_now: &Vector3<f64>, dt: f64) -> (Geodetic, Vector3<f64>) {
    let v_mean = 0.5 * (pva.velocity_ned_m_s + v_now);
    let p_mid = advance(&pva.position, &v_mean, 0.5 * dt);
    let zeta = nav_rate(&p_mid, &v_mean) * dt;
    let mut q_ne = earth_turn(-dt)
        * nav_to_earth(pva.position.lat_rad, pva.position.lon_rad)
        * UnitQuaternion::from_scaled_axis(zeta);
    q_ne.renormalize();
    let (lat_rad, lon_rad) = earth::lat_lon_of(&q_ne);
    let position = Geodetic {
        lat_rad,
        lon_rad,
        height_m: pva.position.height_m - v_mean.z * dt,
    };
    (position, zeta)
}

/// The attitude at t_k.
///
/// # Formula
/// q_b^n(t_k) = q_n(k−1)^n(k) ⊗ q_b^n(t_{k−1}) ⊗ q_b(k)^b(k−1): the body turned by the rotation
/// vector φ = Δθ_k + Δθ_{k−1} × Δθ_k/12 (two-sample coning for equal steps, Savage 1998 part 1),
/// the navigation frame by ζ = ω_in^n·Δt at the midpoint (Shin 2005 §2.2), the position
/// update's: its midpoint and the mean velocity are the interval's, as Shin's recomputed ones.
fn attitude_update(
    pva: &Pva,
    zeta: &Vector3<f64>,
    before: &Increment,
    now: &Increment,
) -> UnitQuaternion<f64> {
    let phi = now.dtheta_rad + before.dtheta_rad.cross(&now.dtheta_rad) / 12.0;
    let mut q = UnitQuaternion::from_scaled_axis(-*zeta)
        * pva.attitude
        * UnitQuaternion::from_scaled_axis(phi);
    q.renormalize();
    q
}

/// The Earth frame's turn over `dt` seconds about its z axis, as C_e(t)^e(t+dt) for dt < 0.
fn earth_turn(dt: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), earth::ROTATION_RATE_RAD_S * dt)
}

/// `p` moved with velocity `v` for `dt` seconds (first order: the midpoint extrapolation).
fn advance(p: &Geodetic, v: &Vector3<f64>, dt: f64) -> Geodetic {
    let r = geodetic_rate(p, v) * dt;
    Geodetic {
        lat_rad: p.lat_rad + r.x,
        lon_rad: p.lon_rad + r.y,
        height_m: p.height_m + r.z,
    }
}
