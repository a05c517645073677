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
    /// storage; the residual products are left as they are for
    /// [`Self::set_residual_products`] to overwrite.
    pub(super) fn clear_but_products(&mut self) {
        self.count = 0;
        self.fixes.fill(FixSums::default());
        self.pair_products = [0.0; 4];
    }

    /// Sets the residual products to Σ_q ρ_q·ρ_qᵀ over the `count` stacked residual vectors ρ_q
    /// held in `panels` (see [`PANEL`]; rows of inactive realizations are zero), and adds the
    /// pair products. Each kept product is one sum over q in order, kept in a register: the
    /// triangle goes in tiles of 4 rows × [`PANEL`] columns, each the product of a 4-row slice
    /// and a column panel of the stacked residuals, so the large packed triangle is written once
    /// per chunk and read never.
    #[inline(always)]
    pub(super) fn set_residual_products(&mut self, panels: &[f64], count: usize) {
        let m = 2 * self.fixes.len();
        let width = PANEL * count;
        debug_assert_eq!(panels.len(), m.div_ceil(PANEL) * width);
        let at = |c: usize, q: usize| panels[(c / PANEL) * width + q * PANEL + c % PANEL];
        let [pm, pi] = self.pair;
        for q in 0..count {
            for (c, p) in self.pair_products.iter_mut().enumerate() {
                *p += at(2 * pi + c / 2, q) * at(2 * pm + c % 2, q);
            }
        }
        for a0 in (0..m).step_by(4) {
            let rows = &panels[(a0 / PANEL) * width..(a0 / PANEL + 1) * width];
            let last = (a0 + 3).min(m - 1);
            for pb in self.layout.first_col(a0) / PANEL..=last / PANEL {
                let cols = &panels[pb * width..(pb + 1) * width];
                let tile = if a0 % PANEL == 0 {
                    tile_products::<0>(rows, cols, count)
                } else {
                    tile_products::<4>(rows, cols, count)
                };
                for (r, row) in tile.iter().enumerate() {
                    let a = a0 + r;
                    if a >= m {
                        break;
                    }
                    let first = self.layout.first_col(a);
                    let start = self.layout.row_start(a);
                    for (c, &v) in row.iter().enumerate() {
                        let b = pb * PANEL + c;
                        if b >= first && b <= a {
                            self.residual_products[start + b - first] = v;
                        }
                    }
                }
            }
        }
    }
}

/// Columns of a panel of stacked residuals: panel p holds components p·PANEL.. of every
/// realization q of a chunk, realization after realization (PANEL numbers each), the components
/// beyond the last zero.
pub(super) const PANEL: usize = 8;

/// Σ_q rows_q[OFF + r] · cols_q[c] for r < 4, c < PANEL, summed over q in order: 8 vector
/// accumulators that stay in registers while the two panels stream by.
#[inline(always)]
fn tile_products<const OFF: usize>(rows: &[f64], cols: &[f64], count: usize) -> [[f64; PANEL]; 4] {
    let mut acc = [[0.0; PANEL]; 4];
    let (rows, _) = rows[..count * PANEL].as_chunks::<PANEL>();
    let (cols, _) = cols[..count * PANEL].as_chunks::<PANEL>();
    for (row, col) in rows.iter().zip(cols) {
        let x: [f64; 4] = std::array::from_fn(|r| row[OFF + r]);
        for r in 0..4 {
            for c in 0..PANEL {
                acc[r][c] += x[r] * col[c];
            }
        }
    }
    acc
}
