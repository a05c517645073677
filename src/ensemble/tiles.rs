//! The residual products Σ ρ·ρᵀ of a block, summed in register tiles.
//!
//! The stacked residual vectors ρ_q of a pass of [`PASS`] realizations (two chunks) are held in
//! column panels (see [`PANEL`]), in single precision. The kept part of the lower triangle is
//! covered by tiles of [`ROWS`] rows × [`PANEL`] columns, stored tile after tile, each tile's
//! sums row-major in double precision. A pass adds to a tile at once: the products of the pass's
//! realizations are summed in order in single-precision registers, by fused multiply-adds, and
//! that sum is added to the tile's double-precision running sum. So every product of a block is
//! a double-precision sum over the block's passes in order of single-precision sums over a
//! pass's realizations in order, and the packed triangle is written once, when the block is
//! finished.
//!
//! Single precision within a pass doubles the products per instruction. Its rounding is far
//! below the sampling noise of the sums: a pass's sum of K = 128 products is within
//! [`PRODUCT_RELATIVE_ERROR`] ≈ 7.7·10⁻⁶ of the exact sum relative to √(Σρ_a²·Σρ_b²) (the
//! worst case, to first order), and the errors of different passes are independent, so a sum
//! over N realizations moves by about 2⁻²⁴·√K ≈ 7·10⁻⁷ of its own standard error, whatever N.
//! Measured: 1.1·10⁻⁷ relative at most over 40 passes of random residuals (tests below), and
//! every number of the default report within 4.4·10⁻⁷ relative of the double-precision sums,
//! every verdict and count unchanged (docs/SPEED.md). Residuals are assumed within single
//! precision's range (|ρ| between about 10⁻¹⁹ and 10¹⁹, so that no product underflows or
//! overflows): metres and metres per second are.

use super::layout::ResidualLayout;

/// Columns of a panel of stacked residuals: panel p holds components p·PANEL.. of every
/// realization q of a chunk, realization after realization (PANEL numbers each, one cache line),
/// the components beyond the last zero.
pub(super) const PANEL: usize = 16;

/// Rows of a tile.
const ROWS: usize = 4;

/// Realizations whose products are summed in single precision before they are added to the
/// double-precision tile sums: two chunks (the fewer passes over the tiles, the less time in
/// memory and in the tiles' conversion; the longer the single-precision sums, the larger their
/// rounding, see [`PRODUCT_RELATIVE_ERROR`]).
pub const PASS: u64 = 2 * super::CHUNK;

/// The largest error of a residual product sum Σ_q ρ_a·ρ_b relative to √(Σ_q ρ_a²·Σ_q ρ_b²):
/// (K + 2)·2⁻²⁴ with K = [`PASS`] products summed in single precision (K fused
/// multiply-adds, the two inputs rounded), to first order, by Cauchy–Schwarz on the usual
/// bound γ·Σ|ρ_a·ρ_b| of a running sum.
pub const PRODUCT_RELATIVE_ERROR: f64 = (PASS as f64 + 2.0) / (1u64 << 24) as f64;

/// Numbers in a tile.
const TILE: usize = ROWS * PANEL;

/// Calls `f(t, a0, pb)` for every tile t in storage order: rows a0..a0 + ROWS of column panel pb
/// (the loops of [`add_products_with`]).
fn for_each_tile(layout: &ResidualLayout, mut f: impl FnMut(usize, usize, usize)) {
    let m = 2 * layout.fixes();
    let mut t = 0;
    for a0 in (0..m).step_by(ROWS) {
        let last = (a0 + ROWS - 1).min(m - 1);
        // The first kept column grows with the row: row a0's is the group's smallest.
        for pb in layout.first_col(a0) / PANEL..=last / PANEL {
            f(t, a0, pb);
            t += 1;
        }
    }
}

/// Numbers of the tile storage of `layout`.
pub(super) fn tiles_len(layout: &ResidualLayout) -> usize {
    let mut n = 0;
    for_each_tile(layout, |_, _, _| n += TILE);
    n
}

/// Panel numbers of a chunk of `count` realizations with `m` stacked residual components.
pub(super) fn panels_len(m: usize, count: usize) -> usize {
    m.div_ceil(PANEL) * PANEL * count
}

