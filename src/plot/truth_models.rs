//! The two truth models side by side: how far each ensemble's mean error strays, in filter σ.

use plotters::style::Color;

use super::panel::{
    Axis, Entry, Layout, Panel, Swatch, draw_legend, legend_height, max_abs, render, rows,
    time_span, y_label_area,
};
use super::{BLACK, BLUE, PlotResult, VERMILLION, capitalized};
use crate::checks::STATE_NAMES;
use crate::ensemble::{EnsembleStats, FixStats};

/// Height of one state's panel, px.
const ROW_PX: u32 = 230;

/// Per state, the a posteriori ensemble mean error in units of the filter's σ,
/// e_ave / √P, at every fix, for the analytic truth (eq. 1) and the Euler truth (eq. 4).
///
/// With the Euler truth the filter's model (eq. 5) is exact and the ratio stays near zero (its
/// scatter is about 1/√N); the analytic truth adds the Euler integration error of the
/// accelerometer, which the filter does not model.
pub fn truth_models(analytic: &EnsembleStats, euler: &EnsembleStats) -> PlotResult {
    let normalized = |f: &FixStats, k: usize| f.post.mean_error[k] / f.post.filter_cov[k][k].sqrt();
    let both = [analytic, euler];
    let (t0, t1) = time_span(both.iter().flat_map(|s| s.fixes.iter().map(|f| f.time_s)));
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 8);
    let axes: Vec<Axis> = (0..3)
        .map(|k| {
            let m = max_abs(
                both.iter()
                    .flat_map(|s| s.fixes.iter().map(move |f| normalized(f, k))),
            );
            let m = if m > 0.0 { 1.15 * m } else { 1.0 };
            Axis::linear("e_ave / σ", "", (-m, m), 7)
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());

    let legend = [
        Entry::new(
            Swatch::Line(VERMILLION.stroke_width(2)),
            format!("analytic truth, eq. (1), N = {}", analytic.realizations),
        ),
        Entry::new(
            Swatch::Line(BLUE.stroke_width(2)),
            format!("Euler truth, eq. (4), N = {}", euler.realizations),
        ),
    ];
    let legend_px = legend_height(&legend);
    let last_row_px = ROW_PX + 24;

    render(legend_px + 2 * ROW_PX + last_row_px + 6, |root| {
        let parts = rows(root, &[legend_px, ROW_PX, ROW_PX, last_row_px]);
        draw_legend(&parts[0], &legend)?;
        for k in 0..3 {
            let p = Panel::new(
                &parts[k + 1],
                &format!(
                    "{}: a posteriori mean error in units of the filter's σ",
                    capitalized(STATE_NAMES[k])
                ),
                time.clone(),
                axes[k].clone(),
                Layout {
                    y_area_px,
                    x_title: k == 2,
                    title: true,
                },
            )?;
            p.hline(0.0, BLACK.mix(0.5).stroke_width(1))?;
            for (stats, color) in [(analytic, VERMILLION), (euler, BLUE)] {
                p.line(
                    stats.fixes.iter().map(|f| (f.time_s, normalized(f, k))),
                    color.stroke_width(2),
                )?;
            }
        }
        Ok(())
    })
}
