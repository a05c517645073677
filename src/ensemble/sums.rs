//! Running sums of an ensemble: everything the statistics need, added one realization at a time
//! and merged block by block, with no per-realization storage.

use nalgebra::{SMatrix, SVector};

use super::layout::ResidualLayout;
use crate::state::ErrorState;

/// Running sums over realizations of one estimate stage (a priori or a posteriori) at one fix,
/// for a state of `N` variables.
#[derive(Clone, Debug, PartialEq)]
pub struct StageSums<const N: usize = { ErrorState::DIM }> {
    /// Σ e, e = δx − δx̂.
    pub e: SVector<f64, N>,
    /// Σ e·eᵀ, symmetric: entry (r, c) and (c, r) hold the same sum.
    pub ee: SMatrix<f64, N, N>,
    /// Σ e·δx̂ᵀ.
    pub ex: SMatrix<f64, N, N>,
    /// Σ δx̂.
    pub x: SVector<f64, N>,
    /// Σ δx̂_k², the diagonal of Σ δx̂·δx̂ᵀ.
    pub xx: SVector<f64, N>,
    /// Σ eᵀ·P⁻¹·e (the normalized estimation error squared).
    pub nees: f64,
}

impl<const N: usize> Default for StageSums<N> {
    fn default() -> Self {
        Self {
            e: SVector::zeros(),
            ee: SMatrix::zeros(),
            ex: SMatrix::zeros(),
            x: SVector::zeros(),
            xx: SVector::zeros(),
            nees: 0.0,
        }
    }
}

impl<const N: usize> StageSums<N> {
    /// Adds one realization's error `e` = δx − δx̂ and estimate `x` = δx̂, with (P)⁻¹ `p_inv`.
    pub fn add(&mut self, e: &SVector<f64, N>, x: &SVector<f64, N>, p_inv: &SMatrix<f64, N, N>) {
        self.e += e;
        self.ee += e * e.transpose();
        self.ex += e * x.transpose();
        self.x += x;
        self.xx += x.component_mul(x);
        self.nees += (e.transpose() * p_inv * e)[0];
    }

    /// The upper triangle of Σ e·eᵀ, row by row: (00, 01, …, 0N, 11, …): the stored form.
    pub fn ee_upper(&self) -> impl Iterator<Item = f64> + '_ {
        (0..N).flat_map(move |r| (r..N).map(move |c| self.ee[(r, c)]))
    }

    /// Sets Σ e·eᵀ from its upper triangle in [`StageSums::ee_upper`] order.
    pub fn set_ee_upper(&mut self, upper: &[f64]) {
        let mut k = 0;
        for r in 0..N {
            for c in r..N {
                self.ee[(r, c)] = upper[k];
                self.ee[(c, r)] = upper[k];
                k += 1;
            }
        }
    }

    /// Floats of one stage's sums in [`StageSums::write_floats`] order: Σ e, the upper triangle of
    /// Σ e·eᵀ, Σ e·δx̂ᵀ (column-major), Σ δx̂, Σ δx̂², NEES.
    pub const FLOATS: usize = N + N * (N + 1) / 2 + N * N + N + N + 1;

    /// Appends the sums to `out` as [`StageSums::FLOATS`] numbers (a partial file's layout).
    pub fn write_floats(&self, out: &mut Vec<f64>) {
        out.extend(self.e.iter());
        out.extend(self.ee_upper());
        out.extend(self.ex.iter());
        out.extend(self.x.iter());
        out.extend(self.xx.iter());
        out.push(self.nees);
    }

    /// The sums from the [`StageSums::FLOATS`] numbers `v` that [`StageSums::write_floats`]
    /// wrote.
    pub fn from_floats(v: &[f64]) -> Self {
        let mut rest = v;
        let mut take = |len: usize| {
            let (head, tail) = rest.split_at(len);
            rest = tail;
            head
        };
        let e = SVector::from_column_slice(take(N));
        let ee = take(N * (N + 1) / 2);
        let ex = SMatrix::from_column_slice(take(N * N));
        let x = SVector::from_column_slice(take(N));
        let xx = SVector::from_column_slice(take(N));
        let mut s = Self {
            e,
            ex,
            x,
            xx,
            nees: take(1)[0],
            ..Self::default()
        };
        s.set_ee_upper(ee);
        s
    }

    fn merge(&mut self, o: &Self) {
        self.e += o.e;
        self.ee += o.ee;
        self.ex += o.ex;
        self.x += o.x;
        self.xx += o.xx;
        self.nees += o.nees;
    }
}

