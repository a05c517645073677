//! The Rauch–Tung–Striebel smoother over the fixes of a closed-loop error-state filter.
//!
//! Between two updates the filter's solution is the mechanization of the one after the
//! earlier update, so the RTS recursion (Rauch, Tung & Striebel, AIAA J. 3(8), 1965; Groves
//! (2013) §3.4.3) runs on the errors of those solutions. With e⁺_k the error of the solution
//! after update k (estimated 0 by the filter, covariance P⁺_k), e⁻_{k+1} = Φ_k e⁺_k + w the
//! error before update k+1 (covariance P⁻_{k+1}), and the update taking out δx̂_k (so that
//! e⁻_k = e⁺_k + δx̂_k to first order):
//!
//! - C_k = P⁺_k Φ_kᵀ (P⁻_{k+1})⁻¹;
//! - ê⁺_k = C_k ê⁻_{k+1}, with ê⁻_N = δx̂_N at the last fix;
//! - ê⁻_k = ê⁺_k + δx̂_k;
//! - P^s_k = P⁺_k + C_k (P^s_{k+1} − P⁻_{k+1}) C_kᵀ, P^s_N = P⁺_N;
//!
//! and the smoothed solution at fix k is the filtered one with ê⁺_k taken out, as the filter's
//! own correction does ([`apply_correction`]).

use nalgebra::{SVector, Vector3};

use super::run::FixRecord;
use crate::ins::error_state::{STATES, Square, holds, start_of};
use crate::ins::filter::apply_correction;
use crate::ins::mech::Pva;
use crate::ins::state::Block;

/// The smoothed solution at one fix.
#[derive(Clone, Debug, PartialEq)]
pub struct Smoothed<const N: usize = STATES> {
    /// Position, velocity and attitude.
    pub pva: Pva,
    /// The gyro biases, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer biases, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The gyro scale factors (zero without the scale states).
    pub gyro_scale: Vector3<f64>,
    /// The accelerometer scale factors (zero without the scale states).
    pub accel_scale: Vector3<f64>,
    /// The covariance of its errors.
    pub covariance: Square<N>,
}

/// The smoothed solution at every fix of `records`, in their order.
pub fn smooth<const N: usize>(records: &[FixRecord<N>]) -> Vec<Smoothed<N>> {
    let n = records.len();
    let mut out = Vec::with_capacity(n);
    let Some(last) = records.last() else {
        return out;
    };
    // ê⁻ and P^s of the fix after the current one.
    let mut e_prior: SVector<f64, N> = last.correction;
    let mut p_next = last.covariance;
    out.push(smoothed(last, &SVector::zeros(), last.covariance));
    for k in (0..n - 1).rev() {
        let (r, next) = (&records[k], &records[k + 1]);
        // C = P⁺Φᵀ(P⁻)⁻¹ from P⁻Cᵀ = ΦP⁺ (P⁻ symmetric positive definite).
        let phi_p = next.transition * r.covariance;
        let c_t = match next.prior_covariance.cholesky() {
            Some(ch) => ch.solve(&phi_p),
            None => Square::<N>::zeros(),
        };
        let c = c_t.transpose();
        let e_post = c * e_prior;
        let p = r.covariance + c * (p_next - next.prior_covariance) * c_t;
        let p = (p + p.transpose()) * 0.5;
        out.push(smoothed(r, &e_post, p));
        e_prior = e_post + r.correction;
        p_next = p;
    }
    out.reverse();
    out
}

/// The filtered solution of `r` with the smoothed errors `e` taken out.
fn smoothed<const N: usize>(
    r: &FixRecord<N>,
    e: &SVector<f64, N>,
    covariance: Square<N>,
) -> Smoothed<N> {
    let (mut pva, mut g, mut a) = (r.pva, r.gyro_bias_rad_s, r.accel_bias_m_s2);
    apply_correction(
        &mut pva,
        &mut g,
        &mut a,
        &e.fixed_rows::<STATES>(0).into_owned(),
    );
    let (mut sg, mut sa) = (r.gyro_scale, r.accel_scale);
    if holds::<N>(Block::GyroScale) {
        sg -= e.fixed_rows::<3>(start_of::<N>(Block::GyroScale));
        sa -= e.fixed_rows::<3>(start_of::<N>(Block::AccelScale));
    }
    Smoothed {
        pva,
        gyro_bias_rad_s: g,
        accel_bias_m_s2: a,
        gyro_scale: sg,
        accel_scale: sa,
        covariance,
    }
}
