//! The machinery every figure shares: axes with readable tick labels, framed panels with a title,
//! legends, and the data handling that keeps non-finite and off-scale values away from plotters.
//!
//! Figures draw straight onto a panel's plotting area with [`Panel`]'s methods rather than through
//! plotters' series and legend, so that lines can be clipped at the axes (plotters would clamp
//! them onto the frame), long series can be thinned to what the pixels can show, and the legend
//! can sit outside the data.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{
    AXIS_LABEL_PX, BLACK, FONT_FAMILY, GREY, GRID, LEGEND_PX, PlotError, PlotResult, TICK_LABEL_PX,
    TITLE_PX, WIDTH_PX,
};

/// A drawing area in pixels.
pub(crate) type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
/// A chart with linear coordinates on both axes (log axes plot log10 of their data).
type Chart<'b> = ChartContext<'b, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
/// A data point (x, y).
pub(crate) type Point = (f64, f64);

/// Average advance of a character as a fraction of the font size; generous for the common
/// sans-serif faces (DejaVu Sans digits are 0.64 em, Arial's 0.56 em).
const CHAR_EM: f64 = 0.6;
/// Height of a panel's title strip, px.
const TITLE_STRIP_PX: u32 = 28;
/// Length of the tick marks, px; plotters keeps labels two tick lengths from the axis.
const TICK_PX: i32 = 4;
/// Space left of a panel's label area, px: keeps the rotated y-axis title off the edge.
const LEFT_PAD_PX: u32 = 4;
/// Space right of a panel's plotting area, px.
const RIGHT_PAD_PX: u32 = 22;
/// Space above a panel's plotting area (below its title), px.
const TOP_PAD_PX: u32 = 4;
/// Height of one legend row, px.
const LEGEND_ROW_PX: u32 = 24;

/// A text style whose glyphs are `px` pixels high in the SVG. plotters' SVG backend writes
/// `font-size = size / 1.24`, so it is handed `px · 1.24`.
pub(crate) fn font(px: f64) -> TextStyle<'static> {
    FontDesc::from((FONT_FAMILY, px * 1.24)).color(&BLACK)
}

/// Estimated width of `text` at `px` pixels.
pub(crate) fn text_width(text: &str, px: f64) -> f64 {
    text.chars().count() as f64 * CHAR_EM * px
}

/// Draws a figure of height `height_px` (and the shared width) on a white background.
pub(crate) fn render(
    height_px: u32,
    draw: impl FnOnce(&Area<'_>) -> Result<(), PlotError>,
) -> PlotResult {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH_PX, height_px)).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// Splits `area` into stacked rows of the given heights; the last row takes what is left.
pub(crate) fn rows<'b>(area: &Area<'b>, heights: &[u32]) -> Vec<Area<'b>> {
    let mut out = Vec::with_capacity(heights.len() + 1);
    let mut rest = area.clone();
    for &h in heights {
        let (top, bottom) = rest.split_vertically(h);
        out.push(top);
        rest = bottom;
    }
    out.push(rest);
    out
}

/// Splits `area` into side-by-side columns of the given widths; the last takes what is left.
pub(crate) fn columns<'b>(area: &Area<'b>, widths: &[u32]) -> Vec<Area<'b>> {
    let mut out = Vec::with_capacity(widths.len() + 1);
    let mut rest = area.clone();
    for &w in widths {
        let (left, right) = rest.split_horizontally(w);
        out.push(left);
        rest = right;
    }
    out.push(rest);
    out
}

// ---------------------------------------------------------------------------------------------
// Axes

/// One axis: its range, its title, and how its ticks are labelled.
#[derive(Clone, Debug)]
pub(crate) struct Axis {
    name: String,
    unit: String,
    /// Range in plot coordinates: the data, or log10 of the data on a log axis.
    range: Range<f64>,
    log10: bool,
    max_ticks: usize,
    /// Linear tick labels are written in units of 10^exponent (the title says so).
    exponent: i32,
    decimals: usize,
}

impl Axis {
    /// A linear axis over `[lo, hi]` (widened when empty or degenerate) with at most `max_ticks`
    /// labelled ticks. `unit` may be empty for a dimensionless quantity.
    pub(crate) fn linear(name: &str, unit: &str, (lo, hi): (f64, f64), max_ticks: usize) -> Self {
        let range = sane_range(lo, hi);
        let mut axis = Axis {
            name: name.to_string(),
            unit: unit.to_string(),
            range,
            log10: false,
            max_ticks: max_ticks.max(2),
            exponent: 0,
            decimals: 0,
        };
        axis.choose_format();
        axis
    }