/// Zeroes the components from m on, up to the end of the last panel, of every realization of
/// a chunk of `count`.
pub(super) fn zero_padding(panels: &mut [f32], m: usize, count: usize) {
    if !m.is_multiple_of(PANEL) {
        for q in 0..count {
            let first = panel_index(m, q, count);
            panels[first..first + PANEL - m % PANEL].fill(0.0);
        }
    }
}

/// Where component c of realization q of a chunk of `count` goes in the panels.
#[inline(always)]
pub(super) fn panel_index(c: usize, q: usize, count: usize) -> usize {
    (c / PANEL) * PANEL * count + q * PANEL + c % PANEL
}

/// Adds Σ_q ρ_q·ρ_qᵀ over the `count` stacked residual vectors ρ_q held in `panels` (rows of
/// inactive realizations zero) to the tiles `sums` of `layout`, or sets the tiles to them
/// (`first`: whatever the tiles held before is overwritten, tile by tile while it is in cache,
/// rather than zeroed in a pass of its own). Runs the AVX2 tile kernel when
/// the processor has AVX2 and FMA, and the plain one otherwise: the same fused multiply-adds in
/// the same order, so the same results.
pub(super) fn add_products(
    layout: &ResidualLayout,
    sums: &mut [f64],
    panels: &[f32],
    count: usize,
    first: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor supports AVX2 and FMA, checked just above.
        unsafe { avx2::add_products(layout, sums, panels, count, first) };
        return;
    }
    add_products_with(
        layout,
        sums,
        panels,
        count,
        first,
        [tile_add::<0>, tile_add::<4>, tile_add::<8>, tile_add::<12>],
    );
}

/// A tile kernel: adds Σ_q rows_q\[OFF + r\]·cols_q\[c\] for r < ROWS, c < PANEL to the tile, summed
/// over q in order in single precision, each product added with one rounding (a fused
/// multiply-add), then added to the tile's double-precision sums.
type Kernel = fn(&mut [f64; TILE], &[f32], &[f32]);

/// The tile kernels of the row offsets within a panel, 0, [`ROWS`], 2·[`ROWS`], …, in order.
type Kernels = [Kernel; PANEL / ROWS];

/// The tiles of `layout` in storage order, each given to the kernel of its row offset.
#[inline(always)]
fn add_products_with(
    layout: &ResidualLayout,
    sums: &mut [f64],
    panels: &[f32],
    count: usize,
    first: bool,
    kernels: Kernels,
) {
    let width = PANEL * count;
    let m = 2 * layout.fixes();
    let mut tiles = sums.as_chunks_mut::<TILE>().0.iter_mut();
    for a0 in (0..m).step_by(ROWS) {
        let last = (a0 + ROWS - 1).min(m - 1);
        let rows = &panels[(a0 / PANEL) * width..][..width];
        // a0 is a multiple of ROWS: the kernel of its offset within its panel.
        let kernel = kernels[(a0 % PANEL) / ROWS];
        for pb in layout.first_col(a0) / PANEL..=last / PANEL {
            let cols = &panels[pb * width..][..width];
            let tile = tiles.next().expect("a tile for every (a0, pb)");
            if first {
                *tile = [0.0; TILE];
            }
            kernel(tile, rows, cols);
        }
    }
}

/// The plain tile kernel (see [`Kernel`]).
fn tile_add<const OFF: usize>(tile: &mut [f64; TILE], rows: &[f32], cols: &[f32]) {
    let mut acc = [[0.0f32; PANEL]; ROWS];
    let (rows, _) = rows.as_chunks::<PANEL>();
    let (cols, _) = cols.as_chunks::<PANEL>();
    for (row, col) in rows.iter().zip(cols) {
        for r in 0..ROWS {
            for c in 0..PANEL {
                acc[r][c] = row[OFF + r].mul_add(col[c], acc[r][c]);
            }
        }
    }
    for (r, a) in acc.iter().enumerate() {
        for (t, &v) in tile[r * PANEL..(r + 1) * PANEL].iter_mut().zip(a) {
            *t += f64::from(v);
        }
    }
}

