//! The Earth of the navigation equations: the WGS-84 ellipsoid, its normal gravity, its rotation,
//! and the rates at which the local-level NED frame turns, as pure functions of position and
//! velocity.
//!
//! Constants from NIMA TR8350.2 (3rd ed., 2000), tables 3.1–3.4; radii and rates as in Groves,
//! *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems* (2nd ed., 2013),
//! §2.4 and §5.4.

use nalgebra::{UnitQuaternion, Vector3};

// The position the GNSS readers hand on: defined with them, below this layer.
pub use crate::input::records::{Geodetic, wrap_longitude};

/// Semi-major axis a, m (TR8350.2 table 3.1).
pub const SEMI_MAJOR_AXIS_M: f64 = 6_378_137.0;
/// Flattening f = 1/298.257223563 (TR8350.2 table 3.1).
pub const FLATTENING: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared e² = f(2 − f) (TR8350.2 table 3.3).
pub const ECCENTRICITY_SQUARED: f64 = FLATTENING * (2.0 - FLATTENING);
/// Semi-minor axis b = a(1 − f), m.
pub const SEMI_MINOR_AXIS_M: f64 = SEMI_MAJOR_AXIS_M * (1.0 - FLATTENING);
/// The Earth's rotation rate ω_ie, rad/s (TR8350.2 table 3.1).
pub const ROTATION_RATE_RAD_S: f64 = 7.292_115e-5;
/// The Earth's gravitational constant GM, m³/s² (TR8350.2 table 3.1).
pub const GM_M3_S2: f64 = 3.986_004_418e14;
/// Normal gravity at the equator γ_e, m/s² (TR8350.2 table 3.4).
pub const GRAVITY_EQUATOR_M_S2: f64 = 9.780_325_335_9;
/// Somigliana's constant k = bγ_p/(aγ_e) − 1 (TR8350.2 table 3.4).
pub const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;
/// m = ω²a²b/GM (TR8350.2 table 3.4).
pub const GRAVITY_RATIO_M: f64 = 0.003_449_786_506_84;

/// The meridian radius of curvature R_N and the transverse (prime-vertical) radius R_E at
/// latitude `lat_rad`, m.
///
/// # Formula
/// R_N = a(1 − e²)/(1 − e² sin²L)^{3/2}, R_E = a/√(1 − e² sin²L) (Groves eqs. 2.105, 2.106).
pub fn radii_m(lat_rad: f64) -> (f64, f64) {
    radii_of_sin(lat_rad.sin())
}

/// [`radii_m`] from sin L.
fn radii_of_sin(s: f64) -> (f64, f64) {
    let w2 = 1.0 - ECCENTRICITY_SQUARED * s * s;
    let w = w2.sqrt();
    let transverse = SEMI_MAJOR_AXIS_M / w;
    let meridian = SEMI_MAJOR_AXIS_M * (1.0 - ECCENTRICITY_SQUARED) / (w2 * w);
    (meridian, transverse)
}

/// Normal gravity γ at `p` (the sum of gravitation and the centrifugal acceleration of the
/// Earth's rotation, along the ellipsoid's normal), m/s², positive down.
///
/// # Formula
/// Somigliana on the ellipsoid, γ₀ = γ_e(1 + k sin²L)/√(1 − e² sin²L) (TR8350.2 eq. 4-1), and
/// the free-air term to second order in h, γ = γ₀[1 − (2/a)(1 + f + m − 2f sin²L)h + 3h²/a²]
/// (TR8350.2 eq. 4-3). The small northward component of normal gravity off the ellipsoid
/// (about 8·10⁻⁹·h·sin 2L m/s², Groves ch. 2) is left out, as in Shin (2005) and KF-GINS; the
/// simulated truth uses this same field, so the mechanization's tests are exact.
pub fn normal_gravity_m_s2(p: &Geodetic) -> f64 {
    gravity_of_sin2(p.lat_rad.sin().powi(2), p.height_m)
}

