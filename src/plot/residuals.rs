//! Whiteness of the residuals: the normalized correlation of r(t_i) and r(t_m), t_m < t_i.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns, rows};
use super::{BLACK, BLUE, GRID, PlotError, PlotResult, REFERENCE, TICK_LABEL_PX, VERMILLION};
use super::{font, text_width};
use crate::checks::{Check, ResidualPair, residual_z};
use crate::ensemble::EnsembleStats;
use crate::format::fixed;
use crate::state::ErrorState;

/// Components M of a residual: residual component c of fix i is stacked at M·i + c.
const M: usize = ErrorState::MEAS;

/// Cells per side of the map at most: fixes are grouped so the map holds ≤ 50 × 50 cells.
const MAX_CELLS: usize = 50;
/// Colour levels between |z| = 0 and the bound.
const LEVELS: usize = 8;
/// Width of the map's column, px.
const MAP_COLUMN_PX: u32 = 600;
/// Height of the map panel, px.
const MAP_PX: u32 = 600;
/// Height of the colour scale, px.
const SCALE_PX: u32 = 96;
/// Colour of |z| = 0 and of |z| just below the bound.
const LOW: RGBColor = RGBColor(0xF1, 0xF6, 0xFB);
const HIGH: RGBColor = RGBColor(0x00, 0x45, 0x7A);

/// Left: every pair of fixes t_m < t_i, coloured by the largest |z| of its M² component pairs,
/// z = √N·corr(r_a(t_i), r_b(t_m)); the fixes are grouped into at most 50 × 50 cells, each showing
/// its largest |z|, with |z| beyond `check.upper` in vermillion. Right: the M² z of the
/// statement's pair against `pair.bound`.
pub fn residual_whiteness(stats: &EnsembleStats, check: &Check, pair: &ResidualPair) -> PlotResult {
    let cells = Cells::new(stats);
    let span = cells.span();
    let map_x = Axis::linear("t_{m}", "s", span, 7);
    let map_y = Axis::linear("t_{i}", "s", span, 7);
    let map_area = y_label_area(&[&map_y]);
    let (n, per_cell) = (cells.times.len(), cells.per_cell);
    let pairs = n * n.saturating_sub(1) / 2;
    let map_title = if per_cell == 1 {
        format!("All {pairs} pairs t_{{m}} < t_{{i}}")
    } else {
        format!("All {pairs} pairs t_{{m}} < t_{{i}}, in cells of {per_cell} × {per_cell} fixes")
    };

    let legend = [
        Entry::new(Swatch::Marker(BLACK.stroke_width(2)), "statement's pair"),
        Entry::new(Swatch::Marker(BLUE.filled()), "z of that pair"),
        Entry::new(Swatch::Marker(VERMILLION.filled()), "beyond the bound"),
        Entry::new(
            Swatch::Line(BLACK.stroke_width(1)),
            format!("±{:.2} bound of the pair", pair.bound),
        ),
    ];
    render_under_legend(&legend, &[MAP_PX + SCALE_PX], 6, |parts| {
        let cols = columns(&parts[0], &[MAP_COLUMN_PX]);
        let left = rows(&cols[0], &[MAP_PX]);
        let map = Panel::new(
            &left[0],
            &map_title,
            map_x,
            map_y,
            Layout::titled(map_area, true),
        )?;
        cells.draw(&map, check.upper)?;
        map.dots([(pair.t_m_s, pair.t_i_s)], 7, BLACK.stroke_width(2))?;
        draw_scale(&left[1], check.upper, map_area)?;
        draw_pair(&cols[1], pair)
    })
}

/// The fixes grouped into cells of `per_cell` × `per_cell` pairs, at most [`MAX_CELLS`] a side.
struct Cells<'a> {
    stats: &'a EnsembleStats,
    times: Vec<f64>,
    per_cell: usize,
    /// Cells per side.
    count: usize,
    /// Mean time between fixes, s (1 for fewer than two fixes).
    period: f64,
}

