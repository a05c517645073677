//! Running sums of an ensemble: everything the statistics need, added one realization at a time
//! and merged chunk by chunk, with no per-realization storage.

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
    /// storage; the residual products are left as they are for [`Self::set_residual_rows`] to
    /// overwrite.
    pub(super) fn clear_but_products(&mut self) {
        self.count = 0;
        self.fixes.fill(FixSums::default());
        self.pair_products = [0.0; 4];
    }

    /// Sets the residual products to Σ_q ρ_q·ρ_qᵀ over the stacked residual vectors `rows` (each
    /// of length 2·fixes, a whole number ≥ 1 of batches of [`BATCH`]; rows of inactive
    /// realizations are zero) and adds the pair products. Each stored product is the first
    /// batch's partial sum, then the next batches' added in order. The rows of the triangle go in
    /// tiles small enough to stay in cache while every batch passes over them, so the large
    /// packed triangle is written once per call.
    #[inline(always)]
    pub(super) fn set_residual_rows(&mut self, rows: &[f64]) {
        let m = 2 * self.fixes.len();
        let batches = rows.len() / (BATCH * m);
        debug_assert!(batches >= 1 && rows.len() == batches * BATCH * m);
        let [pm, pi] = self.pair;
        for row in rows.chunks_exact(m) {
            for (c, p) in self.pair_products.iter_mut().enumerate() {
                *p += row[2 * pi + c / 2] * row[2 * pm + c % 2];
            }
        }
        const TILE: usize = 16;
        let mut tile_start = 0;
        for a0 in (0..m).step_by(TILE) {
            let a1 = (a0 + TILE).min(m);
            for (k, batch) in rows.chunks_exact(BATCH * m).enumerate() {
                let rows: [&[f64]; BATCH] = std::array::from_fn(|q| &batch[q * m..(q + 1) * m]);
                let mut start = tile_start;
                for a in a0..a1 {
                    let first = self.layout.first_col(a);
                    let len = a + 1 - first;
                    let coef: [f64; BATCH] = std::array::from_fn(|q| rows[q][a]);
                    let dst = &mut self.residual_products[start..start + len];
                    let cols: [&[f64]; BATCH] = std::array::from_fn(|q| &rows[q][first..=a]);
                    // Row a (+)= Σ_q ρ_q[a] · ρ_q[first..=a].
                    if k == 0 {
                        row_pass::<true>(dst, &coef, &cols);
                    } else {
                        row_pass::<false>(dst, &coef, &cols);
                    }
                    start += len;
                }
            }
            tile_start += (a0..a1)
                .map(|a| a + 1 - self.layout.first_col(a))
                .sum::<usize>();
        }
    }
}

/// dst = (SET) or += Σ_q coef_q · cols_q, element by element.
#[inline(always)]
fn row_pass<const SET: bool>(dst: &mut [f64], coef: &[f64; BATCH], cols: &[&[f64]; BATCH]) {
    for (b, d) in dst.iter_mut().enumerate() {
        let mut s = 0.0;
        for q in 0..BATCH {
            s += coef[q] * cols[q][b];
        }
        if SET {
            *d = s;
        } else {
            *d += s;
        }
    }
}

/// Realizations whose residual products are accumulated in one pass.
pub(super) const BATCH: usize = 8;