/// The AVX2 tile kernel: eight 256-bit accumulators (two per row) stay in registers while the
/// two panels stream by, 64 fused multiply-adds per four broadcasts and two loads.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{PANEL, ROWS, ResidualLayout, TILE};
    use std::arch::x86_64::*;

    #[target_feature(enable = "avx2,fma")]
    pub(super) fn add_products(
        layout: &ResidualLayout,
        sums: &mut [f64],
        panels: &[f32],
        count: usize,
        first: bool,
    ) {
        super::add_products_with(
            layout,
            sums,
            panels,
            count,
            first,
            [
                |t, r, c| tile_add::<0>(t, r, c),
                |t, r, c| tile_add::<4>(t, r, c),
                |t, r, c| tile_add::<8>(t, r, c),
                |t, r, c| tile_add::<12>(t, r, c),
            ],
        );
    }

    /// The AVX2 variant of [`super::tile_add`]: the same fused multiply-adds in the same order.
    #[target_feature(enable = "avx2,fma")]
    fn tile_add<const OFF: usize>(tile: &mut [f64; TILE], rows: &[f32], cols: &[f32]) {
        let n = rows.len().min(cols.len()) / PANEL;
        let mut acc = [_mm256_setzero_ps(); 2 * ROWS];
        for q in 0..n {
            let row = &rows[q * PANEL..(q + 1) * PANEL];
            let col = &cols[q * PANEL..(q + 1) * PANEL];
            // SAFETY: `col` holds PANEL = 16 numbers, read as two runs of 8.
            let (c0, c1) = unsafe {
                (
                    _mm256_loadu_ps(col.as_ptr()),
                    _mm256_loadu_ps(col.as_ptr().add(8)),
                )
            };
            for r in 0..ROWS {
                let x = _mm256_set1_ps(row[OFF + r]);
                acc[2 * r] = _mm256_fmadd_ps(x, c0, acc[2 * r]);
                acc[2 * r + 1] = _mm256_fmadd_ps(x, c1, acc[2 * r + 1]);
            }
        }
        for (k, a) in acc.iter().enumerate() {
            let mut v = [0.0f32; 8];
            // SAFETY: `v` holds 8 numbers.
            unsafe { _mm256_storeu_ps(v.as_mut_ptr(), *a) };
            let (r, h) = (k / 2, k % 2);
            for (t, x) in tile[r * PANEL + 8 * h..r * PANEL + 8 * h + 8]
                .iter_mut()
                .zip(v)
            {
                *t += f64::from(x);
            }
        }
    }
}

