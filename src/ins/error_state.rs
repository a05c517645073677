//! The INS error state of 15, or 21 with the sensors' scale factors, and its continuous-time
//! dynamics F(t), linearized about the navigation solution.
//!
//! Every error is the estimate minus the truth (Groves §14.2): δr^n the position error in NED
//! metres (δr_N = (R_N + h)δL, δr_E = (R_E + h)cos L·δλ, δr_D = −δh), δv^n the velocity error,
//! δψ the attitude error with Ĉ_b^n = (I + \[δψ×\])C_b^n (to first order), δb_g and δb_a the gyro
//! and accelerometer bias errors, and in the 21-state form δs_g and δs_a the errors of the six
//! scale factors (each sensor reads (1 + s)·x + b + noise per axis). The sensors are compensated
//! by the estimates, x̂ = (x̃ − b̂)/(1 + ŝ) per axis (KF-GINS's `imuCompensate`), so to first order
//! ω̂_ib^b − ω_ib^b = −δb_g − diag(ω_ib^b)·δs_g and f̂^b − f^b = −δb_a − diag(f^b)·δs_a (plus
//! their white noise; Groves §14.2.4 with the scale-factor columns of §14.2.6's augmented state).
//!
//! F is the exact Jacobian of the NED navigation equations (Groves §5.4: ṗ = (v_N/(R_N + h),
//! v_E/((R_E + h)cos L), −v_D), v̇^n = C_b^n f^b + g^n − (2ω_ie^n + ω_en^n) × v^n,
//! Ċ_b^n = C_b^n\[ω_ib^b×\] − \[ω_in^n×\]C_b^n) in these coordinates: the error equations of Groves
//! §14.2.4 with every curvature, Earth-rate, transport-rate and gravity-gradient term kept, and
//! the position block carried from curvilinear to NED metres through T = diag(R_N + h,
//! (R_E + h)cos L, −1): F_rr = ṪT⁻¹ + T·F_pp·T⁻¹.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::earth::{self, Geodetic};
use super::mech::{Pva, skew};
use super::state::{Block, Layout};

/// The number of error states ([`Layout::CORE`]).
pub const STATES: usize = Layout::CORE.dim();
/// The number of error states with the scale factors ([`Layout::WITH_SCALE`]).
pub const STATES_WITH_SCALE: usize = Layout::WITH_SCALE.dim();
/// The first index of δr^n (NED, m): [`Block::Position`]'s offset.
pub const POSITION: usize = core(Block::Position);
/// The first index of δv^n (NED, m/s).
pub const VELOCITY: usize = core(Block::Velocity);
/// The first index of δψ (rad).
pub const ATTITUDE: usize = core(Block::Attitude);
/// The first index of δb_g (body axes, rad/s).
pub const GYRO_BIAS: usize = core(Block::GyroBias);
/// The first index of δb_a (body axes, m/s²).
pub const ACCEL_BIAS: usize = core(Block::AccelBias);

/// Where a block every layout holds starts (at the same place in each).
const fn core(block: Block) -> usize {
    Layout::CORE.offset(block).unwrap()
}

/// Where `block` starts in an error state of `N`; panics if it does not hold it (ask
/// [`holds`] first).
pub const fn start_of<const N: usize>(block: Block) -> usize {
    match offset_of::<N>(block) {
        Some(at) => at,
        None => panic!("the error state does not hold the block"),
    }
}

/// Whether an error state of `N` holds `block`.
pub const fn holds<const N: usize>(block: Block) -> bool {
    Layout::of::<N>().has(block)
}

/// Where the optional `block` starts in an error state of `N`, if it holds it.
pub const fn offset_of<const N: usize>(block: Block) -> Option<usize> {
    Layout::of::<N>().offset(block)
}

/// A square matrix over the error state.
pub type Matrix15 = SMatrix<f64, STATES, STATES>;

/// A square matrix over an error state of `N` (15 or 21).
pub type Square<const N: usize> = SMatrix<f64, N, N>;

/// The sensed motion F's entries are linear in (each a mean over the steps of a covariance
/// interval, or one step's value).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// C_b^n.
    pub c: Matrix3<f64>,
    /// C_b^n·f^b, m/s².
    pub f_n: Vector3<f64>,
    /// C_b^n·diag(f^b), m/s²: the accelerometer scale factors' column block.
    pub c_f: Matrix3<f64>,
    /// C_b^n·diag(ω_ib^b), rad/s: the gyro scale factors' column block.
    pub c_w: Matrix3<f64>,
}

