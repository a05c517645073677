//! Framed panels: a figure's canvas split into rows and columns, and a chart with a title, grid,
//! ticks and axis titles that figures draw on in data coordinates.
//!
//! Figures draw straight onto a panel's plotting area with [`Panel`]'s methods rather than through
//! plotters' series and legend, so that lines can be clipped at the axes (plotters would clamp
//! them onto the frame), long series can be thinned to what the pixels can show, and the legend
//! can sit outside the data.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::{Axis, TICK_PX, x_label_area};
use super::geometry::{Point, clip_polyline, thin};
use super::markup::{drawn_chars, scripts_to_tspans};
use super::{
    AXIS_LABEL_PX, GREY, GRID, PlotError, PlotResult, TICK_LABEL_PX, TITLE_PX, WIDTH_PX, font,
    text_width,
};

/// A drawing area in pixels.
pub(crate) type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
/// A chart with linear coordinates on both axes (log axes plot log10 of their data).
type Chart<'b> = ChartContext<'b, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Height of a panel's title strip, px.
const TITLE_STRIP_PX: u32 = 28;
/// Space left of a panel's label area, px: keeps the rotated y-axis title off the edge.
const LEFT_PAD_PX: u32 = 4;
/// Space right of a panel's plotting area, px.
const RIGHT_PAD_PX: u32 = 22;
/// Space above a panel's plotting area (below its title), px.
const TOP_PAD_PX: u32 = 4;
/// Smallest size a panel title shrinks to when it is too long for its panel, px.
const MIN_TITLE_PX: f64 = 14.0;
/// Average advance of a title's characters (mostly lower case and spaces), in em: DejaVu Sans
/// sets such text at about 0.53 em, Liberation Sans and Arial at about 0.45 em; a title that
/// DejaVu makes a little longer runs into the panel's right margin. (Layout elsewhere uses the
/// more generous [`text_width`], which also covers runs of digits.)
const TITLE_CHAR_EM: f64 = 0.5;
/// Distance between labels left of a plot ([`Panel::label_left`]) and its frame, px.
const LABEL_GAP_PX: i32 = 8;
/// Line pitch of those labels, in units of their font's size (plotters' size, 1.24 × the glyph
/// height in pixels).
const LABEL_LINE_EM: f64 = 1.1;

/// Where a panel's title starts and its size, px: over the plot's left edge (after the label
/// area of `y_area_px`) at [`TITLE_PX`] when it fits before the panel's right edge
/// (`width_px`); a longer title starts at the panel's left edge, and shrinks if it must (to
/// [`MIN_TITLE_PX`] at most, a wider panel being the better fix).
fn title_fit(title: &str, width_px: u32, y_area_px: u32) -> (i32, f64) {
    let fits = |from: u32, px: f64| {
        drawn_chars(title) * TITLE_CHAR_EM * px <= f64::from(width_px.saturating_sub(from + 4))
    };
    let plot_left = LEFT_PAD_PX + y_area_px;
    if fits(plot_left, TITLE_PX) {
        return (plot_left as i32, TITLE_PX);
    }
    let mut px = TITLE_PX;
    while px > MIN_TITLE_PX && !fits(LEFT_PAD_PX, px) {
        px -= 1.0;
    }
    (LEFT_PAD_PX as i32, px)
}

/// Draws a figure of height `height_px` (and the shared width) on a white background, and sets
/// the sub- and superscript markup of its text (`p_{c}`, `e^{ave}`) as scripts.
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
    Ok(scripts_to_tspans(&svg))
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

/// How a panel is laid out.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    /// Width of the left label area, px (see [`super::axis::y_label_area`]).
    pub y_area_px: u32,
    /// Whether the x axis shows its title under the tick labels.
    pub x_title: bool,
    /// Whether the panel has a title strip on top.
    pub title: bool,
}

impl Layout {
    /// A panel with a title strip, its x-axis title shown when `x_title` (the bottom row).
    pub fn titled(y_area_px: u32, x_title: bool) -> Self {
        Self {
            y_area_px,
            x_title,
            title: true,
        }
    }
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
            let (x, px) = title_fit(title, strip.dim_in_pixel().0, layout.y_area_px);
            strip.draw_text(
                title,
                &font(px).pos(Pos::new(HPos::Left, VPos::Center)),
                (x, TITLE_STRIP_PX as i32 / 2 + 2),
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

    /// A cell of a map: the rectangle with corners `a` and `b` (data coordinates), cut at the
    /// axes and grown by `grow.0` pixels to the right and `grow.1` upwards. Cells drawn left to
    /// right and bottom to top, each grown under its right and upper neighbour, leave no
    /// anti-aliased seam between them when the figure is scaled.
    pub(crate) fn cell(
        &self,
        a: Point,
        b: Point,
        grow: (i32, i32),
        style: ShapeStyle,
    ) -> Result<(), PlotError> {
        let (a, b) = (
            (self.x.map(a.0), self.y.map(a.1)),
            (self.x.map(b.0), self.y.map(b.1)),
        );
        if ![a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        let (xr, yr) = (&self.x.range, &self.y.range);
        let clamp = |(x, y): Point| (x.clamp(xr.start, xr.end), y.clamp(yr.start, yr.end));
        let (pa, pb) = (
            self.area().map_coordinate(&clamp(a)),
            self.area().map_coordinate(&clamp(b)),
        );
        let (xs, ys) = self.area().get_pixel_range();
        let left = pa.0.min(pb.0);
        let right = (pa.0.max(pb.0) + grow.0).min(xs.end - 1);
        let top = (pa.1.min(pb.1) - grow.1).max(ys.start);
        let bottom = pa.1.max(pb.1);
        let base = self.area().get_base_pixel();
        self.area().strip_coord_spec().draw(&Rectangle::new(
            [
                (left - base.0, top - base.1),
                (right - base.0, bottom - base.1),
            ],
            style,
        ))?;
        Ok(())
    }

    /// Lines of text right-aligned in the label area left of the plot, centred on ordinate `y`:
    /// labels of categories that keep clear of everything drawn in the plot.
    pub(crate) fn label_left(
        &self,
        y: f64,
        lines: &[String],
        style: &TextStyle<'_>,
    ) -> Result<(), PlotError> {
        let y = self.y.map(y);
        if !y.is_finite() || y < self.y.range.start || y > self.y.range.end {
            return Ok(());
        }
        let at = self.area().map_coordinate(&(self.x.range.start, y));
        let base = self.area().get_base_pixel();
        let line_px = (LABEL_LINE_EM * style.font.get_size()).round() as i32;
        let top = at.1 - base.1 - line_px * lines.len() as i32 / 2;
        for (i, line) in lines.iter().enumerate() {
            self.area().strip_coord_spec().draw_text(
                line,
                &style.pos(Pos::new(HPos::Right, VPos::Center)),
                (-LABEL_GAP_PX, top + line_px * i as i32 + line_px / 2),
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
