//! The average normalized estimation error squared (NEES) and innovation squared (NIS).

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::{Point, extent, padded, time_span};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns};
use super::{BLACK, BLUE, BLUISH_GREEN, ORANGE, PlotError, PlotResult, REFERENCE};
use crate::checks::Check;
use crate::ensemble::EnsembleStats;
use crate::state::ErrorState;

/// Height of one panel, px.
const ROW_PX: u32 = 300;
/// Width of the full-run column of a split row, px; the enlarged band takes the rest.
const FULL_COLUMN_PX: u32 = 590;
/// Dimension of the error state: the expected NEES.
const STATE_DIM: f64 = ErrorState::DIM as f64;
/// Dimension of the measurement: the expected NIS.
const MEASUREMENT_DIM: f64 = ErrorState::MEAS as f64;
/// A statistic reaching this multiple of its band's upper end (or this fraction of its lower
/// end) would flatten the band to a line on a linear axis: its row is split.
const FAR_RATIO: f64 = 3.0;
/// The enlarged band fills the middle of its axis, which reaches this many band widths beyond
/// either end.
const ZOOM_MARGIN: f64 = 1.5;

/// One statistic: its series, its band and its expected value.
struct Statistic<'a> {
    name: &'static str,
    series: Vec<(Vec<Point>, RGBColor)>,
    check: &'a Check,
    expected: f64,
}

/// How a row shows its statistic.
enum Scale {
    /// One linear axis over the values, the band and the expected value.
    Linear(Axis),
    /// The values on a log axis over the whole run, and beside it a linear axis enlarged around
    /// the band, which the values far from it run off.
    Split { log: Axis, zoom: Axis },
}

impl Statistic<'_> {
    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.series
            .iter()
            .flat_map(|(points, _)| points.iter().map(|p| p.1))
            .filter(|v| v.is_finite())
    }

    /// A linear axis when the values stay within [`FAR_RATIO`] of the band, a split otherwise.
    fn scale(&self) -> Scale {
        let name = format!("average {}", self.name);
        let (lower, upper) = (self.check.lower, self.check.upper);
        let reference = [lower, upper, self.expected];
        let all = || self.values().chain(reference);
        let far = self
            .values()
            .any(|v| v > FAR_RATIO * upper || v < lower / FAR_RATIO);
        let positive = extent(all().filter(|v| *v > 0.0));
        match positive {
            Some((lo, hi)) if far && upper > lower => {
                let w = upper - lower;
                Scale::Split {
                    log: Axis::log10(&name, "", (lo, hi)),
                    zoom: Axis::linear(
                        &name,
                        "",
                        (lower - ZOOM_MARGIN * w, upper + ZOOM_MARGIN * w),
                        5,
                    ),
                }
            }
            _ => {
                let range = extent(all()).map_or((0.0, 2.0 * self.expected), |e| padded(e, 0.08));
                Scale::Linear(Axis::linear(&name, "", range, 7))
            }
        }
    }

    /// The band (shaded, black edges), the expected value and the series on `p`, over `[t0, t1]`.
    fn draw(&self, p: &Panel<'_>, (t0, t1): (f64, f64)) -> Result<(), PlotError> {
        let (lower, upper) = (self.check.lower, self.check.upper);
        p.band(&[t0, t1], &[lower; 2], &[upper; 2], BLACK.mix(0.1))?;
        p.hline(self.expected, REFERENCE.stroke_width(1))?;
        p.hline(lower, BLACK.stroke_width(1))?;
        p.hline(upper, BLACK.stroke_width(1))?;
        for (points, color) in &self.series {
            p.line(points.iter().copied(), color.stroke_width(2))?;
        }
        Ok(())
    }
}