impl<'a> Cells<'a> {
    fn new(stats: &'a EnsembleStats) -> Self {
        let times: Vec<f64> = stats.fixes.iter().map(|f| f.time_s).collect();
        let n = times.len();
        let per_cell = n.div_ceil(MAX_CELLS).max(1);
        let period = if n >= 2 {
            (times[n - 1] - times[0]) / (n - 1) as f64
        } else {
            1.0
        };
        Self {
            stats,
            count: n.div_ceil(per_cell),
            times,
            per_cell,
            period,
        }
    }

    /// The map's extent along either axis: half a period beyond the first and last fix.
    fn span(&self) -> (f64, f64) {
        match (self.times.first(), self.times.last()) {
            (Some(&a), Some(&b)) => (a - 0.5 * self.period, b + 0.5 * self.period),
            _ => (0.0, 1.0),
        }
    }

    /// Edges of cell c along either axis: from half a period before its first fix to half a
    /// period after its last.
    fn edges(&self, c: usize) -> (f64, f64) {
        let a = c * self.per_cell;
        let b = ((c + 1) * self.per_cell).min(self.times.len()) - 1;
        (
            self.times[a] - 0.5 * self.period,
            self.times[b] + 0.5 * self.period,
        )
    }

    /// Largest |z| of a cell (row = block of t_i, column = block of t_m), NaN where empty.
    fn max_z(&self, ci: usize, cm: usize) -> f64 {
        let (n, per_cell) = (self.times.len(), self.per_cell);
        let mut worst = f64::NAN;
        for i in ci * per_cell..((ci + 1) * per_cell).min(n) {
            for m in cm * per_cell..((cm + 1) * per_cell).min(i) {
                for a in 0..M {
                    for b in 0..M {
                        let z = residual_z(self.stats, M * i + a, M * m + b).abs();
                        if z.is_finite() {
                            worst = z.max(worst);
                        }
                    }
                }
            }
        }
        worst
    }

    /// Every cell on `map`, coloured by its level against the bound `upper`.
    fn draw(&self, map: &Panel<'_>, upper: f64) -> Result<(), PlotError> {
        // Levels of every cell, by row (block of t_i) and column (block of t_m ≤ t_i).
        let grid: Vec<Vec<Option<usize>>> = (0..self.count)
            .map(|ci| {
                (0..=ci)
                    .map(|cm| level(self.max_z(ci, cm), upper))
                    .collect()
            })
            .collect();
        for (ci, row) in grid.iter().enumerate() {
            let (y0, y1) = self.edges(ci);
            // Runs of equal colour along the row are drawn as one rectangle, grown by a pixel
            // under the cells drawn after it (right, and the row above) so no seam shows.
            let mut start = 0;
            while start < row.len() {
                let mut end = start;
                while end + 1 < row.len() && row[end + 1] == row[start] {
                    end += 1;
                }
                if let Some(lv) = row[start] {
                    let right = row.get(end + 1).is_some_and(Option::is_some);
                    let up = grid
                        .get(ci + 1)
                        .is_some_and(|above| above[start..=end].iter().all(Option::is_some));
                    map.cell(
                        (self.edges(start).0, y0),
                        (self.edges(end).1, y1),
                        (i32::from(right), i32::from(up)),
                        level_color(lv).filled(),
                    )?;
                }
                start = end + 1;
            }
        }
        Ok(())
    }
}

/// The colour level of |z| = `z` against the bound `upper`: [`LEVELS`] at or beyond it, `None`
/// when undefined.
fn level(z: f64, upper: f64) -> Option<usize> {
    if !z.is_finite() {
        None
    } else if z >= upper {
        Some(LEVELS)
    } else {
        Some(((z / upper * LEVELS as f64).floor() as usize).min(LEVELS - 1))
    }
}

