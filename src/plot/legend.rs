//! Legends drawn outside the data: swatches in the style each series is drawn with, laid out in
//! centred rows.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::panel::{Area, render, rows};
use super::{LEGEND_PX, PlotError, PlotResult, WIDTH_PX};
use super::{font, text_width};

/// Height of one legend row, px.
const LEGEND_ROW_PX: u32 = 24;

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
fn legend_height(entries: &[Entry]) -> u32 {
    let n = legend_rows(entries, WIDTH_PX as f64 - 40.0).len() as u32;
    n * LEGEND_ROW_PX + 8
}

/// Draws `entries` in centred rows across `area`.
fn draw_legend(area: &Area<'_>, entries: &[Entry]) -> Result<(), PlotError> {
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

/// A figure of the legend `legend` over rows of the heights `heights`, px, and a bottom margin of
/// `bottom_px`; `draw` fills the rows (their areas in order, the legend's not among them).
pub(crate) fn render_under_legend(
    legend: &[Entry],
    heights: &[u32],
    bottom_px: u32,
    draw: impl FnOnce(&[Area<'_>]) -> Result<(), PlotError>,
) -> PlotResult {
    let legend_px = legend_height(legend);
    let split: Vec<u32> = std::iter::once(legend_px)
        .chain(heights.iter().copied())
        .collect();
    render(split.iter().sum::<u32>() + bottom_px, |root| {
        let parts = rows(root, &split);
        draw_legend(&parts[0], legend)?;
        draw(&parts[1..=heights.len()])
    })
}

/// A figure of the legend `legend` over one row per state (position, velocity, bias), each
/// `row_px` high but the last, which is taller to hold the time axis's title; `draw` fills row
/// k's area.
pub(crate) fn render_state_rows(
    row_px: u32,
    legend: &[Entry],
    mut draw: impl FnMut(&Area<'_>, usize) -> Result<(), PlotError>,
) -> PlotResult {
    // The last row also holds the time axis's tick labels.
    let heights: Vec<u32> = super::states()
        .map(|k| row_px + if super::last_state(k) { 24 } else { 0 })
        .collect();
    render_under_legend(legend, &heights, 6, |parts| {
        for (k, area) in parts.iter().enumerate() {
            draw(area, k)?;
        }
        Ok(())
    })
}