/// Running sums at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixSums<const N: usize = { ErrorState::DIM }> {
    /// Sums of the a priori stage.
    pub prior: StageSums<N>,
    /// Sums of the a posteriori stage.
    pub post: StageSums<N>,
    /// Σ rᵀ·S⁻¹·r (the normalized innovation squared).
    pub nis: f64,
}

impl<const N: usize> FixSums<N> {
    /// Floats of one fix's sums in a file: the two stages' and Σ NIS.
    pub const FLOATS: usize = 2 * StageSums::<N>::FLOATS + 1;
    /// Floats of one fix's sums in memory (Σ e·eᵀ kept whole).
    pub const MEMORY_FLOATS: usize = floats_of::<Self>();
}

/// Floats in a `T` made of `f64`s only (checked at compile time: no padding, nothing else).
const fn floats_of<T>() -> usize {
    let (size, float) = (std::mem::size_of::<T>(), std::mem::size_of::<f64>());
    assert!(size % float == 0, "sums are made of f64s only");
    size / float
}

// The configuration's memory budget counts the sums with the model's figure.
const _: () = assert!(<FixSums>::MEMORY_FLOATS == crate::model::SUM_FLOATS_PER_FIX);

/// Running sums of an ensemble, or of part of one, for a state of `N` variables and a
/// measurement of `M` components.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator<const N: usize = { ErrorState::DIM }, const M: usize = { ErrorState::MEAS }>
{
    /// Realizations summed.
    pub count: u64,
    /// One entry per fix.
    pub fixes: Vec<FixSums<N>>,
    /// Which residual products are kept.
    pub layout: ResidualLayout,
    /// Σ ρ·ρᵀ over realizations, where ρ = (r(t_0), r(t_1), …) stacks every residual: the kept
    /// part of the lower triangle, diagonal included (see [`ResidualLayout`]).
    pub residual_products: Vec<f64>,
    /// The fix indices [m, i] of the statement's single residual pair.
    pub pair: [usize; 2],
    /// Σ r_j(t_i)·r_k(t_m) of the single pair, entry (j, k), kept whatever the layout.
    pub pair_products: SMatrix<f64, M, M>,
}

impl<const N: usize, const M: usize> Accumulator<N, M> {
    /// Empty sums with the residual products of `layout` and the single pair `pair`.
    pub fn new(layout: &ResidualLayout, pair: [usize; 2]) -> Self {
        Self {
            count: 0,
            fixes: vec![FixSums::default(); layout.fixes()],
            residual_products: vec![0.0; layout.len()],
            layout: layout.clone(),
            pair,
            pair_products: SMatrix::zeros(),
        }
    }

    /// Adds `other` to these sums.
    ///
    /// # Panics
    /// When the two sums do not have the same layout and pair.
    pub fn merge(&mut self, other: &Self) {
        assert!(
            self.layout == other.layout && self.pair == other.pair,
            "sums of different ensembles"
        );
        self.count += other.count;
        self.pair_products += other.pair_products;
        for (a, b) in self.fixes.iter_mut().zip(&other.fixes) {
            a.prior.merge(&b.prior);
            a.post.merge(&b.post);
            a.nis += b.nis;
        }
        for (a, b) in self
            .residual_products
            .iter_mut()
            .zip(&other.residual_products)
        {
            *a += b;
        }
    }

    /// Empties the per-fix sums, the count and the pair products, keeping the layout and the
    /// storage; the residual products are left for the engine to overwrite, every one of them.
    pub(super) fn clear_but_products(&mut self) {
        self.count = 0;
        self.fixes.fill(FixSums::default());
        self.pair_products = SMatrix::zeros();
    }
}