/// Top: the ensemble-average NEES (1/N) Σ eᵀP⁻¹e at every fix, a priori and a posteriori, against
/// its expected value 3 and the χ² band of `nees`. Bottom: the average NIS (1/N) Σ rᵀS⁻¹r against
/// 2 and the band of `nis`.
///
/// A statistic that reaches `FAR_RATIO` (3) times its band's upper end (33 against a band
/// [2.9, 3.1], say) would flatten the band to a line on a linear axis: its row then shows the
/// whole run on a log axis, and beside it the run again on an axis enlarged around the band.
pub fn consistency(stats: &EnsembleStats, nees: &Check, nis: &Check) -> PlotResult {
    let fixes = &stats.fixes;
    let (t0, t1) = time_span(fixes.iter().map(|f| f.time_s));
    let span = (t0.min(0.0), t1);
    let statistics = [
        Statistic {
            name: "NEES",
            series: vec![
                (
                    fixes.iter().map(|f| (f.time_s, f.prior.nees_avg)).collect(),
                    ORANGE,
                ),
                (
                    fixes.iter().map(|f| (f.time_s, f.post.nees_avg)).collect(),
                    BLUE,
                ),
            ],
            check: nees,
            expected: STATE_DIM,
        },
        Statistic {
            name: "NIS",
            series: vec![(
                fixes.iter().map(|f| (f.time_s, f.nis_avg)).collect(),
                BLUISH_GREEN,
            )],
            check: nis,
            expected: MEASUREMENT_DIM,
        },
    ];
    let scales: Vec<Scale> = statistics.iter().map(Statistic::scale).collect();
    let main_axes: Vec<&Axis> = scales
        .iter()
        .map(|s| match s {
            Scale::Linear(a) | Scale::Split { log: a, .. } => a,
        })
        .collect();
    let zoom_axes: Vec<&Axis> = scales
        .iter()
        .filter_map(|s| match s {
            Scale::Split { zoom, .. } => Some(zoom),
            Scale::Linear(_) => None,
        })
        .collect();
    let y_areas_px = [y_label_area(&main_axes), y_label_area(&zoom_axes)];

    let legend = [
        Entry::new(Swatch::Line(ORANGE.stroke_width(2)), "NEES, a priori"),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "NEES, a posteriori"),
        Entry::new(Swatch::Line(BLUISH_GREEN.stroke_width(2)), "NIS"),
        Entry::new(Swatch::Line(REFERENCE.stroke_width(1)), "expected value"),
        Entry::new(Swatch::Line(BLACK.stroke_width(1)), "χ² acceptance band"),
    ];
    let last_row_px = ROW_PX + 24;

    render_under_legend(&legend, &[ROW_PX, last_row_px + 6], 0, |parts| {
        for (row, (stat, scale)) in statistics.iter().zip(&scales).enumerate() {
            let over = if row == 0 {
                format!(
                    " over N = {} realizations",
                    crate::format::count(stats.realizations)
                )
            } else {
                String::new()
            };
            let last = row == statistics.len() - 1;
            stat.draw_row(&parts[row], scale, (&over, last), span, y_areas_px)?;
        }
        Ok(())
    })
}

impl Statistic<'_> {
    /// The statistic's row on `area` over the times `span`, by its `scale`: one panel, or the
    /// log-axis panel with the enlarged one beside it. The first title ends with `over`; `last`
    /// says whether the time axis is titled; the panels' y label areas are `main_px` and
    /// `zoom_px`.
    fn draw_row(
        &self,
        area: &Area<'_>,
        scale: &Scale,
        (over, last): (&str, bool),
        span: (f64, f64),
        [main_px, zoom_px]: [u32; 2],
    ) -> Result<(), PlotError> {
        let layout = |y_area_px| Layout::titled(y_area_px, last);
        let (lower, upper) = (self.check.lower, self.check.upper);
        match scale {
            Scale::Linear(axis) => {
                let p = Panel::new(
                    area,
                    &format!(
                        "Average {}{over}: expected {}, band [{lower:.3}, {upper:.3}]",
                        self.name, self.expected
                    ),
                    Axis::linear("time", "s", span, 8),
                    axis.clone(),
                    layout(main_px),
                )?;
                self.draw(&p, span)
            }
            Scale::Split { log, zoom } => {
                let cols = columns(area, &[FULL_COLUMN_PX]);
                let p = Panel::new(
                    &cols[0],
                    &format!("Average {}{over}, log axis", self.name),
                    Axis::linear("time", "s", span, 7),
                    log.clone(),
                    layout(main_px),
                )?;
                self.draw(&p, span)?;
                let q = Panel::new(
                    &cols[1],
                    &format!("Enlarged: band [{lower:.3}, {upper:.3}]"),
                    Axis::linear("time", "s", span, 4),
                    zoom.clone(),
                    layout(zoom_px),
                )?;
                self.draw(&q, span)
            }
        }
    }
}
