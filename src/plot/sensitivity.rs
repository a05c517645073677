//! What a wrong assumption costs: the actual σ of each state against the σ the filter claims, at
//! the last fix, as each assumed statistic is scaled.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::extent;
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel};
use super::{
    BLACK, BLUE, BLUISH_GREEN, GREY, ORANGE, PlotResult, REDDISH_PURPLE, VERMILLION, capitalized,
    last_state, state_name, states,
};
use crate::state::ErrorState;

/// Height of one state's panel, px.
const ROW_PX: u32 = 230;

/// Colours of the assumed statistics, in order.
const COLORS: [RGBColor; 6] = [
    BLUE,
    VERMILLION,
    BLUISH_GREEN,
    REDDISH_PURPLE,
    ORANGE,
    BLACK,
];

/// One assumed statistic across the factors.
pub struct SensitivitySeries {
    /// Legend label: the `[filter]` key.
    pub label: String,
    /// (factor, actual σ / claimed σ per state) at each factor.
    pub points: Vec<(f64, [f64; ErrorState::DIM])>,
}

/// Per state, actual σ / claimed σ at the last fix against the factor on the assumed standard
/// deviation, one line per assumed statistic, both axes logarithmic; 1 is a filter whose claim
/// is right, above 1 an overconfident filter, below 1 a conservative one.
pub fn sigma_ratio(series: &[SensitivitySeries]) -> PlotResult {
    let factors =
        extent(series.iter().flat_map(|s| s.points.iter().map(|p| p.0))).unwrap_or((0.5, 2.0));
    let x = Axis::factor("factor on the assumed σ", factors);
    let axes: Vec<Axis> = states()
        .map(|k| {
            let (lo, hi) = extent(
                series
                    .iter()
                    .flat_map(|s| s.points.iter().map(move |p| p.1[k]))
                    .chain([1.0]),
            )
            .unwrap_or((1.0, 1.0));
            Axis::log10("actual σ / claimed σ", "", (lo.min(0.5), hi.max(2.0)))
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let mut legend: Vec<Entry> = series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            Entry::new(
                Swatch::Line(COLORS[i % COLORS.len()].stroke_width(2)),
                s.label.clone(),
            )
        })
        .collect();
    legend.push(Entry::new(
        Swatch::Line(GREY.stroke_width(1)),
        "1: the claim is right",
    ));
    render_state_rows(ROW_PX, &legend, |area, k| {
        let p = Panel::new(
            area,
            &format!(
                "{}: actual σ over claimed σ at the last fix",
                capitalized(state_name(k))
            ),
            x.clone(),
            axes[k].clone(),
            Layout::titled(y_area_px, last_state(k)),
        )?;
        p.hline(1.0, GREY.stroke_width(1))?;
        for (i, s) in series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            p.line(
                s.points.iter().map(|q| (q.0, q.1[k])),
                color.stroke_width(2),
            )?;
            p.dots(s.points.iter().map(|q| (q.0, q.1[k])), 3, color.filled())?;
        }
        Ok(())
    })
}