impl Motion {
    /// The motion of one step at attitude `c` with specific force `f_b` and rate `w_b`.
    pub fn of(c: &Matrix3<f64>, f_b: &Vector3<f64>, w_b: &Vector3<f64>) -> Self {
        Motion {
            c: *c,
            f_n: c * f_b,
            c_f: c * Matrix3::from_diagonal(f_b),
            c_w: c * Matrix3::from_diagonal(w_b),
        }
    }
}

/// How each bias group decays: 1/τ of a Gauss–Markov bias, 0 for a constant or a random walk, in
/// 1/s.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BiasDecay {
    /// The gyro biases' 1/τ, 1/s.
    pub gyro_per_s: f64,
    /// The accelerometer biases' 1/τ, 1/s.
    pub accel_per_s: f64,
}

/// The Jacobians of the frame rates and of the velocity equation with respect to position
/// (curvilinear: L, λ, h) and velocity.
struct RateJacobians {
    /// ∂ṗ/∂p (rows L̇, λ̇, ḣ).
    position_rate_p: Matrix3<f64>,
    /// ∂ω_in^n/∂p.
    nav_rate_p: Matrix3<f64>,
    /// ∂ω_in^n/∂v (also ∂ω_en^n/∂v).
    nav_rate_v: Matrix3<f64>,
    /// ∂(2ω_ie^n + ω_en^n)/∂p.
    coriolis_p: Matrix3<f64>,
}

/// The partial derivatives of the frame rates at `p` for velocity `v`.
///
/// # Formula
/// With R_n = R_N + h, R_e = R_E + h, ω = ω_ie: ω_in^n = (ω cos L + v_E/R_e, −v_N/R_n,
/// −ω sin L − v_E tan L/R_e) (Groves §5.4), differentiated term by term; the radii's rates from
/// [`earth::radii_rate_m_per_rad`].
fn rate_jacobians(p: &Geodetic, v: &Vector3<f64>, w: f64) -> RateJacobians {
    let (rn0, re0) = earth::radii_m(p.lat_rad);
    let (drn, dre) = earth::radii_rate_m_per_rad(p.lat_rad);
    let (rn, re) = (rn0 + p.height_m, re0 + p.height_m);
    let (sl, cl) = p.lat_rad.sin_cos();
    let tl = sl / cl;
    let (vn, ve) = (v.x, v.y);
    // Transport rate ω_en^n = (v_E/R_e, −v_N/R_n, −v_E tan L/R_e) by L and h.
    let en_lat = Vector3::new(
        -ve * dre / (re * re),
        vn * drn / (rn * rn),
        -ve * (re / (cl * cl) - tl * dre) / (re * re),
    );
    let en_h = Vector3::new(-ve / (re * re), vn / (rn * rn), ve * tl / (re * re));
    let ie_lat = Vector3::new(-w * sl, 0.0, -w * cl);
    let columns =
        |lat: Vector3<f64>, h: Vector3<f64>| Matrix3::from_columns(&[lat, Vector3::zeros(), h]);
    let nav_rate_v = Matrix3::new(0.0, 1.0 / re, 0.0, -1.0 / rn, 0.0, 0.0, 0.0, -tl / re, 0.0);
    let position_rate_p = Matrix3::new(
        -vn * drn / (rn * rn),
        0.0,
        -vn / (rn * rn),
        -ve * (dre * cl - re * sl) / (re * re * cl * cl),
        0.0,
        -ve / (re * re * cl),
        0.0,
        0.0,
        0.0,
    );
    RateJacobians {
        position_rate_p,
        nav_rate_p: columns(ie_lat + en_lat, en_h),
        nav_rate_v,
        coriolis_p: columns(2.0 * ie_lat + en_lat, en_h),
    }
}

/// The error dynamics F at the navigation solution `pva` with the compensated specific force
/// `f_b` (body axes, m/s²).
pub fn dynamics(pva: &Pva, f_b: &Vector3<f64>, decay: &BiasDecay) -> Matrix15 {
    let c = *pva.attitude.to_rotation_matrix().matrix();
    dynamics_with(pva, &c, &(c * f_b), decay)
}

/// F with the attitude's blocks from `c` (C_b^n) and the specific force's from `f_n` (NED):
/// F's entries are linear in C_b^n and f^n, so F averaged over several IMU steps is this with
/// their means (Groves §14.2.4's blocks; the position- and velocity-dependent ones from `pva`).
pub fn dynamics_with(
    pva: &Pva,
    c: &Matrix3<f64>,
    f_n: &Vector3<f64>,
    decay: &BiasDecay,
) -> Matrix15 {
    dynamics_rotating(pva, c, f_n, decay, earth::ROTATION_RATE_RAD_S)
}

