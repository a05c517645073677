//! The Allan deviation of a static log on log–log axes: the deviation at each τ with its
//! interval (whiskers), each resolved noise term as a line, the model fit over the τ where it
//! holds, and the points it misses ringed. Plain data in
//! (the caller evaluates the terms' curves), SVG out, in the look of every other figure.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::extent;
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Layout, Panel};
use super::{BLACK, BLUE, BLUISH_GREEN, GREY, ORANGE, PlotResult, REDDISH_PURPLE, VERMILLION};

/// Height of the plot, px.
const ROW_PX: u32 = 480;

/// The colours of the terms' lines, by the term's slot (quantization, velocity random walk,
/// bias instability, acceleration random walk).
pub const TERM_COLOURS: [RGBColor; 5] = [VERMILLION, REDDISH_PURPLE, BLUE, BLUISH_GREEN, ORANGE];

/// The deviation at one τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllanMark {
    /// τ, s.
    pub tau_s: f64,
    /// σ(τ), m/s².
    pub adev: f64,
    /// Its interval, when it has one.
    pub interval: Option<(f64, f64)>,
    /// Whether the fitted curve leaves the interval here.
    pub departs: bool,
}

/// A resolved term's σ(τ) as a line.
#[derive(Clone, Debug, PartialEq)]
pub struct TermCurve {
    /// Legend label, e.g. "N: slope −½".
    pub label: String,
    /// Its slot in [`TERM_COLOURS`].
    pub slot: usize,
    /// (τ s, σ m/s²) along the line.
    pub points: Vec<(f64, f64)>,
}

/// Everything the figure shows.
#[derive(Clone, Debug, PartialEq)]
pub struct AllanSeries {
    /// The deviation at every τ.
    pub marks: Vec<AllanMark>,
    /// The resolved terms.
    pub terms: Vec<TermCurve>,
    /// The fitted sum over the stretches of τ where it holds, (τ s, σ m/s²) each.
    pub sum: Vec<Vec<(f64, f64)>>,
    /// The unit of σ(τ) on the axis: m/s² for an accelerometer, rad/s for a gyro.
    pub unit: &'static str,
}

/// The Allan deviation against τ, log–log: dots with interval whiskers, the terms' lines and
/// their sum (grey).
pub fn allan_deviation(s: &AllanSeries) -> PlotResult {
    let x = Axis::log10(
        "averaging time τ",
        "s",
        extent(s.marks.iter().map(|m| m.tau_s)).unwrap_or((0.1, 10.0)),
    );
    let lows = s.marks.iter().map(|m| m.interval.map_or(m.adev, |i| i.0));
    let highs = s.marks.iter().map(|m| m.interval.map_or(m.adev, |i| i.1));
    let y = Axis::log10(
        "Allan deviation σ(τ)",
        s.unit,
        extent(lows.chain(highs).filter(|v| *v > 0.0)).unwrap_or((0.1, 10.0)),
    );
    let y_area_px = y_label_area(&[&y]);
    let mut legend = vec![
        Entry::new(Swatch::Marker(BLACK.filled()), "σ(τ)"),
        Entry::new(Swatch::Line(BLACK.stroke_width(1)), "interval"),
    ];
    for t in &s.terms {
        legend.push(Entry::new(
            Swatch::Line(TERM_COLOURS[t.slot % TERM_COLOURS.len()].stroke_width(2)),
            t.label.clone(),
        ));
    }
    legend.push(Entry::new(
        Swatch::Line(GREY.stroke_width(2)),
        "model fit, where it holds",
    ));
    if s.marks.iter().any(|m| m.departs) {
        legend.push(Entry::new(
            Swatch::Marker(VERMILLION.stroke_width(2)),
            "departs from the fit",
        ));
    }
    render_under_legend(&legend, &[ROW_PX], 6, |areas| {
        let p = Panel::new(
            &areas[0],
            "Allan deviation",
            x.clone(),
            y.clone(),
            Layout::titled(y_area_px, true),
        )?;
        for t in &s.terms {
            let c = TERM_COLOURS[t.slot % TERM_COLOURS.len()];
            p.line(t.points.iter().copied(), c.stroke_width(2))?;
        }
        for stretch in &s.sum {
            p.line(stretch.iter().copied(), GREY.stroke_width(2))?;
        }
        for m in &s.marks {
            if let Some((lo, hi)) = m.interval {
                p.line([(m.tau_s, lo), (m.tau_s, hi)], BLACK.stroke_width(1))?;
            }
        }
        p.dots(s.marks.iter().map(|m| (m.tau_s, m.adev)), 4, BLACK.filled())?;
        p.dots(
            s.marks
                .iter()
                .filter(|m| m.departs)
                .map(|m| (m.tau_s, m.adev)),
            7,
            VERMILLION.stroke_width(2),
        )
    })
}