    /// A log axis covering the positive values `[lo, hi]`, widened to whole decades.
    pub(crate) fn log10(name: &str, unit: &str, (lo, hi): (f64, f64)) -> Self {
        let (lo, hi) = if lo > 0.0 && hi >= lo && hi.is_finite() {
            (lo, hi)
        } else {
            (0.1, 10.0)
        };
        let a = lo.log10().floor();
        let mut b = hi.log10().ceil();
        if b <= a {
            b = a + 1.0;
        }
        let decades = (b - a) as usize;
        Axis {
            name: name.to_string(),
            unit: unit.to_string(),
            range: a..b,
            log10: true,
            max_ticks: (decades + 1).min(8),
            exponent: 0,
            decimals: 0,
        }
    }

    /// An axis over `[lo, hi]` without ticks, labels or title.
    pub(crate) fn bare((lo, hi): (f64, f64)) -> Self {
        Axis {
            name: String::new(),
            unit: String::new(),
            range: sane_range(lo, hi),
            log10: false,
            max_ticks: 0,
            exponent: 0,
            decimals: 0,
        }
    }

    /// The axis title, e.g. "position error (10⁻³ m)".
    pub(crate) fn title(&self) -> String {
        match (self.exponent, self.unit.is_empty()) {
            (0, true) => self.name.clone(),
            (0, false) => format!("{} ({})", self.name, self.unit),
            (e, true) => format!("{} (×{})", self.name, power_of_ten(e)),
            (e, false) => format!("{} ({} {})", self.name, power_of_ten(e), self.unit),
        }
    }

    /// The value `v` in plot coordinates: NaN where it cannot be shown (≤ 0 on a log axis).
    pub(crate) fn map(&self, v: f64) -> f64 {
        if !self.log10 {
            v
        } else if v > 0.0 {
            v.log10()
        } else {
            f64::NAN
        }
    }

    /// The range in plot coordinates.
    pub(crate) fn range(&self) -> Range<f64> {
        self.range.clone()
    }

    /// The ticks plotters labels, in plot coordinates.
    fn ticks(&self) -> Vec<f64> {
        RangedCoordf64::from(self.range.clone()).key_points(self.max_ticks)
    }

    /// The label of the tick at `v` (plot coordinates).
    fn label(&self, v: f64) -> String {
        if self.log10 {
            let k = v.round();
            if (v - k).abs() < 1e-9 {
                return power_of_ten(k as i32);
            }
            return format_number(10f64.powf(v), 2);
        }
        format_number(v / 10f64.powi(self.exponent), self.decimals)
    }

    /// The widest tick label, px.
    fn label_width(&self) -> f64 {
        self.ticks()
            .iter()
            .map(|&v| text_width(&self.label(v), TICK_LABEL_PX))
            .fold(0.0, f64::max)
    }

    /// Picks the power of ten the labels are written in and the decimals they need.
    fn choose_format(&mut self) {
        let ticks = self.ticks();
        let largest = ticks.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let magnitude = if largest > 0.0 {
            largest.log10().floor() as i32
        } else {
            0
        };
        self.exponent = if (-2..=4).contains(&magnitude) {
            0
        } else {
            magnitude
        };
        let scale = 10f64.powi(self.exponent);
        let step = ticks
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() && step > 0.0 {
            step / scale
        } else {
            (self.range.end - self.range.start).abs() / scale
        };
        self.decimals = (0..=9)
            .find(|&d| {
                let f = 10f64.powi(d);
                ticks.iter().all(|&v| {
                    let x = v / scale * f;
                    (x - x.round()).abs() <= 1e-6 * (step * f).max(1.0)
                })
            })
            .unwrap_or(9) as usize;
    }
}

/// `lo..hi` when it is a finite, non-empty interval; otherwise a small interval around it.
fn sane_range(lo: f64, hi: f64) -> Range<f64> {
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) if hi > lo => lo..hi,
        (true, true) => {
            let c = 0.5 * (lo + hi);
            let h = if c == 0.0 { 1.0 } else { 0.1 * c.abs() };
            c - h..c + h
        }
        _ => -1.0..1.0,
    }
}