/// The colour scale under the map on `area`, up to 1.25 times the bound `upper`.
fn draw_scale(area: &Area<'_>, upper: f64, y_area_px: u32) -> Result<(), PlotError> {
    let scale_top = 1.25 * upper;
    let scale_x = Axis::linear(
        &format!("largest |z| in the cell (bound {})", fixed(upper, 2)),
        "",
        (0.0, scale_top),
        8,
    );
    let scale = Panel::new(
        area,
        "",
        scale_x,
        Axis::bare((-0.5, 0.5)),
        Layout {
            y_area_px,
            x_title: true,
            title: false,
        },
    )?;
    for l in 0..=LEVELS {
        let lo = upper * l as f64 / LEVELS as f64;
        let hi = if l == LEVELS {
            scale_top
        } else {
            upper * (l + 1) as f64 / LEVELS as f64
        };
        let grow = i32::from(l < LEVELS);
        scale.cell((lo, -0.5), (hi, 0.5), (grow, 0), level_color(l).filled())?;
    }
    scale.vline(upper, BLACK.stroke_width(2))?;
    Ok(())
}

/// The M² z of the statement's pair on `area`, one row per component pair, against ±bound.
fn draw_pair(area: &Area<'_>, pair: &ResidualPair) -> Result<(), PlotError> {
    let names: [&str; M] = ["r_{p}", "r_{v}"];
    // In pair.z's order: (position, position), (position, velocity), (velocity, position), ….
    let categories: Vec<String> = (0..M * M)
        .map(|c| format!("{}(t_{{i}})·{}(t_{{m}})", names[c / M], names[c % M]))
        .collect();
    let zs = pair.z.iter().flatten().copied().collect::<Vec<_>>();
    let reach = zs
        .iter()
        .filter(|z| z.is_finite())
        .fold(pair.bound, |m, z| m.max(z.abs()));
    let pair_x = Axis::linear("z = √N · correlation", "", (-1.2 * reach, 1.2 * reach), 5);
    // Each component pair is named, with its z, left of the plot, clear of its lines and dots.
    let pair_labels: Vec<[String; 2]> = zs
        .iter()
        .zip(&categories)
        .map(|(&z, name)| {
            let value = if z.is_finite() {
                format!("z = {}", fixed(z, 2))
            } else {
                "undefined".to_string()
            };
            [name.clone(), value]
        })
        .collect();
    let pair_area = pair_labels
        .iter()
        .flatten()
        .map(|l| text_width(l, TICK_LABEL_PX))
        .fold(0.0, f64::max)
        .ceil() as u32
        + 14;
    let p = Panel::new(
        area,
        &format!(
            "Pair t_{{m}} = {} s, t_{{i}} = {} s",
            fixed(pair.t_m_s, 1),
            fixed(pair.t_i_s, 1)
        ),
        pair_x,
        Axis::bare((-0.5, 3.5)),
        Layout::titled(pair_area, true),
    )?;
    p.vline(0.0, REFERENCE.stroke_width(1))?;
    p.vline(pair.bound, BLACK.stroke_width(1))?;
    p.vline(-pair.bound, BLACK.stroke_width(1))?;
    // One row per component pair, top to bottom.
    for (idx, (&z, lines)) in zs.iter().zip(&pair_labels).enumerate() {
        let y = (3 - idx) as f64;
        p.hline(y, GRID.stroke_width(1))?;
        p.label_left(y, lines, &font(TICK_LABEL_PX))?;
        let color = if z.abs() > pair.bound {
            VERMILLION
        } else {
            BLUE
        };
        p.dots([(z, y)], 6, color.filled())?;
    }
    Ok(())
}

/// Colour of level `l`: a ramp from light to dark blue below the bound, vermillion at it.
fn level_color(l: usize) -> RGBColor {
    if l >= LEVELS {
        return VERMILLION;
    }
    let f = (l as f64 + 0.5) / LEVELS as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    RGBColor(mix(LOW.0, HIGH.0), mix(LOW.1, HIGH.1), mix(LOW.2, HIGH.2))
}
