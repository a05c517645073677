//! The residual products Σ ρ·ρᵀ of a block, summed in register tiles.
//!
//! A chunk's stacked residual vectors ρ_q are held in column panels (see [`PANEL`]). The kept part
//! of the lower triangle is covered by tiles of [`ROWS`] rows × [`PANEL`] columns, stored tile
//! after tile, each tile's products row-major. A chunk adds to a tile in one pass: the tile's
//! running sums are loaded into registers, every realization of the chunk is added in order, and
//! the sums are stored back. So every product of a block is one running sum over the block's
//! realizations in order, and the packed triangle is written once, when the block is finished.

use super::layout::ResidualLayout;

/// Columns of a panel of stacked residuals: panel p holds components p·PANEL.. of every
/// realization q of a chunk, realization after realization (PANEL numbers each), the components
/// beyond the last zero.
pub(super) const PANEL: usize = 8;

/// Rows of a tile.
const ROWS: usize = 4;

/// Numbers in a tile.
const TILE: usize = ROWS * PANEL;

/// Calls `f(t, a0, pb)` for every tile t in storage order: rows a0..a0 + ROWS of column panel pb.
#[inline(always)]
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

/// Where component c of realization q of a chunk of `count` goes in the panels.
#[inline(always)]
pub(super) fn panel_index(c: usize, q: usize, count: usize) -> usize {
    (c / PANEL) * PANEL * count + q * PANEL + c % PANEL
}

/// Adds Σ_q ρ_q·ρ_qᵀ over the `count` stacked residual vectors ρ_q held in `panels` (rows of
/// inactive realizations zero) to the tiles `sums` of `layout`.
#[inline(always)]
pub(super) fn add_products(
    layout: &ResidualLayout,
    sums: &mut [f64],
    panels: &[f64],
    count: usize,
) {
    let width = PANEL * count;
    let m = 2 * layout.fixes();
    let mut tiles = sums.as_chunks_mut::<TILE>().0.iter_mut();
    // The loops of `for_each_tile`, written out: a closure would not be compiled into the
    // vectorized caller.
    for a0 in (0..m).step_by(ROWS) {
        let last = (a0 + ROWS - 1).min(m - 1);
        let rows = &panels[(a0 / PANEL) * width..][..width];
        for pb in layout.first_col(a0) / PANEL..=last / PANEL {
            let cols = &panels[pb * width..][..width];
            let tile = tiles.next().expect("a tile for every (a0, pb)");
            if a0 % PANEL == 0 {
                tile_add::<0>(tile, rows, cols);
            } else {
                tile_add::<ROWS>(tile, rows, cols);
            }
        }
    }
}

/// Adds Σ_q rows_q[OFF + r] · cols_q[c] for r < ROWS, c < PANEL to `tile`, over q in order:
/// 8 vector accumulators that stay in registers while the two panels stream by.
#[inline(always)]
fn tile_add<const OFF: usize>(tile: &mut [f64; TILE], rows: &[f64], cols: &[f64]) {
    let mut acc = [[0.0; PANEL]; ROWS];
    for (r, a) in acc.iter_mut().enumerate() {
        a.copy_from_slice(&tile[r * PANEL..(r + 1) * PANEL]);
    }
    let (rows, _) = rows.as_chunks::<PANEL>();
    let (cols, _) = cols.as_chunks::<PANEL>();
    for (row, col) in rows.iter().zip(cols) {
        let x = [row[OFF], row[OFF + 1], row[OFF + 2], row[OFF + 3]];
        for r in 0..ROWS {
            for c in 0..PANEL {
                acc[r][c] += x[r] * col[c];
            }
        }
    }
    for (r, a) in acc.iter().enumerate() {
        tile[r * PANEL..(r + 1) * PANEL].copy_from_slice(a);
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
            let mut panels = vec![0.0; panels_len(m, count)];
            let rho: Vec<Vec<f64>> = (0..count)
                .map(|q| {
                    (0..m)
                        .map(|c| ((q * 31 + c * 7) % 11) as f64 - 5.0)
                        .collect()
                })
                .collect();
            for (q, r) in rho.iter().enumerate() {
                for (c, &v) in r.iter().enumerate() {
                    panels[panel_index(c, q, count)] = v;
                }
            }
            let mut sums = vec![0.0; tiles_len(&layout)];
            // Two chunks: the same realizations added twice.
            add_products(&layout, &mut sums, &panels, count);
            add_products(&layout, &mut sums, &panels, count);
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
}