/// `x` with `decimals` decimals and a true minus sign; never "−0".
pub(crate) fn format_number(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        return s.trim_start_matches('-').to_string();
    }
    s.replace('-', "\u{2212}")
}

/// 10^k with a superscript exponent: "1", "10", "10⁻³".
pub(crate) fn power_of_ten(k: i32) -> String {
    match k {
        0 => "1".to_string(),
        1 => "10".to_string(),
        _ => format!("10{}", superscript(k)),
    }
}

fn superscript(k: i32) -> String {
    k.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// Width of the left label area that fits the tick labels and the rotated title of every axis
/// in `axes`: panels stacked in one column share it so that their plotting areas line up.
pub(crate) fn y_label_area(axes: &[&Axis]) -> u32 {
    let labels = axes.iter().map(|a| a.label_width()).fold(0.0, f64::max);
    let titled = axes.iter().any(|a| !a.title().is_empty());
    // Rotated title (one line), a gap, the labels, and the tick-to-label distance.
    let title = if titled {
        AXIS_LABEL_PX * 1.3 + 8.0
    } else {
        6.0
    };
    (title + labels + 2.0 * TICK_PX as f64 + 2.0).ceil() as u32
}

/// Height of the bottom label area: tick labels, and the axis title when it is shown.
fn x_label_area(with_title: bool) -> u32 {
    let ticks = 2 * TICK_PX as u32 + (TICK_LABEL_PX * 1.25) as u32 + 4;
    if with_title {
        ticks + (AXIS_LABEL_PX * 1.4) as u32 + 2
    } else {
        ticks
    }
}

// ---------------------------------------------------------------------------------------------
// Panels

/// How a panel is laid out.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    /// Width of the left label area, px (see [`y_label_area`]).
    pub y_area_px: u32,
    /// Whether the x axis shows its title under the tick labels.
    pub x_title: bool,
    /// Whether the panel has a title strip on top.
    pub title: bool,
}

/// A framed chart with its axes, ready to draw data in data coordinates.
pub(crate) struct Panel<'b> {
    chart: Chart<'b>,
    x: Axis,
    y: Axis,
}