/// [`dynamics_with`] on an Earth turning at `rotation_rad_s` (0: the error dynamics of a
/// mechanization that leaves the Earth's rate out).
pub fn dynamics_rotating(
    pva: &Pva,
    c: &Matrix3<f64>,
    f_n: &Vector3<f64>,
    decay: &BiasDecay,
    rotation_rad_s: f64,
) -> Matrix15 {
    let motion = Motion {
        c: *c,
        f_n: *f_n,
        c_f: Matrix3::zeros(),
        c_w: Matrix3::zeros(),
    };
    dynamics_of(pva, &motion, decay, rotation_rad_s)
}

/// F over an error state of `N` (15, or 21 with the scale factors) for the sensed `motion`, on
/// an Earth turning at `rotation_rad_s`. The scale factors' columns: δv̇ ∋ −C_b^n·diag(f^b)·δs_a,
/// δψ̇ ∋ −C_b^n·diag(ω_ib^b)·δs_g (the module's compensation, to first order); the scale factors
/// are constants (their rows zero).
pub fn dynamics_of<const N: usize>(
    pva: &Pva,
    motion: &Motion,
    decay: &BiasDecay,
    rotation_rad_s: f64,
) -> Square<N> {
    let (c, f_n) = (motion.c, &motion.f_n);
    let p = &pva.position;
    let v = pva.velocity_ned_m_s;
    let (rn0, re0) = earth::radii_m(p.lat_rad);
    let (drn, dre) = earth::radii_rate_m_per_rad(p.lat_rad);
    let (rn, re) = (rn0 + p.height_m, re0 + p.height_m);
    let (sl, cl) = p.lat_rad.sin_cos();
    let j = rate_jacobians(p, &v, rotation_rad_s);

    // NED metres from curvilinear errors: δr = T·δp, and T's rate along the solution.
    let t = Matrix3::from_diagonal(&Vector3::new(rn, re * cl, -1.0));
    let t_inv = Matrix3::from_diagonal(&Vector3::new(1.0 / rn, 1.0 / (re * cl), -1.0));
    let p_rate = earth::geodetic_rate(p, &v);
    let (dlat, dh) = (p_rate.x, p_rate.z);
    let t_rate = Matrix3::from_diagonal(&Vector3::new(
        drn * dlat + dh,
        (dre * dlat + dh) * cl - re * sl * dlat,
        0.0,
    ));

    // Scaled by exactly 1 on the rotating Earth: the same bits as the free function.
    let w_ie = earth::earth_rate_ned(p.lat_rad) * (rotation_rad_s / earth::ROTATION_RATE_RAD_S);
    let w_en = earth::transport_rate_ned(p, &v);
    let w_in = w_ie + w_en;
    let coriolis = 2.0 * w_ie + w_en;
    let (dg_dlat, dg_dh) = earth::gravity_gradient(p);
    let gravity_p = Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dg_dlat, 0.0, dg_dh);
    let sv = skew(&v);

    let mut f = Square::<N>::zeros();
    let mut set = |row: usize, col: usize, m: Matrix3<f64>| {
        f.fixed_view_mut::<3, 3>(row, col).copy_from(&m);
    };
    set(
        POSITION,
        POSITION,
        t_rate * t_inv + t * j.position_rate_p * t_inv,
    );
    set(POSITION, VELOCITY, Matrix3::identity());
    // v̇ = C f + g − Ω × v with Ω = 2ω_ie + ω_en: −Ω × v = [v×]Ω.
    set(VELOCITY, POSITION, (gravity_p + sv * j.coriolis_p) * t_inv);
    set(VELOCITY, VELOCITY, -skew(&coriolis) + sv * j.nav_rate_v);
    set(VELOCITY, ATTITUDE, -skew(f_n));
    set(VELOCITY, ACCEL_BIAS, -c);
    // δψ̇ = C δω_ib^b − δω_in^n − ω_in^n × δψ (Groves §14.2.4).
    set(ATTITUDE, POSITION, -j.nav_rate_p * t_inv);
    set(ATTITUDE, VELOCITY, -j.nav_rate_v);
    set(ATTITUDE, ATTITUDE, -skew(&w_in));
    set(ATTITUDE, GYRO_BIAS, -c);
    set(
        GYRO_BIAS,
        GYRO_BIAS,
        -decay.gyro_per_s * Matrix3::identity(),
    );
    set(
        ACCEL_BIAS,
        ACCEL_BIAS,
        -decay.accel_per_s * Matrix3::identity(),
    );
    if let Some(at) = const { offset_of::<N>(Block::AccelScale) } {
        set(VELOCITY, at, -motion.c_f);
    }
    if let Some(at) = const { offset_of::<N>(Block::GyroScale) } {
        set(ATTITUDE, at, -motion.c_w);
    }
    f
}