/// [`normal_gravity_m_s2`] from sin²L and h.
fn gravity_of_sin2(s2: f64, h: f64) -> f64 {
    let gamma0 =
        GRAVITY_EQUATOR_M_S2 * (1.0 + SOMIGLIANA_K * s2) / (1.0 - ECCENTRICITY_SQUARED * s2).sqrt();
    let a = SEMI_MAJOR_AXIS_M;
    gamma0
        * (1.0 - 2.0 / a * (1.0 + FLATTENING + GRAVITY_RATIO_M - 2.0 * FLATTENING * s2) * h
            + 3.0 * h * h / (a * a))
}

/// Normal gravity as a vector in NED, m/s²: (0, 0, γ).
pub fn gravity_ned(p: &Geodetic) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, normal_gravity_m_s2(p))
}

/// The Earth's rotation rate resolved in NED at latitude `lat_rad`, ω_ie^n, rad/s.
///
/// # Formula
/// ω_ie^n = ω_ie (cos L, 0, −sin L) (Groves ch. 2, the Earth rate in local-navigation axes).
pub fn earth_rate_ned(lat_rad: f64) -> Vector3<f64> {
    earth_rate_of(lat_rad.sin(), lat_rad.cos())
}

/// [`earth_rate_ned`] from sin L and cos L.
fn earth_rate_of(s: f64, c: f64) -> Vector3<f64> {
    Vector3::new(ROTATION_RATE_RAD_S * c, 0.0, -ROTATION_RATE_RAD_S * s)
}

/// The transport rate ω_en^n: how fast the NED frame turns over the curved Earth as the vehicle
/// moves with velocity `v_ned` (m/s) at `p`, rad/s.
///
/// # Formula
/// ω_en^n = (v_E/(R_E + h), −v_N/(R_N + h), −v_E tan L/(R_E + h)) (Groves eq. 5.44).
pub fn transport_rate_ned(p: &Geodetic, v_ned: &Vector3<f64>) -> Vector3<f64> {
    let (rn, re) = radii_m(p.lat_rad);
    let h = p.height_m;
    transport_rate_of(rn + h, re + h, p.lat_rad.tan(), v_ned)
}

/// [`transport_rate_ned`] from R_N + h, R_E + h and tan L.
fn transport_rate_of(rn_h: f64, re_h: f64, tan: f64, v_ned: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v_ned.y / re_h, -v_ned.x / rn_h, -v_ned.y * tan / re_h)
}

/// λ_a − λ_b wrapped into (−π, π], rad: the shorter way round between two meridians.
pub fn longitude_difference(a_rad: f64, b_rad: f64) -> f64 {
    wrap_longitude(a_rad - b_rad)
}

/// `p` moved by `d_ned_m` metres north, east and down (first order in d/R: the lever arm, a
/// fix's noise, a prior's draw).
pub fn offset(p: &Geodetic, d_ned_m: &Vector3<f64>) -> Geodetic {
    let (rn, re) = radii_m(p.lat_rad);
    Geodetic {
        lat_rad: p.lat_rad + d_ned_m.x / (rn + p.height_m),
        lon_rad: wrap_longitude(p.lon_rad + d_ned_m.y / ((re + p.height_m) * p.lat_rad.cos())),
        height_m: p.height_m - d_ned_m.z,
    }
}

/// The rate of change of latitude, longitude and height for a velocity `v_ned`:
/// (dL/dt, dλ/dt, dh/dt), rad/s, rad/s, m/s.
///
/// # Formula
/// L̇ = v_N/(R_N + h), λ̇ = v_E/((R_E + h) cos L), ḣ = −v_D (Groves ch. 2, curvilinear position).
pub fn geodetic_rate(p: &Geodetic, v_ned: &Vector3<f64>) -> Vector3<f64> {
    let (rn, re) = radii_m(p.lat_rad);
    let h = p.height_m;
    geodetic_rate_of(rn + h, re + h, p.lat_rad.cos(), v_ned)
}