impl<'b> Panel<'b> {
    /// Draws the title, grid, ticks, axis titles and frame of a panel filling `area`.
    pub(crate) fn new(
        area: &Area<'b>,
        title: &str,
        x: Axis,
        y: Axis,
        layout: Layout,
    ) -> Result<Self, PlotError> {
        let body = if layout.title {
            let (strip, body) = area.split_vertically(TITLE_STRIP_PX);
            strip.draw_text(
                title,
                &font(TITLE_PX).pos(Pos::new(HPos::Left, VPos::Center)),
                (
                    (LEFT_PAD_PX + layout.y_area_px) as i32,
                    TITLE_STRIP_PX as i32 / 2 + 2,
                ),
            )?;
            body
        } else {
            area.clone()
        };
        // A rotated y-axis title much longer than the plot is tall would run into the next
        // panel: it then takes the tick labels' size. (The width estimate is generous, hence the
        // slack; sizes stay whole pixels.)
        let plot_height =
            body.dim_in_pixel().1 as f64 - (TOP_PAD_PX + x_label_area(layout.x_title)) as f64;
        let y_title_px = if text_width(&y.title(), AXIS_LABEL_PX) <= 1.15 * plot_height {
            AXIS_LABEL_PX
        } else {
            TICK_LABEL_PX
        };
        let mut chart = ChartBuilder::on(&body)
            .margin_top(TOP_PAD_PX)
            .margin_left(LEFT_PAD_PX)
            .margin_right(RIGHT_PAD_PX)
            .y_label_area_size(layout.y_area_px)
            .x_label_area_size(x_label_area(layout.x_title))
            .build_cartesian_2d(x.range(), y.range())?;
        {
            let x_fmt = |v: &f64| x.label(*v);
            let y_fmt = |v: &f64| y.label(*v);
            let x_title = x.title();
            let mut mesh = chart.configure_mesh();
            mesh.x_labels(x.max_ticks)
                .y_labels(y.max_ticks)
                .max_light_lines(0)
                .bold_line_style(GRID.stroke_width(1))
                .axis_style(GREY.stroke_width(1))
                .set_all_tick_mark_size(TICK_PX)
                .label_style(font(TICK_LABEL_PX))
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt);
            if layout.x_title && !x_title.is_empty() {
                mesh.axis_desc_style(font(AXIS_LABEL_PX)).x_desc(x_title);
            }
            mesh.draw()?;
        }
        if !y.title().is_empty() {
            // Drawn as a second mesh pass without ticks or grid, so that it can take its own size.
            let y_title = y.title();
            let mut mesh = chart.configure_mesh();
            mesh.disable_mesh()
                .disable_axes()
                .x_labels(0)
                .y_labels(0)
                .axis_desc_style(font(y_title_px))
                .y_desc(y_title);
            mesh.draw()?;
        }
        let (xr, yr) = (x.range(), y.range());
        chart.plotting_area().draw(&Rectangle::new(
            [(xr.start, yr.start), (xr.end, yr.end)],
            GREY.stroke_width(1),
        ))?;
        Ok(Panel { chart, x, y })
    }

    fn area(&self) -> &DrawingArea<SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>> {
        self.chart.plotting_area()
    }

    /// Width of the plotting area, px.
    fn width_px(&self) -> usize {
        self.area().dim_in_pixel().0.max(1) as usize
    }

    /// The pixel column that plotters draws abscissa `x` (plot coordinates) in.
    fn column(&self, x: f64) -> i64 {
        i64::from(self.area().map_coordinate(&(x, self.y.range.start)).0)
    }

    /// Maps data points to plot coordinates (NaN where the y axis cannot show them).
    fn mapped(&self, points: impl IntoIterator<Item = Point>) -> Vec<Point> {
        points
            .into_iter()
            .map(|(x, y)| (self.x.map(x), self.y.map(y)))
            .collect()
    }

    /// A polyline through `points` (in x order), broken where a value is not finite and clipped
    /// at the axes; long runs are thinned to the extremes of each pixel column.
    pub(crate) fn line(
        &self,
        points: impl IntoIterator<Item = Point>,
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        let pts = self.mapped(points);
        for run in clip_polyline(&pts, &self.x.range, &self.y.range) {
            let run = thin(&run, self.width_px(), |x| self.column(x));
            self.area().draw(&PathElement::new(run, style))?;
        }
        Ok(())
    }

    /// A filled band between `lower` and `upper` at the abscissae `x`, cut at the y axis.
    /// Samples where any value is not finite split the band.
    pub(crate) fn band(
        &self,
        x: &[f64],
        lower: &[f64],
        upper: &[f64],
        color: RGBAColor,
    ) -> Result<(), PlotError> {
        let (y0, y1) = (self.y.range.start, self.y.range.end);
        let clamp = |v: f64| v.clamp(y0, y1);
        let mut runs: Vec<(Vec<Point>, Vec<Point>)> = Vec::new();
        let mut open = false;
        for ((&t, &lo), &hi) in x.iter().zip(lower).zip(upper) {
            let (t, lo, hi) = (self.x.map(t), self.y.map(lo), self.y.map(hi));
            if !(t.is_finite() && lo.is_finite() && hi.is_finite()) {
                open = false;
                continue;
            }
            if !open {
                runs.push((Vec::new(), Vec::new()));
                open = true;
            }
            let run = runs.last_mut().expect("a run was opened");
            run.0.push((t, clamp(hi)));
            run.1.push((t, clamp(lo)));
        }
        let width = self.width_px();
        for (top, bottom) in runs {
            if top.len() < 2 {
                continue;
            }
            let mut outline = thin(&top, width, |x| self.column(x));
            let mut lower = thin(&bottom, width, |x| self.column(x));
            lower.reverse();
            outline.extend(lower);
            self.area().draw(&Polygon::new(outline, color.filled()))?;
        }
        Ok(())
    }

    /// A horizontal line across the panel at `y`, when it is within the axis.
    pub(crate) fn hline(&self, y: f64, style: ShapeStyle) -> Result<(), PlotError> {
        let y = self.y.map(y);
        if y.is_finite() && y >= self.y.range.start && y <= self.y.range.end {
            let xr = &self.x.range;
            self.area()
                .draw(&PathElement::new(vec![(xr.start, y), (xr.end, y)], style))?;
        }
        Ok(())
    }

    /// A vertical line across the panel at `x`, when it is within the axis.
    pub(crate) fn vline(&self, x: f64, style: ShapeStyle) -> Result<(), PlotError> {
        let x = self.x.map(x);
        if x.is_finite() && x >= self.x.range.start && x <= self.x.range.end {
            let yr = &self.y.range;
            self.area()
                .draw(&PathElement::new(vec![(x, yr.start), (x, yr.end)], style))?;
        }
        Ok(())
    }

    /// A circle of `radius_px` at every point inside the axes.
    pub(crate) fn dots(
        &self,
        points: impl IntoIterator<Item = Point>,
        radius_px: u32,
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        for p in self.mapped(points) {
            if self.contains(p) {
                self.area().draw(&Circle::new(p, radius_px, style))?;
            }
        }
        Ok(())
    }

    /// A rectangle with corners `a` and `b` (data coordinates), cut at the axes.
    pub(crate) fn rect(&self, a: Point, b: Point, style: ShapeStyle) -> Result<(), PlotError> {
        let (a, b) = (
            (self.x.map(a.0), self.y.map(a.1)),
            (self.x.map(b.0), self.y.map(b.1)),
        );
        if [a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
            let (xr, yr) = (&self.x.range, &self.y.range);
            let cx = |v: f64| v.clamp(xr.start, xr.end);
            let cy = |v: f64| v.clamp(yr.start, yr.end);
            self.area().draw(&Rectangle::new(
                [(cx(a.0), cy(a.1)), (cx(b.0), cy(b.1))],
                style,
            ))?;
        }
        Ok(())
    }

    /// Text at a data point, anchored by `pos`.
    pub(crate) fn text(
        &self,
        at: Point,
        text: &str,
        style: &TextStyle<'_>,
        pos: Pos,
    ) -> Result<(), PlotError> {
        let at = (self.x.map(at.0), self.y.map(at.1));
        if at.0.is_finite() && at.1.is_finite() {
            let px = self.area().map_coordinate(&at);
            let base = self.area().get_base_pixel();
            self.area().strip_coord_spec().draw_text(
                text,
                &style.pos(pos),
                (px.0 - base.0, px.1 - base.1),
            )?;
        }
        Ok(())
    }

    fn contains(&self, (x, y): Point) -> bool {
        let (xr, yr) = (&self.x.range, &self.y.range);
        x.is_finite()
            && y.is_finite()
            && x >= xr.start
            && x <= xr.end
            && y >= yr.start
            && y <= yr.end
    }
}