/// Writes the kept products held in the tiles `sums` into the packed storage `out` of `layout`.
pub(super) fn unpack(layout: &ResidualLayout, sums: &[f64], out: &mut [f64]) {
    let m = 2 * layout.fixes();
    let (tiles, _) = sums.as_chunks::<TILE>();
    for_each_tile(layout, |t, a0, pb| {
        for r in 0..ROWS.min(m - a0) {
            let a = a0 + r;
            let first = layout.first_col(a);
            let lo = first.max(pb * PANEL);
            let hi = a.min(pb * PANEL + PANEL - 1);
            if lo <= hi {
                let start = layout.row_start(a);
                out[start + lo - first..=start + hi - first].copy_from_slice(
                    &tiles[t][r * PANEL + lo - pb * PANEL..=r * PANEL + hi - pb * PANEL],
                );
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tiles of random panels unpack to the plain sums of products, for the full triangle and
    /// a band, with a partial last panel.
    #[test]
    fn tiles_unpack_to_the_products_of_the_stacked_residuals() {
        for (fixes, lag) in [(7, None), (13, Some(2)), (1, None)] {
            let layout = ResidualLayout::new(fixes, lag);
            let m = 2 * fixes;
            let count = 5;
            let mut panels = vec![0.0f32; panels_len(m, count)];
            let rho: Vec<Vec<f64>> = (0..count)
                .map(|q| {
                    (0..m)
                        .map(|c| ((q * 31 + c * 7) % 11) as f64 - 5.0)
                        .collect()
                })
                .collect();
            for (q, r) in rho.iter().enumerate() {
                for (c, &v) in r.iter().enumerate() {
                    panels[panel_index(c, q, count)] = v as f32;
                }
            }
            // Two chunks: the same realizations set, then added again, over a stale start.
            let mut sums = vec![f64::NAN; tiles_len(&layout)];
            add_products(&layout, &mut sums, &panels, count, true);
            add_products(&layout, &mut sums, &panels, count, false);
            let mut out = vec![f64::NAN; layout.len()];
            unpack(&layout, &sums, &mut out);
            for a in 0..m {
                for b in 0..=a {
                    let want: f64 = 2.0 * rho.iter().map(|r| r[a] * r[b]).sum::<f64>();
                    match layout.index(a, b) {
                        Some(i) => assert_eq!(out[i], want, "({a}, {b})"),
                        None => assert!(lag.is_some()),
                    }
                }
            }
        }
    }

    /// Random panels of a chunk of 64 (some realizations inactive, so zero), with components of
    /// very different scales, like position and velocity residuals.
    fn random_panels(
        m: usize,
        count: usize,
        active: usize,
        seed: u64,
    ) -> (Vec<f32>, Vec<Vec<f64>>) {
        let mut rng = crate::random::Stream::new(seed, 0);
        let rho: Vec<Vec<f64>> = (0..count)
            .map(|q| {
                (0..m)
                    .map(|c| {
                        let scale = if c % 2 == 0 { 3.0 } else { 0.05 };
                        if q < active {
                            scale * rng.normal()
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect();
        let mut panels = vec![0.0f32; panels_len(m, count)];
        zero_padding(&mut panels, m, count);
        for (q, r) in rho.iter().enumerate() {
            for (c, &v) in r.iter().enumerate() {
                panels[panel_index(c, q, count)] = v as f32;
            }
        }
        (panels, rho)
    }

    /// Single precision within a chunk stays inside its stated bound: every product sum of 40
    /// chunks of random residuals is within PRODUCT_RELATIVE_ERROR·√(Σρ_a²·Σρ_b²) of the exact
    /// double-precision sum, and is not exact (the bound is not vacuous: the errors are of the
    /// size single precision gives, far above double precision's).
    #[test]
    fn single_precision_sums_stay_within_their_bound() {
        let layout = ResidualLayout::new(150, None);
        let (m, count) = (300, PASS as usize);
        let mut sums = vec![f64::NAN; tiles_len(&layout)];
        let mut exact = vec![0.0; layout.len()];
        for chunk in 0..40 {
            let (panels, rho) = random_panels(m, count, if chunk == 7 { 21 } else { count }, chunk);
            add_products(&layout, &mut sums, &panels, count, chunk == 0);
            for r in &rho {
                for a in 0..m {
                    for b in 0..=a {
                        exact[layout.index(a, b).unwrap()] += r[a] * r[b];
                    }
                }
            }
        }
        let mut out = vec![f64::NAN; layout.len()];
        unpack(&layout, &sums, &mut out);
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for a in 0..m {
            for b in 0..=a {
                let i = layout.index(a, b).unwrap();
                let diagonal = |c: usize| exact[layout.index(c, c).unwrap()];
                let scale = (diagonal(a) * diagonal(b)).sqrt();
                let err = (out[i] - exact[i]).abs() / scale;
                worst = worst.max(err);
                largest = largest.max(err / PRODUCT_RELATIVE_ERROR);
            }
        }
        assert!(
            largest <= 1.0,
            "error {worst:e} beyond the bound {PRODUCT_RELATIVE_ERROR:e}"
        );
        assert!(worst > 1e-9, "errors of {worst:e}: not single precision");
    }

    /// The AVX2 kernel and the plain one give the same bits.
    #[test]
    fn both_tile_kernels_give_the_same_sums() {
        let layout = ResidualLayout::new(37, Some(9));
        let (m, count) = (74, 24);
        let (panels, _) = random_panels(m, count, 19, 3);
        let mut plain = vec![0.5; tiles_len(&layout)];
        let mut fast = plain.clone();
        add_products_with(
            &layout,
            &mut plain,
            &panels,
            count,
            false,
            [tile_add::<0>, tile_add::<4>, tile_add::<8>, tile_add::<12>],
        );
        add_products(&layout, &mut fast, &panels, count, false);
        assert!(
            plain
                .iter()
                .zip(&fast)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
        assert!(plain.iter().any(|&v| v != 0.5));
    }
}
