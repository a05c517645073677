//! The three-axis study's figures: the drive (plan view and height) and one realization's biases
//! and attitude errors with the filter's ±σ against the truth.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::extent;
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns, render};
use super::{BLACK, BLUE, GREY, PlotResult, VERMILLION, WIDTH_PX};

/// Height of one row of small panels, px.
const ROW_PX: u32 = 200;

/// The drive seen from above (east against north, m) and its height against time.
pub fn ins_track(t_s: &[f64], north_m: &[f64], east_m: &[f64], height_m: &[f64]) -> PlotResult {
    let span = |v: &[f64]| extent(v.iter().copied()).unwrap_or((0.0, 1.0));
    let (n, e) = (span(north_m), span(east_m));
    // Equal metres on both axes of the plan view: the longer side sets the scale.
    let half = 0.55 * (n.1 - n.0).max(e.1 - e.0).max(1.0);
    let centre = |(lo, hi): (f64, f64)| 0.5 * (lo + hi);
    let east = Axis::linear("east", "m", (centre(e) - half, centre(e) + half), 6);
    let north = Axis::linear("north", "m", (centre(n) - half, centre(n) + half), 6);
    let time = Axis::linear("time", "s", span(t_s), 6);
    let h = span(height_m);
    let height = Axis::linear("height", "m", (h.0 - 1.0, h.1 + 1.0), 6);
    let y_area = y_label_area(&[&north, &height]);
    render(430, |root| {
        let parts = columns(root, &[WIDTH_PX / 2]);
        let plan = Panel::new(
            &parts[0],
            "The drive from above",
            east,
            north,
            Layout::titled(y_area, true),
        )?;
        plan.line(
            east_m.iter().copied().zip(north_m.iter().copied()),
            BLUE.stroke_width(2),
        )?;
        plan.dots([(east_m[0], north_m[0])], 5, BLACK.filled())?;
        let up = Panel::new(
            &parts[1],
            "Its height",
            time,
            height,
            Layout::titled(y_area, true),
        )?;
        up.line(
            t_s.iter().copied().zip(height_m.iter().copied()),
            BLUE.stroke_width(2),
        )
    })
}

/// One quantity of one realization at every fix: the estimate or error, the filter's σ and the
/// truth (None for an error, whose truth is zero).
pub struct TraceSeries<'a> {
    /// Panel title.
    pub title: String,
    /// Unit of the values.
    pub unit: &'static str,
    /// The estimate (a bias) or the error (an attitude error).
    pub value: Vec<f64>,
    /// The filter's σ.
    pub sigma: Vec<f64>,
    /// The truth, for an estimate.
    pub truth: Option<Vec<f64>>,
    /// The times, s.
    pub t_s: &'a [f64],
}

/// Panels in rows of three: each an estimate (or error) with the filter's ±σ band and the truth
/// (or zero).
pub fn ins_trace(series: &[TraceSeries<'_>]) -> PlotResult {
    let legend = [
        Entry::new(
            Swatch::Block(BLUE.mix(0.18).filled()),
            "estimate ± σ (an error: ±σ about 0)",
        ),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "estimate, or error"),
        Entry::new(Swatch::Line(VERMILLION.stroke_width(2)), "truth"),
    ];
    let rows_n = series.len().div_ceil(3);
    let heights: Vec<u32> = (0..rows_n)
        .map(|r| ROW_PX + if r + 1 == rows_n { 24 } else { 0 })
        .collect();
    render_under_legend(&legend, &heights, 6, |parts| {
        for (r, area) in parts.iter().enumerate() {
            let cells = columns(area, &[WIDTH_PX / 3, WIDTH_PX / 3]);
            for (c, cell) in cells.iter().enumerate() {
                let Some(s) = series.get(3 * r + c) else {
                    continue;
                };
                panel(cell, s, r + 1 == rows_n)?;
            }
        }
        Ok(())
    })
}

fn panel(area: &Area<'_>, s: &TraceSeries<'_>, bottom: bool) -> Result<(), super::PlotError> {
    let centre: Vec<f64> = match &s.truth {
        Some(_) => s.value.clone(),
        None => vec![0.0; s.value.len()],
    };
    let lower: Vec<f64> = centre.iter().zip(&s.sigma).map(|(c, d)| c - d).collect();
    let upper: Vec<f64> = centre.iter().zip(&s.sigma).map(|(c, d)| c + d).collect();
    let all = lower
        .iter()
        .chain(&upper)
        .chain(&s.value)
        .chain(s.truth.iter().flatten())
        .copied();
    let (lo, hi) = extent(all).unwrap_or((-1.0, 1.0));
    let pad = 0.05 * (hi - lo).max(f64::MIN_POSITIVE);
    let t = extent(s.t_s.iter().copied()).unwrap_or((0.0, 1.0));
    let name = if s.truth.is_some() { "bias" } else { "error" };
    let y = Axis::linear(name, s.unit, (lo - pad, hi + pad), 5);
    let x = Axis::linear("time", "s", (0.0, t.1), 4);
    let y_area = y_label_area(&[&y]);
    let p = Panel::new(area, &s.title, x, y, Layout::titled(y_area, bottom))?;
    p.band(s.t_s, &lower, &upper, BLUE.mix(0.18))?;
    p.line(
        s.t_s.iter().copied().zip(s.value.iter().copied()),
        BLUE.stroke_width(2),
    )?;
    if let Some(truth) = &s.truth {
        p.line(
            s.t_s.iter().copied().zip(truth.iter().copied()),
            VERMILLION.stroke_width(2),
        )?;
    } else {
        p.hline(0.0, GREY.stroke_width(1))?;
    }
    Ok(())
}