/// Splits `points` at non-finite values and clips every segment to the rectangle `xr` × `yr`
/// (Liang–Barsky), returning the visible runs.
fn clip_polyline(points: &[Point], xr: &Range<f64>, yr: &Range<f64>) -> Vec<Vec<Point>> {
    let finite = |p: &Point| p.0.is_finite() && p.1.is_finite();
    let mut runs: Vec<Vec<Point>> = Vec::new();
    let mut open = false;
    for w in points.windows(2) {
        let (p, q) = (w[0], w[1]);
        if !(finite(&p) && finite(&q)) {
            open = false;
            continue;
        }
        match clip_segment(p, q, xr, yr) {
            Some((a, b, t0, t1)) => {
                if open && t0 == 0.0 {
                    runs.last_mut().expect("an open run").push(b);
                } else {
                    runs.push(vec![a, b]);
                }
                open = t1 == 1.0;
            }
            None => open = false,
        }
    }
    if runs.is_empty() && points.len() == 1 && finite(&points[0]) {
        let p = points[0];
        if p.0 >= xr.start && p.0 <= xr.end && p.1 >= yr.start && p.1 <= yr.end {
            runs.push(vec![p, p]);
        }
    }
    runs
}

/// The part of segment p→q inside the rectangle, with its parameters t0 ≤ t1 along p→q.
fn clip_segment(
    p: Point,
    q: Point,
    xr: &Range<f64>,
    yr: &Range<f64>,
) -> Option<(Point, Point, f64, f64)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    for (den, num) in [
        (-dx, p.0 - xr.start),
        (dx, xr.end - p.0),
        (-dy, p.1 - yr.start),
        (dy, yr.end - p.1),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| (p.0 + t * dx, p.1 + t * dy);
    Some((
        if t0 == 0.0 { p } else { at(t0) },
        if t1 == 1.0 { q } else { at(t1) },
        t0,
        t1,
    ))
}

