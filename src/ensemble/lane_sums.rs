//! The running sums of one fix of a chunk kept per lane: each lane of every lane group of the
//! chunk adds its realization's fix into its own column, with no branch and no reduction, and the
//! lanes are added up once (see [`Lanes::sum`]), when every group has passed the fix.
// Lane loops index several arrays by the lane k; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use super::sums::{FixSums, StageSums};
use crate::filter::{FilterSchedule, Matrix3};
use crate::lanes::Lanes;

/// Upper-triangle index pairs of a symmetric 3×3 matrix, in [`StageSums::ee`] order.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// What every engine hands over at one fix, for a lane group: the true error state, the
/// estimates and the residual (inactive lanes all zero).
#[derive(Clone, Copy, Debug)]
pub struct LaneFix {
    /// δx(t_i).
    pub delta_x: [Lanes; 3],
    /// δx̂(t_i⁻).
    pub prior: [Lanes; 3],
    /// δx̂(t_i⁺).
    pub post: [Lanes; 3],
    /// r(t_i).
    pub residual: [Lanes; 2],
}

/// One stage's sums per lane; fields as in [`StageSums`]. The normalized estimation error
/// squared is not summed per lane: Σ eᵀP⁻¹e = Σ_k w_k·(Σ e·eᵀ)_k, with one P per fix, so it is
/// formed from the lanes' Σ e·eᵀ when they are added up.
#[derive(Clone, Copy, Debug, Default)]
struct LaneStage {
    e: [Lanes; 3],
    ee: [Lanes; 6],
    /// Σ e·δx̂ᵀ, column-major like [`Matrix3`].
    ex: [Lanes; 9],
    x: [Lanes; 3],
    xx: [Lanes; 3],
}

/// `*s = v` for the first lane group of a fix (`FIRST`), `*s += v` for the others: the sums of
/// a fix start from the first group's values, with no zeroing.
#[inline(always)]
fn put<const FIRST: bool>(s: &mut Lanes, v: Lanes) {
    if FIRST {
        *s = v;
    } else {
        *s += v;
    }
}

impl LaneStage {
    /// Adds e = δx − δx̂ for the estimate `x` (see [`put`] for `FIRST`).
    #[inline(always)]
    fn add<const FIRST: bool>(&mut self, delta_x: &[Lanes; 3], x: &[Lanes; 3]) {
        let e = [delta_x[0] - x[0], delta_x[1] - x[1], delta_x[2] - x[2]];
        for (s, &(r, c)) in self.ee.iter_mut().zip(UPPER.iter()) {
            put::<FIRST>(s, e[r] * e[c]);
        }
        for c in 0..3 {
            for r in 0..3 {
                put::<FIRST>(&mut self.ex[3 * c + r], e[r] * x[c]);
            }
            put::<FIRST>(&mut self.e[c], e[c]);
            put::<FIRST>(&mut self.x[c], x[c]);
            put::<FIRST>(&mut self.xx[c], x[c] * x[c]);
        }
    }

    /// Adds the lanes' totals (see [`Lanes::sum`]) to `s`, and Σ eᵀP⁻¹e formed from them
    /// with the weights `w` of eᵀP⁻¹e over the upper triangle (off-diagonal terms doubled).
    #[inline(always)]
    fn reduce_into(&self, s: &mut StageSums, w: &[f64; 6]) {
        for k in 0..3 {
            s.e[k] += self.e[k].sum();
            s.x[k] += self.x[k].sum();
            s.xx[k] += self.xx[k].sum();
        }
        let mut nees = 0.0;
        for (k, &(r, c)) in UPPER.iter().enumerate() {
            let ee = self.ee[k].sum();
            s.ee[(r, c)] += ee;
            if r != c {
                s.ee[(c, r)] += ee;
            }
            nees += w[k] * ee;
        }
        s.nees += nees;
        // Column-major, like the lane layout; no closure, so that it is compiled into the caller.
        for (k, v) in self.ex.iter().enumerate() {
            s.ex[(k % 3, k / 3)] += v.sum();
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct LaneFixSums {
    prior: LaneStage,
    post: LaneStage,
    nis: Lanes,
}

/// The weights of the quadratic forms at one fix.
#[derive(Clone, Copy, Debug)]
struct Weights {
    prior: [f64; 6],
    post: [f64; 6],
    /// S⁻¹ as (00, 2·01, 11).
    s: [f64; 3],
}

/// The per-lane sums of the fix being summed, and the weights of every fix's quadratic forms
/// (none until [`LaneSums::set_weights`]).
#[derive(Clone, Debug, Default)]
pub struct LaneSums {
    current: LaneFixSums,
    weights: Vec<Weights>,
}

impl LaneSums {
    /// Takes the weights of the quadratic forms from `schedule`, with empty sums.
    pub fn set_weights(&mut self, schedule: &FilterSchedule) {
        let upper = |m: &Matrix3| {
            std::array::from_fn(|k| {
                let (r, c) = UPPER[k];
                if r == c { m[(r, c)] } else { 2.0 * m[(r, c)] }
            })
        };
        self.current = LaneFixSums::default();
        self.weights.clear();
        self.weights.extend(schedule.fixes.iter().map(|f| Weights {
            prior: upper(&f.p_prior_inv),
            post: upper(&f.p_post_inv),
            s: [f.s_inv[(0, 0)], 2.0 * f.s_inv[(0, 1)], f.s_inv[(1, 1)]],
        }));
    }

    /// Adds a lane group's fix `i`; `FIRST` for the first group of the fix (see [`put`]).
    #[inline(always)]
    pub fn add<const FIRST: bool>(&mut self, i: usize, f: &LaneFix) {
        let w = &self.weights[i];
        let sums = &mut self.current;
        sums.prior.add::<FIRST>(&f.delta_x, &f.prior);
        sums.post.add::<FIRST>(&f.delta_x, &f.post);
        let [r0, r1] = f.residual;
        let nis = Lanes([w.s[0]; 8]) * r0 * r0
            + Lanes([w.s[1]; 8]) * r0 * r1
            + Lanes([w.s[2]; 8]) * r1 * r1;
        put::<FIRST>(&mut sums.nis, nis);
    }

    /// Adds the lanes' totals of fix `i` to `out`; the next fix starts with its first group.
    #[inline(always)]
    pub fn finish_fix(&mut self, i: usize, out: &mut FixSums) {
        let (c, w) = (&self.current, &self.weights[i]);
        c.prior.reduce_into(&mut out.prior, &w.prior);
        c.post.reduce_into(&mut out.post, &w.post);
        out.nis += c.nis.sum();
    }
}
