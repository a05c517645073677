//! A drifting bias seen by two filters: the σ each claims against the RMS error it achieves, over
//! the run, one row per state.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::extent;
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel};
use super::{
    BLUE, PlotResult, VERMILLION, capitalized, last_state, state_name, state_unit, states,
};
use crate::state::ErrorState;

/// Height of one state's panel, px.
const ROW_PX: u32 = 220;

/// One filter's series over the run.
pub struct DriftSeries {
    /// Legend label of the filter.
    pub label: String,
    /// Times, s.
    pub time_s: Vec<f64>,
    /// The σ the filter claims, per state.
    pub claimed: Vec<[f64; ErrorState::DIM]>,
    /// The RMS error it achieves, per state.
    pub achieved: Vec<[f64; ErrorState::DIM]>,
}

/// Per state, the claimed σ (thin) and the achieved RMS error (thick) of each filter against
/// time, the y axis logarithmic: where the thick line leaves the thin one of its colour, the
/// filter claims more than it achieves.
pub fn drift_sigma(series: &[DriftSeries]) -> PlotResult {
    const COLORS: [RGBColor; 2] = [VERMILLION, BLUE];
    let t = extent(series.iter().flat_map(|s| s.time_s.iter().copied())).unwrap_or((0.0, 1.0));
    let x = Axis::linear("time", "s", (0.0, t.1), 8);
    let axes: Vec<Axis> = states()
        .map(|k| {
            let values = series.iter().flat_map(|s| {
                s.claimed
                    .iter()
                    .chain(&s.achieved)
                    .map(move |v| v[k])
                    .filter(|v| *v > 0.0)
            });
            Axis::log10(
                "σ, RMS",
                state_unit(k),
                extent(values).unwrap_or((0.1, 1.0)),
            )
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let legend: Vec<Entry> = series
        .iter()
        .zip(COLORS)
        .flat_map(|(s, c)| {
            [
                Entry::new(
                    Swatch::Line(c.stroke_width(1)),
                    format!("{}: claimed σ", s.label),
                ),
                Entry::new(
                    Swatch::Line(c.stroke_width(4)),
                    format!("{}: achieved RMS", s.label),
                ),
            ]
        })
        .collect();
    render_state_rows(ROW_PX, &legend, |area, k| {
        let p = Panel::new(
            area,
            &format!(
                "{}: claimed σ and achieved RMS error",
                capitalized(state_name(k))
            ),
            x.clone(),
            axes[k].clone(),
            Layout::titled(y_area_px, last_state(k)),
        )?;
        for (s, c) in series.iter().zip(COLORS) {
            let points = |v: &[[f64; ErrorState::DIM]]| -> Vec<(f64, f64)> {
                s.time_s.iter().zip(v).map(|(&t, v)| (t, v[k])).collect()
            };
            p.line(points(&s.achieved), c.mix(0.6).stroke_width(4))?;
            p.line(points(&s.claimed), c.stroke_width(1))?;
        }
        Ok(())
    })
}
