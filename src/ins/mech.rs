//! Strapdown mechanization in the local-level NED frame on the WGS-84 ellipsoid: one step from
//! the IMU's increments Δv, Δθ over [t_{k−1}, t_k] and the previous step's, in the order velocity,
//! position, attitude (each update uses the ones before it at the interval's midpoint).
//!
//! The algorithm is the two-sample one of Savage, "Strapdown inertial navigation integration
//! algorithm design", J. Guidance, Control and Dynamics 21(1) (attitude: coning) and 21(2)
//! (velocity: rotation and sculling; position: the Earth-to-navigation frame update), 1998, in the
//! local-level form of Shin, *Estimation Techniques for Low-Cost Inertial Navigation* (UCGE
//! report 20219, 2005), §2.2, with Groves (2013) §5.4–5.5 for the frame rates.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::earth::{self, Geodetic, Local, nav_to_earth};

// The increments the IMU readers hand on: defined with them, below this layer.
pub use crate::input::records::Increment;

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

/// The skew-symmetric matrix \[a×\] with \[a×\]b = a × b.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// The rotation of the NED frame with respect to inertial space, ω_in^n = ω_ie^n + ω_en^n, rad/s.
fn nav_rate(e: &Local, v: &Vector3<f64>) -> Vector3<f64> {
    e.earth_rate_ned() + e.transport_rate_ned(v)
}

/// One mechanization step from `pva` at t_{k−1} with the increments `now` over [t_{k−1}, t_k] and
/// `before` over the step before (on the first step, `now` again: exact for constant rates).
pub fn step(pva: &Pva, before: &Increment, now: &Increment) -> Pva {
    step_rotating(pva, before, now, earth::ROTATION_RATE_RAD_S)
}

/// [`step`] on an Earth turning at `rotation_rad_s` (0: a mechanization that leaves the Earth's
/// rate out, the negative control of a filter that forgets it).
pub fn step_rotating(pva: &Pva, before: &Increment, now: &Increment, rotation_rad_s: f64) -> Pva {
    // The Earth at t_{k−1}'s position, for the velocity's and the position's first evaluation.
    let start = Local::rotating_at(&pva.position, rotation_rad_s);
    let velocity = velocity_update(pva, &start, before, now);
    let (position, zeta) = position_update(pva, &start, &velocity, now.dt_s);
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
fn velocity_update(pva: &Pva, start: &Local, before: &Increment, now: &Increment) -> Vector3<f64> {
    let dt = now.dt_s;
    let (dth, dv) = (now.dtheta_rad, now.dvel_m_s);
    let rotation = 0.5 * dth.cross(&dv);
    let sculling = (before.dtheta_rad.cross(&dv) + before.dvel_m_s.cross(&dth)) / 12.0;
    let dv_nav = pva.attitude * (dv + rotation + sculling);
    let v0 = pva.velocity_ned_m_s;
    let increment = |e: &Local, v: &Vector3<f64>| {
        // ω_ie^n and ω_en^n once each for both the frame's turn and the Coriolis term.
        let (w_ie, w_en) = (e.earth_rate_ned(), e.transport_rate_ned(v));
        let zeta = (w_ie + w_en) * dt;
        let specific = dv_nav - 0.5 * zeta.cross(&dv_nav);
        let coriolis = (2.0 * w_ie + w_en).cross(v);
        specific + (e.gravity_ned() - coriolis) * dt
    };
    // The midpoint extrapolated with the frame rates at t_{k−1}, then the increment again there.
    let v_mid = v0 + 0.5 * increment(start, &v0);
    let p_mid = advance(&pva.position, start, &v_mid, 0.5 * dt);
    v0 + increment(&Local::rotating_at(&p_mid, start.rotation_rad_s()), &v_mid)
}

/// The position at t_k from the mean velocity over the step, and the navigation frame's turn
/// ζ = ω_in^n·Δt over the step (at the midpoint, for the attitude update too).
///
/// # Formula
/// C_n^e(t_k) = C_e(k−1)^e(k)·C_n^e(t_{k−1})·C_n(k)^n(k−1): the Earth frame turned by −ω_ie·Δt
/// about its z axis, the navigation frame by ζ = ω_in^n·Δt (the rates at the midpoint); h_k =
/// h_{k−1} − v̄_D·Δt (Savage 1998 part 2, the position update; Shin 2005 §2.2).
fn position_update(
    pva: &Pva,
    start: &Local,
    v_now: &Vector3<f64>,
    dt: f64,
) -> (Geodetic, Vector3<f64>) {
    let v_mean = 0.5 * (pva.velocity_ned_m_s + v_now);
    let p_mid = advance(&pva.position, start, &v_mean, 0.5 * dt);
    let w = start.rotation_rad_s();
    let zeta = nav_rate(&Local::rotating_at(&p_mid, w), &v_mean) * dt;
    let mut q_ne = earth_turn(-dt, w)
        * nav_to_earth(pva.position.lat_rad, pva.position.lon_rad)
        * rotation(&zeta);
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
    let mut q = rotation(&-*zeta) * pva.attitude * rotation(&phi);
    q.renormalize();
    q
}

/// The Earth frame's turn over `dt` seconds about its z axis, as C_e(t)^e(t+dt) for dt < 0.
fn earth_turn(dt: f64, rotation_rad_s: f64) -> UnitQuaternion<f64> {
    rotation(&Vector3::new(0.0, 0.0, rotation_rad_s * dt))
}

/// The largest (θ/2)² [`rotation`] takes by its series: θ = 10⁻² rad, where the first term left
/// out, (θ/2)¹⁰/10!, is 3·10⁻³⁰.
const SERIES_HALF_ANGLE_SQUARED: f64 = 2.5e-5;

/// The quaternion of the rotation vector `v`, (cos(θ/2), sin(θ/2)·v/θ) with θ = |v| (Savage 1998
/// part 1, the attitude quaternion's update from the rotation vector): for the small angles of
/// one step (Δθ, ζ, the Earth's turn) by the power series of cos x and (sin x)/x in x = θ/2 to
/// x⁸, which needs no sine, cosine or square root; above 10⁻² rad by the functions.
pub fn rotation(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let x2 = 0.25 * v.norm_squared();
    if x2 > SERIES_HALF_ANGLE_SQUARED {
        return UnitQuaternion::from_scaled_axis(*v);
    }
    let cos = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)));
    // sin(θ/2)/θ = ½·(sin x)/x.
    let sinc = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
    UnitQuaternion::new_unchecked(Quaternion::new(cos, sinc * v.x, sinc * v.y, sinc * v.z))
}

/// `p` (where the Earth is `e`) moved with velocity `v` for `dt` seconds (first order: the
/// midpoint extrapolation).
fn advance(p: &Geodetic, e: &Local, v: &Vector3<f64>, dt: f64) -> Geodetic {
    let r = e.geodetic_rate(v) * dt;
    Geodetic {
        lat_rad: p.lat_rad + r.x,
        lon_rad: earth::wrap_longitude(p.lon_rad + r.y),
        height_m: p.height_m + r.z,
    }
}
