//! Orthogonality of the estimation error and the estimate.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{max_abs, time_span};
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel, columns};
use super::{
    BLACK, BLUE, BLUISH_GREEN, ORANGE, PlotResult, REFERENCE, WIDTH_PX, capitalized, last_state,
    state_name, states,
};
use crate::checks::Check;
use crate::ensemble::{EnsembleStats, StageStats};
use crate::state::ErrorState;

/// Height of one error component's row, px.
const ROW_PX: u32 = 230;
/// Colours of the estimate components, in state order (repeated beyond the last).
const COLORS: [plotters::style::RGBColor; 3] = [BLUE, ORANGE, BLUISH_GREEN];
/// Number of states.
const N: usize = ErrorState::DIM;

/// Colour of estimate component `k`.
fn color(k: usize) -> plotters::style::RGBColor {
    COLORS[k % COLORS.len()]
}

/// The normalized correlations √N·corr(e_j − e_ave,j, δx̂_k) of every component pair at every fix
/// against ±bound: one row per error component j, a priori on the left and a posteriori on the
/// right, one colour per estimate component k. Undefined correlations (an estimate component
/// that does not vary over the ensemble) are left out.
pub fn orthogonality(stats: &EnsembleStats, check: &Check) -> PlotResult {
    let fixes = &stats.fixes;
    let root_n = (stats.realizations as f64).sqrt();
    let z = |s: &StageStats, j: usize, k: usize| root_n * s.orthogonality_corr[j][k];
    let (t0, t1) = time_span(fixes.iter().map(|f| f.time_s));
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 7);
    let m = max_abs(
        fixes
            .iter()
            .flat_map(|f| [&f.prior, &f.post])
            .flat_map(|s| (0..N * N).map(move |i| z(s, i / N, i % N)))
            .chain([check.upper]),
    );
    let y = Axis::linear("√N · correlation", "", (-1.15 * m, 1.15 * m), 7);
    let y_area_px = y_label_area(&[&y]);

    let mut legend: Vec<Entry> = states()
        .map(|k| {
            Entry::new(
                Swatch::Line(color(k).stroke_width(2)),
                format!("{} estimate", state_name(k)),
            )
        })
        .collect();
    legend.push(Entry::new(
        Swatch::Line(BLACK.stroke_width(1)),
        format!("±{:.2} bound", check.upper),
    ));
    render_state_rows(ROW_PX, &legend, |area, j| {
        let cols = columns(area, &[WIDTH_PX / 2]);
        for (c, prior) in [(0, true), (1, false)] {
            let p = Panel::new(
                &cols[c],
                &format!(
                    "{} error vs the estimates, {}",
                    capitalized(state_name(j)),
                    if prior { "a priori" } else { "a posteriori" }
                ),
                time.clone(),
                y.clone(),
                Layout::titled(y_area_px, last_state(j)),
            )?;
            p.hline(0.0, REFERENCE.stroke_width(1))?;
            p.hline(check.upper, BLACK.stroke_width(1))?;
            p.hline(-check.upper, BLACK.stroke_width(1))?;
            for k in states() {
                p.line(
                    fixes.iter().map(|f| {
                        let s = if prior { &f.prior } else { &f.post };
                        (f.time_s, z(s, j, k))
                    }),
                    color(k).stroke_width(1),
                )?;
            }
        }
        Ok(())
    })
}
