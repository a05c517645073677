//! Running sums of an ensemble: everything the statistics need, added one realization at a time
//! and merged block by block, with no per-realization storage.

use super::layout::ResidualLayout;
use crate::filter::{Matrix3, Vector3};

/// Running sums over realizations of one estimate stage (a priori or a posteriori) at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageSums {
    /// Σ e, e = δx − δx̂.
    pub e: Vector3,
    /// Σ e·eᵀ, upper triangle in the order (00, 01, 02, 11, 12, 22).
    pub ee: [f64; 6],
    /// Σ e·δx̂ᵀ.
    pub ex: Matrix3,
    /// Σ δx̂.
    pub x: Vector3,
    /// Σ δx̂_k², the diagonal of Σ δx̂·δx̂ᵀ.
    pub xx: Vector3,
    /// Σ eᵀ·P⁻¹·e (the normalized estimation error squared).
    pub nees: f64,
}

/// Upper-triangle index pairs of a symmetric 3×3 matrix, in [`StageSums::ee`] order.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

impl StageSums {
    /// Floats of one stage's sums: Σe, the upper triangle of Σe·eᵀ, Σe·δx̂ᵀ, Σδx̂, Σδx̂² and
    /// Σ NEES, stored as they are in memory (and in a partial file).
    pub const FLOATS: usize = floats_of::<Self>();

    /// Σ e·eᵀ as a full matrix.
    pub fn ee_matrix(&self) -> Matrix3 {
        let mut m = Matrix3::zeros();
        for (v, &(r, c)) in self.ee.iter().zip(&UPPER) {
            m[(r, c)] = *v;
            m[(c, r)] = *v;
        }
        m
    }

    fn merge(&mut self, o: &Self) {
        self.e += o.e;
        for (a, b) in self.ee.iter_mut().zip(&o.ee) {
            *a += b;
        }
        self.ex += o.ex;
        self.x += o.x;
        self.xx += o.xx;
        self.nees += o.nees;
    }
}

/// Running sums at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixSums {
    /// Sums of the a priori stage.
    pub prior: StageSums,
    /// Sums of the a posteriori stage.
    pub post: StageSums,
    /// Σ rᵀ·S⁻¹·r (the normalized innovation squared).
    pub nis: f64,
}

impl FixSums {
    /// Floats of one fix's sums: the two stages' and Σ NIS.
    pub const FLOATS: usize = floats_of::<Self>();
}

/// Floats in a `T` made of `f64`s only (checked at compile time: no padding, nothing else).
const fn floats_of<T>() -> usize {
    let (size, float) = (std::mem::size_of::<T>(), std::mem::size_of::<f64>());
    assert!(size % float == 0, "sums are made of f64s only");
    size / float
}

const _: () = assert!(FixSums::FLOATS == 2 * StageSums::FLOATS + 1);
// The configuration's memory budget counts the sums with the model's figure.
const _: () = assert!(FixSums::FLOATS == crate::model::SUM_FLOATS_PER_FIX);

/// Running sums of an ensemble, or of part of one.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    /// Realizations summed.
    pub count: u64,
    /// One entry per fix.
    pub fixes: Vec<FixSums>,
    /// Which residual products are kept.
    pub layout: ResidualLayout,
    /// Σ ρ·ρᵀ over realizations, where ρ = (r(t_0), r(t_1), …) stacks every residual: the kept
    /// part of the lower triangle, diagonal included (see [`ResidualLayout`]).
    pub residual_products: Vec<f64>,
    /// The fix indices [m, i] of the statement's single residual pair.
    pub pair: [usize; 2],
    /// Σ r_j(t_i)·r_k(t_m) of the single pair, row-major (j, k), kept whatever the layout.
    pub pair_products: [f64; 4],
}

impl Accumulator {
    /// Empty sums with the residual products of `layout` and the single pair `pair`.
    pub fn new(layout: &ResidualLayout, pair: [usize; 2]) -> Self {
        Self {
            count: 0,
            fixes: vec![FixSums::default(); layout.fixes()],
            residual_products: vec![0.0; layout.len()],
            layout: layout.clone(),
            pair,
            pair_products: [0.0; 4],
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
        for (a, b) in self.pair_products.iter_mut().zip(&other.pair_products) {
            *a += b;
        }
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
        self.pair_products = [0.0; 4];
    }
}
