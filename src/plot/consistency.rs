//! The average normalized estimation error squared (NEES) and innovation squared (NIS).

use plotters::style::Color;

use super::panel::{
    Axis, Entry, Layout, Panel, Swatch, draw_legend, extent, legend_height, padded, render, rows,
    time_span, y_label_area,
};
use super::{BLACK, BLUE, BLUISH_GREEN, ORANGE, PlotResult};
use crate::checks::Check;
use crate::ensemble::EnsembleStats;

/// Height of one panel, px.
const ROW_PX: u32 = 300;
/// Dimension of the error state: the expected NEES.
const STATE_DIM: f64 = 3.0;
/// Dimension of the measurement: the expected NIS.
const MEASUREMENT_DIM: f64 = 2.0;

/// Top: the ensemble-average NEES (1/N) Σ eᵀP⁻¹e at every fix, a priori and a posteriori, against
/// its expected value 3 and the χ² band of `nees`. Bottom: the average NIS (1/N) Σ rᵀS⁻¹r against
/// 2 and the band of `nis`.
pub fn consistency(stats: &EnsembleStats, nees: &Check, nis: &Check) -> PlotResult {
    let fixes = &stats.fixes;
    let (t0, t1) = time_span(fixes.iter().map(|f| f.time_s));
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 8);
    let fitted = |name: &str, values: Vec<f64>, check: &Check, expected: f64| {
        let values = values
            .into_iter()
            .chain([check.lower, check.upper, expected]);
        let range = extent(values).map_or((0.0, 2.0 * expected), |e| padded(e, 0.08));
        Axis::linear(name, "", range, 7)
    };
    let nees_axis = fitted(
        "average NEES",
        fixes
            .iter()
            .flat_map(|f| [f.prior.nees_avg, f.post.nees_avg])
            .collect(),
        nees,
        STATE_DIM,
    );
    let nis_axis = fitted(
        "average NIS",
        fixes.iter().map(|f| f.nis_avg).collect(),
        nis,
        MEASUREMENT_DIM,
    );
    let y_area_px = y_label_area(&[&nees_axis, &nis_axis]);

    let legend = [
        Entry::new(Swatch::Line(ORANGE.stroke_width(2)), "NEES, a priori"),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "NEES, a posteriori"),
        Entry::new(Swatch::Line(BLUISH_GREEN.stroke_width(2)), "NIS"),
        Entry::new(
            Swatch::Line(BLACK.mix(0.4).stroke_width(1)),
            "expected value",
        ),
        Entry::new(Swatch::Line(BLACK.stroke_width(1)), "χ² acceptance band"),
    ];
    let legend_px = legend_height(&legend);
    let last_row_px = ROW_PX + 24;

    render(legend_px + ROW_PX + last_row_px + 6, |root| {
        let parts = rows(root, &[legend_px, ROW_PX, last_row_px]);
        draw_legend(&parts[0], &legend)?;
        let p = Panel::new(
            &parts[1],
            &format!(
                "Average NEES over N = {} realizations: expected {STATE_DIM}, band [{:.3}, {:.3}]",
                stats.realizations, nees.lower, nees.upper
            ),
            time.clone(),
            nees_axis,
            Layout {
                y_area_px,
                x_title: false,
                title: true,
            },
        )?;
        p.hline(STATE_DIM, BLACK.mix(0.4).stroke_width(1))?;
        p.hline(nees.lower, BLACK.stroke_width(1))?;
        p.hline(nees.upper, BLACK.stroke_width(1))?;
        p.line(
            fixes.iter().map(|f| (f.time_s, f.prior.nees_avg)),
            ORANGE.stroke_width(2),
        )?;
        p.line(
            fixes.iter().map(|f| (f.time_s, f.post.nees_avg)),
            BLUE.stroke_width(2),
        )?;

        let q = Panel::new(
            &parts[2],
            &format!(
                "Average NIS: expected {MEASUREMENT_DIM}, band [{:.3}, {:.3}]",
                nis.lower, nis.upper
            ),
            time,
            nis_axis,
            Layout {
                y_area_px,
                x_title: true,
                title: true,
            },
        )?;
        q.hline(MEASUREMENT_DIM, BLACK.mix(0.4).stroke_width(1))?;
        q.hline(nis.lower, BLACK.stroke_width(1))?;
        q.hline(nis.upper, BLACK.stroke_width(1))?;
        q.line(
            fixes.iter().map(|f| (f.time_s, f.nis_avg)),
            BLUISH_GREEN.stroke_width(2),
        )?;
        Ok(())
    })
}