/// [`geodetic_rate`] from R_N + h, R_E + h and cos L.
fn geodetic_rate_of(rn_h: f64, re_h: f64, c: f64, v_ned: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v_ned.x / rn_h, v_ned.y / (re_h * c), -v_ned.z)
}

/// The Earth at one point, from one sine and cosine of its latitude: what the free functions
/// give ([`earth_rate_ned`], [`transport_rate_ned`], [`geodetic_rate`], [`gravity_ned`]), by
/// the same formulas, for a caller that asks several of them at a point (the mechanization asks
/// them at three points a step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    sin_lat: f64,
    cos_lat: f64,
    /// R_N + h, m.
    rn_h: f64,
    /// R_E + h, m.
    re_h: f64,
    /// Normal gravity γ, m/s².
    gravity_m_s2: f64,
    /// The Earth's rotation rate this point turns with, rad/s: [`ROTATION_RATE_RAD_S`], or 0
    /// for a mechanization that leaves it out (a negative control).
    rotation_rad_s: f64,
}

impl Local {
    /// The Earth at `p`.
    pub fn at(p: &Geodetic) -> Self {
        Self::rotating_at(p, ROTATION_RATE_RAD_S)
    }

    /// The Earth at `p`, turning at `rotation_rad_s` (0: a non-rotating Earth).
    pub fn rotating_at(p: &Geodetic, rotation_rad_s: f64) -> Self {
        let (s, c) = p.lat_rad.sin_cos();
        let (rn, re) = radii_of_sin(s);
        Local {
            sin_lat: s,
            cos_lat: c,
            rn_h: rn + p.height_m,
            re_h: re + p.height_m,
            gravity_m_s2: gravity_of_sin2(s * s, p.height_m),
            rotation_rad_s,
        }
    }

    /// The rotation rate this point turns with, rad/s.
    pub fn rotation_rad_s(&self) -> f64 {
        self.rotation_rad_s
    }

    /// ω_ie^n, rad/s (Groves eq. 5.41).
    pub fn earth_rate_ned(&self) -> Vector3<f64> {
        let w = self.rotation_rad_s;
        Vector3::new(w * self.cos_lat, 0.0, -w * self.sin_lat)
    }

    /// ω_en^n for a velocity `v_ned`, rad/s.
    pub fn transport_rate_ned(&self, v_ned: &Vector3<f64>) -> Vector3<f64> {
        transport_rate_of(self.rn_h, self.re_h, self.sin_lat / self.cos_lat, v_ned)
    }

    /// (dL/dt, dλ/dt, dh/dt) for a velocity `v_ned`.
    pub fn geodetic_rate(&self, v_ned: &Vector3<f64>) -> Vector3<f64> {
        geodetic_rate_of(self.rn_h, self.re_h, self.cos_lat, v_ned)
    }

    /// Normal gravity in NED, m/s².
    pub fn gravity_ned(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, self.gravity_m_s2)
    }
}

/// The attitude of the NED frame at `p` with respect to the Earth-fixed (ECEF) frame, q_n^e:
/// a vector's NED components to its ECEF components.
///
/// # Formula
/// C_n^e = R_z(λ)·R_y(−L − π/2), the transpose of Groves eq. 2.150.
pub fn nav_to_earth(lat_rad: f64, lon_rad: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), lon_rad)
        * UnitQuaternion::from_axis_angle(
            &Vector3::y_axis(),
            -lat_rad - std::f64::consts::FRAC_PI_2,
        )
}

