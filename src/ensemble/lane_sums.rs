//! The running sums of one fix of a chunk kept per lane: each lane of every lane group of the
//! chunk adds its realization's fix into its own column, with no branch and no reduction, and the
//! lanes are added up once (see [`Lanes::sum`]), when every group has passed the fix.
// Lane loops index several arrays by the lane k; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use nalgebra::SMatrix;

use super::sums::{FixSums, StageSums};
use crate::filter::FilterSchedule;
use crate::lanes::{Lanes, Real};
use crate::state::ErrorState;

/// States of the error state.
const DIM: usize = ErrorState::DIM;
/// Components of a GPS residual.
const MEAS: usize = ErrorState::MEAS;

/// Upper-triangle index pairs (r, c), r ≤ c, of a symmetric D×D matrix, row by row; `L` is
/// D(D + 1)/2.
const fn upper<const D: usize, const L: usize>() -> [(usize, usize); L] {
    let mut pairs = [(0, 0); L];
    let (mut r, mut k) = (0, 0);
    while r < D {
        let mut c = r;
        while c < D {
            pairs[k] = (r, c);
            k += 1;
            c += 1;
        }
        r += 1;
    }
    pairs
}

/// Entries of the upper triangle of a state-space matrix.
const UPPER_LEN: usize = DIM * (DIM + 1) / 2;
/// Upper-triangle index pairs of a symmetric state-space matrix.
const UPPER: [(usize, usize); UPPER_LEN] = upper::<DIM, UPPER_LEN>();
/// Entries of the upper triangle of a measurement-space matrix.
const MEAS_UPPER_LEN: usize = MEAS * (MEAS + 1) / 2;
/// Upper-triangle index pairs of a symmetric measurement-space matrix.
const MEAS_UPPER: [(usize, usize); MEAS_UPPER_LEN] = upper::<MEAS, MEAS_UPPER_LEN>();

/// The weights of the quadratic form xᵀ·A·x over the upper triangle of symmetric A: the
/// diagonal once, the off-diagonal terms twice.
fn form_weights<const D: usize, const L: usize>(
    a: &SMatrix<f64, D, D>,
    pairs: &[(usize, usize); L],
) -> [f64; L] {
    std::array::from_fn(|k| {
        let (r, c) = pairs[k];
        if r == c { a[(r, c)] } else { 2.0 * a[(r, c)] }
    })
}

/// What every engine hands over at one fix, for a lane group: the true error state, the
/// estimates and the residual (inactive lanes all zero).
#[derive(Clone, Copy, Debug)]
pub struct LaneFix {
    /// δx(t_i).
    pub delta_x: [Lanes; DIM],
    /// δx̂(t_i⁻).
    pub prior: [Lanes; DIM],
    /// δx̂(t_i⁺).
    pub post: [Lanes; DIM],
    /// r(t_i).
    pub residual: [Lanes; MEAS],
}

/// One stage's sums per lane; fields as in [`StageSums`]. The normalized estimation error
/// squared is not summed per lane: Σ eᵀP⁻¹e = Σ_k w_k·(Σ e·eᵀ)_k, with one P per fix, so it is
/// formed from the lanes' Σ e·eᵀ when they are added up.
#[derive(Clone, Copy, Debug, Default)]
struct LaneStage {
    e: [Lanes; DIM],
    ee: [Lanes; UPPER_LEN],
    /// Σ e·δx̂ᵀ, column-major like nalgebra's matrices.
    ex: [Lanes; DIM * DIM],
    x: [Lanes; DIM],
    xx: [Lanes; DIM],
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
    fn add<const FIRST: bool>(&mut self, delta_x: &[Lanes; DIM], x: &[Lanes; DIM]) {
        let mut e = [Lanes::default(); DIM];
        for k in 0..DIM {
            e[k] = delta_x[k] - x[k];
        }
        for (s, &(r, c)) in self.ee.iter_mut().zip(UPPER.iter()) {
            put::<FIRST>(s, e[r] * e[c]);
        }
        for c in 0..DIM {
            for r in 0..DIM {
                put::<FIRST>(&mut self.ex[DIM * c + r], e[r] * x[c]);
            }
            put::<FIRST>(&mut self.e[c], e[c]);
            put::<FIRST>(&mut self.x[c], x[c]);
            put::<FIRST>(&mut self.xx[c], x[c] * x[c]);
        }
    }

    /// Adds the lanes' totals (see [`Lanes::sum`]) to `s`, and Σ eᵀP⁻¹e formed from them
    /// with the weights `w` of eᵀP⁻¹e over the upper triangle (off-diagonal terms doubled).
    #[inline(always)]
    fn reduce_into(&self, s: &mut StageSums, w: &[f64; UPPER_LEN]) {
        for k in 0..DIM {
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
            s.ex[(k % DIM, k / DIM)] += v.sum();
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
    prior: [f64; UPPER_LEN],
    post: [f64; UPPER_LEN],
    /// S⁻¹ over its upper triangle, off-diagonal terms doubled: (00, 2·01, 11).
    s: [f64; MEAS_UPPER_LEN],
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
        self.current = LaneFixSums::default();
        self.weights.clear();
        self.weights.extend(schedule.fixes.iter().map(|f| Weights {
            prior: form_weights(&f.p_prior_inv, &UPPER),
            post: form_weights(&f.p_post_inv, &UPPER),
            s: form_weights(&f.s_inv, &MEAS_UPPER),
        }));
    }

    /// Adds a lane group's fix `i`; `FIRST` for the first group of the fix (see [`put`]).
    #[inline(always)]
    pub fn add<const FIRST: bool>(&mut self, i: usize, f: &LaneFix) {
        let w = &self.weights[i];
        let sums = &mut self.current;
        sums.prior.add::<FIRST>(&f.delta_x, &f.prior);
        sums.post.add::<FIRST>(&f.delta_x, &f.post);
        let r = &f.residual;
        // rᵀ·S⁻¹·r over the upper triangle, added in its order.
        let (a, b) = MEAS_UPPER[0];
        let mut nis = Lanes::splat(w.s[0]) * r[a] * r[b];
        for (k, &(a, b)) in MEAS_UPPER.iter().enumerate().skip(1) {
            nis += Lanes::splat(w.s[k]) * r[a] * r[b];
        }
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
