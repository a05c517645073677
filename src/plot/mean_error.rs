//! The ensemble mean error against its acceptance band.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{max_abs, settled_from, time_span};
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel, columns};
use super::{
    BLACK, BLUE, ORANGE, PlotError, PlotResult, REFERENCE, capitalized, last_state, state_name,
    state_unit, states,
};
use crate::checks::Check;
use crate::ensemble::{EnsembleStats, FixStats, StageStats};
use crate::study::StagedState;

/// Height of one state's row, px.
const ROW_PX: u32 = 240;
/// Width of the full-run column, px; the enlarged second half takes the rest.
const FULL_COLUMN_PX: u32 = 590;

/// Per state, the ensemble mean error e_ave at every fix, a posteriori and a priori, against the
/// check's band ±bound·σ/√N, where σ² is the filter's variance of that stage; beside it the
/// second half of the run, enlarged.
///
/// `predicted` holds the mean error the truth's deterministic part predicts at every fix,
/// [a priori, a posteriori]: it is drawn over the measured one (thin black lines).
///
/// The full-run axes are fitted to the statistics after the first second (or first quarter, if the
/// run is shorter), where the prior's large σ would otherwise set the scale. The band narrows as
/// σ does (a hundredfold for the bias over the default run), so the enlarged half keeps the
/// late mean error from looking like zero.
pub fn mean_error(stats: &EnsembleStats, check: &Check, predicted: &[StagedState]) -> PlotResult {
    let fixes = &stats.fixes;
    let n = stats.realizations as f64;
    let (t0, t1) = time_span(fixes.iter().map(|f| f.time_s));
    let settle = settled_from(t0, t1);
    let half = 0.5 * (t0.min(0.0) + t1);
    let band = |s: &StageStats, k: usize| check.upper * (s.filter_cov[k][k] / n).sqrt();
    // Symmetric axis of component k fitted to the fixes at or after `from`.
    let axis = |k: usize, from: f64| {
        let m = max_abs(
            fixes
                .iter()
                .zip(predicted)
                .filter(|(f, _)| f.time_s >= from)
                .flat_map(|(f, m)| {
                    [
                        f.post.mean_error[k],
                        f.prior.mean_error[k],
                        band(&f.post, k),
                        band(&f.prior, k),
                        m[0][k],
                        m[1][k],
                    ]
                }),
        );
        let m = if m > 0.0 { 1.15 * m } else { 1.0 };
        Axis::linear("e^{ave}", state_unit(k), (-m, m), 7)
    };
    let full_axes: Vec<Axis> = states().map(|k| axis(k, settle)).collect();
    let half_axes: Vec<Axis> = states().map(|k| axis(k, half)).collect();
    let full_area = y_label_area(&full_axes.iter().collect::<Vec<_>>());
    let half_area = y_label_area(&half_axes.iter().collect::<Vec<_>>());
    let full_time = Axis::linear("time", "s", (t0.min(0.0), t1), 8);
    let half_time = Axis::linear("time", "s", (half, t1), 5);

    let legend = [
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "a posteriori e^{ave}"),
        Entry::new(Swatch::Line(ORANGE.stroke_width(2)), "a priori e^{ave}"),
        Entry::new(
            Swatch::Block(BLUE.mix(0.15).filled()),
            format!("±{:.2}·σ/√N, a posteriori", check.upper),
        ),
        Entry::new(Swatch::Line(ORANGE.stroke_width(1)), "the same, a priori"),
        Entry::new(
            Swatch::Line(BLACK.stroke_width(1)),
            "predicted (noise-free pass), a posteriori",
        ),
        Entry::new(
            Swatch::Line(REFERENCE.stroke_width(1)),
            "predicted, a priori",
        ),
    ];
    render_state_rows(ROW_PX, &legend, |area, k| {
        let cols = columns(area, &[FULL_COLUMN_PX]);
        let name = capitalized(state_name(k));
        let layout = |y_area_px| Layout::titled(y_area_px, last_state(k));
        let full = Panel::new(
            &cols[0],
            &format!(
                "{name}: ensemble mean error, N = {}",
                crate::format::count(stats.realizations)
            ),
            full_time.clone(),
            full_axes[k].clone(),
            layout(full_area),
        )?;
        draw(&full, fixes, predicted, k, &band)?;
        let late = Panel::new(
            &cols[1],
            &format!("{name}: second half, enlarged"),
            half_time.clone(),
            half_axes[k].clone(),
            layout(half_area),
        )?;
        draw(&late, fixes, predicted, k, &band)?;
        Ok(())
    })
}

/// The band, the zero line, both mean errors and both predictions of component `k`.
fn draw(
    p: &Panel<'_>,
    fixes: &[FixStats],
    predicted: &[StagedState],
    k: usize,
    band: &dyn Fn(&StageStats, usize) -> f64,
) -> Result<(), PlotError> {
    let t: Vec<f64> = fixes.iter().map(|f| f.time_s).collect();
    let upper: Vec<f64> = fixes.iter().map(|f| band(&f.post, k)).collect();
    let lower: Vec<f64> = upper.iter().map(|b| -b).collect();
    p.band(&t, &lower, &upper, BLUE.mix(0.15))?;
    for sign in [1.0, -1.0] {
        p.line(
            fixes.iter().map(|f| (f.time_s, sign * band(&f.prior, k))),
            ORANGE.stroke_width(1),
        )?;
    }
    p.hline(0.0, REFERENCE.stroke_width(1))?;
    p.line(
        fixes.iter().map(|f| (f.time_s, f.prior.mean_error[k])),
        ORANGE.stroke_width(2),
    )?;
    p.line(
        fixes.iter().map(|f| (f.time_s, f.post.mean_error[k])),
        BLUE.stroke_width(2),
    )?;
    // The a priori prediction in grey under the a posteriori one in black.
    for (stage, color) in [(0, REFERENCE), (1, BLACK)] {
        p.line(
            fixes
                .iter()
                .zip(predicted)
                .map(|(f, m)| (f.time_s, m[stage][k])),
            color.stroke_width(1),
        )?;
    }
    Ok(())
}