/// Latitude and longitude from q_n^e (the inverse of [`nav_to_earth`]), rad.
///
/// # Formula
/// From C_n^e's third row (cos L, 0, −sin L) and first two columns' second elements
/// (C₀₁ = −sin λ, C₁₁ = cos λ): L = atan2(−C₂₂, C₂₀), λ = atan2(−C₀₁, C₁₁).
pub fn lat_lon_of(q_ne: &UnitQuaternion<f64>) -> (f64, f64) {
    let c = q_ne.to_rotation_matrix();
    let c = c.matrix();
    ((-c[(2, 2)]).atan2(c[(2, 0)]), (-c[(0, 1)]).atan2(c[(1, 1)]))
}

/// ECEF coordinates of `p`, m.
///
/// # Formula
/// x = (R_E + h) cos L cos λ, y = (R_E + h) cos L sin λ, z = ((1 − e²)R_E + h) sin L (Groves
/// eq. 2.112).
pub fn ecef_m(p: &Geodetic) -> Vector3<f64> {
    let (_, re) = radii_m(p.lat_rad);
    let (sl, cl) = p.lat_rad.sin_cos();
    let (so, co) = p.lon_rad.sin_cos();
    Vector3::new(
        (re + p.height_m) * cl * co,
        (re + p.height_m) * cl * so,
        ((1.0 - ECCENTRICITY_SQUARED) * re + p.height_m) * sl,
    )
}

/// The radii's rates of change with latitude, (dR_N/dL, dR_E/dL), m/rad.
///
/// # Formula
/// With W² = 1 − e² sin²L: dR_N/dL = 3a(1 − e²)e² sin L cos L/W⁵, dR_E/dL = a e² sin L cos L/W³
/// (the derivatives of Groves eqs. 2.105 and 2.106).
pub fn radii_rate_m_per_rad(lat_rad: f64) -> (f64, f64) {
    let (s, c) = lat_rad.sin_cos();
    let w2 = 1.0 - ECCENTRICITY_SQUARED * s * s;
    let w = w2.sqrt();
    let e2sc = ECCENTRICITY_SQUARED * s * c;
    (
        3.0 * SEMI_MAJOR_AXIS_M * (1.0 - ECCENTRICITY_SQUARED) * e2sc / (w2 * w2 * w),
        SEMI_MAJOR_AXIS_M * e2sc / (w2 * w),
    )
}

/// The gradient of normal gravity, (∂γ/∂L, ∂γ/∂h), in m/s² per rad and per m.
///
/// # Formula
/// The derivatives of [`normal_gravity_m_s2`]'s γ = γ₀(L)·P(L, h):
/// γ₀′ = γ_e[2k sin L cos L/W + (1 + k sin²L)e² sin L cos L/W³], ∂P/∂L = 8f sin L cos L·h/a,
/// ∂P/∂h = −(2/a)(1 + f + m − 2f sin²L) + 6h/a².
pub fn gravity_gradient(p: &Geodetic) -> (f64, f64) {
    let (s, c) = p.lat_rad.sin_cos();
    let s2 = s * s;
    let w2 = 1.0 - ECCENTRICITY_SQUARED * s2;
    let w = w2.sqrt();
    let gamma0 = GRAVITY_EQUATOR_M_S2 * (1.0 + SOMIGLIANA_K * s2) / w;
    let dgamma0 = GRAVITY_EQUATOR_M_S2
        * (2.0 * SOMIGLIANA_K * s * c / w
            + (1.0 + SOMIGLIANA_K * s2) * ECCENTRICITY_SQUARED * s * c / (w2 * w));
    let (a, h) = (SEMI_MAJOR_AXIS_M, p.height_m);
    let free_air = 1.0 + FLATTENING + GRAVITY_RATIO_M - 2.0 * FLATTENING * s2;
    let poly = 1.0 - 2.0 / a * free_air * h + 3.0 * h * h / (a * a);
    let dpoly_dlat = 8.0 * FLATTENING * s * c * h / a;
    let dpoly_dh = -2.0 / a * free_air + 6.0 * h / (a * a);
    (dgamma0 * poly + gamma0 * dpoly_dlat, gamma0 * dpoly_dh)
}
