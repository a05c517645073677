//! The fixed-interval (Rauch–Tung–Striebel) smoother, run at the fixes and evaluated at any
//! sample from the fix that follows it.
//!
//! # Formula
//! Between two fixes there is no measurement, so P⁺ = P⁻ at every sample in between and the
//! per-sample smoother gains C_j = P_j·Φ_jᵀ·P_{j+1}⁻¹ telescope: from sample k to the next fix b,
//! C_k⋯C_{b−1} = P_k·Φ(t_b − t_k)ᵀ·(P_b⁻)⁻¹. With
//!
//! ```text
//! λ_b = (P_b⁻)⁻¹ (x̂_b^s − x̂_b⁻),   Λ_b = (P_b⁻)⁻¹ (P_b^s − P_b⁻) (P_b⁻)⁻¹
//! ```
//!
//! the smoothed estimate at any sample k before b is
//!
//! ```text
//! x̂_k^s = x̂_k + P_k Φᵀ λ_b,   P_k^s = P_k + P_k Φᵀ Λ_b Φ P_k,   Φ = Φ(t_b − t_k)
//! ```
//!
//! the RTS recursion composed over the interval. At a fix (k = a, x̂_a = x̂_a⁺) it is the
//! fix-level RTS step, which the backward pass runs from the last fix to the first; after the
//! last fix no measurement follows and the smoothed estimate is the filtered one. So the backward
//! pass keeps O(fixes) and every sample's smoothed value costs a few 3×3 products (λ_b and Λ_b
//! once for the samples before each fix).

use crate::state::{StateMatrix, StateVector};

use super::forward::FilteredFix;
use super::symmetric::Symmetric;

/// The smoothed estimate at a fix.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothedFix {
    /// Smoothed estimate x̂^s at the fix.
    pub x: StateVector,
    /// Its covariance P^s.
    pub p: Symmetric,
}

/// What the samples before a fix need of its smoothed estimate: formed when they are reached,
/// not kept at every fix.
pub struct Carry {
    /// λ = (P⁻)⁻¹ (x̂^s − x̂⁻).
    lambda: StateVector,
    /// Λ = (P⁻)⁻¹ (P^s − P⁻) (P⁻)⁻¹.
    big_lambda: StateMatrix,
}

fn symmetric(m: StateMatrix) -> StateMatrix {
    (m + m.transpose()) * 0.5
}

impl SmoothedFix {
    /// The smoothed estimate at the fix `f`, carried to the samples before it.
    pub fn carry(&self, f: &FilteredFix) -> Carry {
        let inv = f.p_prior_inv();
        Carry {
            lambda: inv * (self.x - f.prior),
            big_lambda: symmetric(inv * (self.p.matrix() - f.p_prior.matrix()) * inv),
        }
    }
}

impl Carry {
    /// The smoothed estimate and covariance at a sample whose filtered ones are `x`, `p`, with
    /// this fix the next one after it and `phi` the transition from the sample to this fix.
    pub fn smooth(
        &self,
        x: &StateVector,
        p: &StateMatrix,
        phi: &StateMatrix,
    ) -> (StateVector, StateMatrix) {
        let g = p * phi.transpose();
        (
            x + g * self.lambda,
            symmetric(p + g * self.big_lambda * g.transpose()),
        )
    }
}

/// The backward pass over the fixes, last to first: the smoothed estimate at every fix.
pub fn backward(fixes: &[FilteredFix]) -> Vec<SmoothedFix> {
    let mut out: Vec<SmoothedFix> = Vec::with_capacity(fixes.len());
    for (i, f) in fixes.iter().enumerate().rev() {
        let smoothed = match fixes.get(i + 1) {
            // At the last fix nothing follows: smoothed = filtered.
            None => SmoothedFix {
                x: f.post,
                p: f.p_post,
            },
            Some(next) => {
                let after = out.last().expect("the later fix was smoothed first");
                let (x, p) =
                    after
                        .carry(next)
                        .smooth(&f.post, &f.p_post.matrix(), &next.phi_from_previous);
                SmoothedFix {
                    x,
                    p: Symmetric::of(&p),
                }
            }
        };
        out.push(smoothed);
    }
    out.reverse();
    out
}