/// Thins a run ordered in x, drawn `columns` pixels wide, to what the pixels can show: one point
/// per pixel column (`column(x)`) where the run is monotone across it, and its extremes where it
/// turns inside it (noise, or a sawtooth's drop). Coordinates are whole pixels in the SVG, so the
/// dropped points would only have drawn a staircase of vertical steps.
fn thin(run: &[Point], columns: usize, column: impl Fn(f64) -> i64) -> Vec<Point> {
    if run.len() <= columns {
        return run.to_vec();
    }
    let mut out = Vec::with_capacity(4 * columns + 4);
    let mut start = 0;
    while start < run.len() {
        let c = column(run[start].0);
        let mut end = start + 1;
        while end < run.len() && column(run[end].0) == c {
            end += 1;
        }
        let bucket = &run[start..end];
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in bucket.iter().enumerate() {
            if p.1 < bucket[lo].1 {
                lo = i;
            }
            if p.1 > bucket[hi].1 {
                hi = i;
            }
        }
        let last = bucket.len() - 1;
        let monotone = (lo == 0 && hi == last) || (hi == 0 && lo == last);
        if monotone {
            out.push(bucket[0]);
        } else {
            let mut keep = [0, lo, hi, last];
            keep.sort_unstable();
            let mut previous = usize::MAX;
            for k in keep {
                if k != previous {
                    out.push(bucket[k]);
                    previous = k;
                }
            }
        }
        start = end;
    }
    if out.last() != run.last() {
        out.extend(run.last());
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Data ranges

/// The smallest and largest finite values, if any.
pub(crate) fn extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// The largest finite |value|, or 0.
pub(crate) fn max_abs(values: impl IntoIterator<Item = f64>) -> f64 {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(0.0, |m, v| m.max(v.abs()))
}

/// `[lo, hi]` widened by `frac` of its span on both sides.
pub(crate) fn padded((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    let pad = (hi - lo) * frac;
    (lo - pad, hi + pad)
}

/// Where a run of `[t0, t1]` has left the prior behind: after its first second, or its first
/// quarter if shorter. Axes fitted to the data from here on are not set by the prior's σ
/// (10 m, 1 m/s, 0.1 m/s²), which the first GPS fixes collapse.
pub(crate) fn settled_from(t0: f64, t1: f64) -> f64 {
    t0 + (1.0f64).min(0.25 * (t1 - t0))
}

/// The first and last finite abscissa of `values`, or `[0, 1]`.
pub(crate) fn time_span(times: impl IntoIterator<Item = f64>) -> (f64, f64) {
    extent(times).unwrap_or((0.0, 1.0))
}

// ---------------------------------------------------------------------------------------------
// Legends

/// What a legend entry shows before its label, in the style the figure draws it with.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Swatch {
    /// A line segment.
    Line(ShapeStyle),
    /// A block: a band or a cell colour.
    Block(ShapeStyle),
    /// A circle, filled or open.
    Marker(ShapeStyle),
}

/// One legend entry.
#[derive(Clone, Debug)]
pub(crate) struct Entry {
    pub swatch: Swatch,
    pub label: String,
}

impl Entry {
    pub(crate) fn new(swatch: Swatch, label: impl Into<String>) -> Self {
        Entry {
            swatch,
            label: label.into(),
        }
    }
}

const SWATCH_PX: i32 = 26;
const SWATCH_GAP_PX: f64 = 7.0;
const ENTRY_GAP_PX: f64 = 26.0;

fn entry_width(e: &Entry) -> f64 {
    SWATCH_PX as f64 + SWATCH_GAP_PX + text_width(&e.label, LEGEND_PX)
}

/// Lays `entries` out in centred rows no wider than `width`.
fn legend_rows(entries: &[Entry], width: f64) -> Vec<Vec<&Entry>> {
    let mut rows: Vec<Vec<&Entry>> = Vec::new();
    let mut used = 0.0;
    for e in entries {
        let w = entry_width(e);
        match rows.last_mut() {
            Some(row) if used + ENTRY_GAP_PX + w <= width => {
                row.push(e);
                used += ENTRY_GAP_PX + w;
            }
            _ => {
                rows.push(vec![e]);
                used = w;
            }
        }
    }
    rows
}

/// Height of the legend strip that [`draw_legend`] fills for `entries` over the full width.
pub(crate) fn legend_height(entries: &[Entry]) -> u32 {
    let n = legend_rows(entries, WIDTH_PX as f64 - 40.0).len() as u32;
    n * LEGEND_ROW_PX + 8
}

/// Draws `entries` in centred rows across `area`.
pub(crate) fn draw_legend(area: &Area<'_>, entries: &[Entry]) -> Result<(), PlotError> {
    let (w, _) = area.dim_in_pixel();
    let text = font(LEGEND_PX).pos(Pos::new(HPos::Left, VPos::Center));
    for (r, row) in legend_rows(entries, w as f64 - 40.0).iter().enumerate() {
        let total: f64 = row.iter().map(|e| entry_width(e)).sum::<f64>()
            + ENTRY_GAP_PX * (row.len().saturating_sub(1)) as f64;
        let mut x = ((w as f64 - total) / 2.0).round() as i32;
        let y = 4 + r as i32 * LEGEND_ROW_PX as i32 + LEGEND_ROW_PX as i32 / 2;
        for e in row {
            draw_swatch(area, e.swatch, x, y)?;
            area.draw_text(&e.label, &text, (x + SWATCH_PX + SWATCH_GAP_PX as i32, y))?;
            x += entry_width(e).round() as i32 + ENTRY_GAP_PX as i32;
        }
    }
    Ok(())
}

fn draw_swatch(area: &Area<'_>, swatch: Swatch, x: i32, y: i32) -> Result<(), PlotError> {
    match swatch {
        Swatch::Line(style) => {
            area.draw(&PathElement::new(vec![(x, y), (x + SWATCH_PX, y)], style))?;
        }
        Swatch::Block(style) => {
            area.draw(&Rectangle::new(
                [(x, y - 7), (x + SWATCH_PX, y + 7)],
                style.filled(),
            ))?;
        }
        Swatch::Marker(style) => {
            area.draw(&Circle::new((x + SWATCH_PX / 2, y), 4, style))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_scaled_and_signed() {
        let a = Axis::linear("bias error", "m/s²", (-0.0012, 0.0012), 6);
        assert_eq!(a.title(), "bias error (10⁻³ m/s²)");
        let labels: Vec<String> = a.ticks().iter().map(|&v| a.label(v)).collect();
        assert!(labels.contains(&"0.0".to_string()), "{labels:?}");
        assert!(labels.contains(&"\u{2212}1.0".to_string()), "{labels:?}");
        let b = Axis::linear("time", "s", (0.0, 30.0), 8);
        let labels: Vec<String> = b.ticks().iter().map(|&v| b.label(v)).collect();
        assert_eq!(labels, ["0", "5", "10", "15", "20", "25", "30"]);
    }

    #[test]
    fn log_axis_labels_are_powers_of_ten() {
        let a = Axis::log10("variance", "m²", (0.003, 40.0));
        assert_eq!(a.range(), -3.0..2.0);
        let labels: Vec<String> = a.ticks().iter().map(|&v| a.label(v)).collect();
        assert_eq!(labels, ["10⁻³", "10⁻²", "10⁻¹", "1", "10", "10²"]);
    }

    #[test]
    fn clipping_breaks_lines_at_gaps_and_edges() {
        let pts = [
            (0.0, 0.0),
            (1.0, 2.0),
            (2.0, 0.0),
            (3.0, f64::NAN),
            (4.0, 0.5),
            (5.0, 0.5),
        ];
        let runs = clip_polyline(&pts, &(0.0..5.0), &(-1.0..1.0));
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[0], vec![(0.0, 0.0), (0.5, 1.0)]);
        assert_eq!(runs[1], vec![(1.5, 1.0), (2.0, 0.0)]);
        assert_eq!(runs[2], vec![(4.0, 0.5), (5.0, 0.5)]);
    }

    #[test]
    fn thinning_keeps_the_extremes_of_each_column() {
        let run: Vec<Point> = (0..1000)
            .map(|i| (i as f64 / 1000.0, if i == 501 { 9.0 } else { 0.0 }))
            .collect();
        let thin = thin(&run, 10, |x| (x * 10.0).floor() as i64);
        assert!(thin.len() <= 40);
        assert!(thin.contains(&(0.501, 9.0)));
        assert!(thin.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    #[test]
    fn numbers_never_read_minus_zero() {
        assert_eq!(format_number(-0.0001, 2), "0.00");
        assert_eq!(format_number(-1.5, 1), "\u{2212}1.5");
        assert_eq!(power_of_ten(-12), "10⁻¹²");
    }
}
