//! The figures of a three-axis calibration from a recording (`calibrate --imu --gnss`): the
//! estimates at every fix (the six biases, the attitude), filtered and smoothed with their ±σ
//! bands; the innovation of each measured component within ±√S; the NIS of every fix against
//! its own χ² band. Plain per-fix series in, SVG out; the track is [`super::ins_track`].

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{extent, padded, settled_from, time_span};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns};
use super::{BLACK, BLUE, BLUISH_GREEN, ORANGE, PlotError, PlotResult, VERMILLION, WIDTH_PX};

/// Height of one row of panels, px.
const ROW_PX: u32 = 210;
/// Panels per row.
const PER_ROW: usize = 3;
/// Up to this many fixes are drawn as markers; more as a thin line through them.
const MAX_MARKERS: usize = 600;

/// One estimated quantity at every fix: filtered (after the update) and smoothed, each with its σ.
pub struct EstimateSeries<'a> {
    /// Panel title.
    pub title: String,
    /// The quantity's name on the y axis.
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// The fixes' times, s.
    pub t_s: &'a [f64],
    /// The filtered estimate.
    pub filtered: Vec<f64>,
    /// Its σ.
    pub filtered_sigma: Vec<f64>,
    /// The smoothed estimate.
    pub smoothed: Vec<f64>,
    /// Its σ.
    pub smoothed_sigma: Vec<f64>,
}

/// One innovation component at every fix, NaN where the fix did not measure it.
pub struct InnovationSeries<'a> {
    /// Panel title.
    pub title: String,
    /// The component's name on the y axis.
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// The fixes' times, s.
    pub t_s: &'a [f64],
    /// The innovation ν.
    pub innovation: Vec<f64>,
    /// √S of the component.
    pub sqrt_s: Vec<f64>,
}

/// Heights of the rows that hold `n` panels, the last taller for the time axis's title.
fn row_heights(n: usize) -> Vec<u32> {
    let rows = n.div_ceil(PER_ROW);
    (0..rows)
        .map(|r| ROW_PX + if r + 1 == rows { 24 } else { 0 })
        .collect()
}

/// Panels in rows of three on `parts`; `draw` fills panel `k` (`bottom` on the last row).
fn grid(
    parts: &[Area<'_>],
    n: usize,
    mut draw: impl FnMut(&Area<'_>, usize, bool) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    let rows = parts.len();
    for (r, area) in parts.iter().enumerate() {
        let cells = columns(area, &[WIDTH_PX / 3, WIDTH_PX / 3]);
        for (c, cell) in cells.iter().enumerate() {
            let k = PER_ROW * r + c;
            if k < n {
                draw(cell, k, r + 1 == rows)?;
            }
        }
    }
    Ok(())
}

/// An axis fitted to `values`, padded by 8 %.
fn fitted(name: &str, unit: &str, values: impl IntoIterator<Item = f64>) -> Axis {
    let range = extent(values).map_or((-1.0, 1.0), |e| {
        let (lo, hi) = padded(e, 0.08);
        if hi > lo {
            (lo, hi)
        } else {
            (lo - 1.0, hi + 1.0)
        }
    });
    Axis::linear(name, unit, range, 5)
}

/// Estimates in rows of three panels: each the filtered estimate (vermillion, ±σ amber) and the
/// smoothed one (blue, ±σ blue). The y axes are fitted after the first second (or quarter) of
/// the run, once the prior's σ has collapsed.
pub fn imu_estimates(series: &[EstimateSeries<'_>]) -> PlotResult {
    let legend = [
        Entry::new(Swatch::Line(VERMILLION.stroke_width(2)), "filtered"),
        Entry::new(Swatch::Block(ORANGE.mix(0.3).filled()), "filtered ±σ"),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "smoothed"),
        Entry::new(Swatch::Block(BLUE.mix(0.2).filled()), "smoothed ±σ"),
    ];
    render_under_legend(&legend, &row_heights(series.len()), 6, |parts| {
        grid(parts, series.len(), |cell, k, bottom| {
            estimate_panel(cell, &series[k], bottom)
        })
    })
}

fn estimate_panel(area: &Area<'_>, s: &EstimateSeries<'_>, bottom: bool) -> Result<(), PlotError> {
    let (t0, t1) = time_span(s.t_s.iter().copied());
    let settle = settled_from(t0, t1);
    let band = |x: &[f64], sd: &[f64], sign: f64| -> Vec<f64> {
        x.iter().zip(sd).map(|(v, d)| v + sign * d).collect()
    };
    let (flo, fhi) = (
        band(&s.filtered, &s.filtered_sigma, -1.0),
        band(&s.filtered, &s.filtered_sigma, 1.0),
    );
    let (slo, shi) = (
        band(&s.smoothed, &s.smoothed_sigma, -1.0),
        band(&s.smoothed, &s.smoothed_sigma, 1.0),
    );
    let late = |v: &[f64]| -> Vec<f64> {
        s.t_s
            .iter()
            .zip(v)
            .filter(|(t, _)| **t >= settle)
            .map(|(_, x)| *x)
            .collect()
    };
    let y = fitted(
        s.name,
        s.unit,
        [late(&flo), late(&fhi), slo.clone(), shi.clone()].concat(),
    );
    let x = Axis::linear("time", "s", (t0, t1), 4);
    let p = Panel::new(
        area,
        &s.title,
        x,
        y.clone(),
        Layout::titled(y_label_area(&[&y]), bottom),
    )?;
    p.band(s.t_s, &flo, &fhi, ORANGE.mix(0.3))?;
    p.band(s.t_s, &slo, &shi, BLUE.mix(0.2))?;
    let at = |v: &[f64]| {
        s.t_s
            .iter()
            .copied()
            .zip(v.iter().copied())
            .collect::<Vec<_>>()
    };
    p.line(at(&s.filtered), VERMILLION.stroke_width(2))?;
    p.line(at(&s.smoothed), BLUE.stroke_width(2))
}

/// The innovation of each measured component at every fix (markers) within the ±√S and ±2√S the
/// filter predicts for it (the diagonal of S = HP⁻Hᵀ + R), in rows of three panels. The y axes
/// are fitted after the first second (or quarter) of the run.
pub fn imu_innovations(series: &[InnovationSeries<'_>]) -> PlotResult {
    let legend = [
        Entry::new(Swatch::Marker(BLUE.filled()), "innovation ν"),
        Entry::new(Swatch::Block(ORANGE.mix(0.35).filled()), "±√S"),
        Entry::new(Swatch::Block(ORANGE.mix(0.15).filled()), "±2√S"),
    ];
    render_under_legend(&legend, &row_heights(series.len()), 6, |parts| {
        grid(parts, series.len(), |cell, k, bottom| {
            innovation_panel(cell, &series[k], bottom)
        })
    })
}

fn innovation_panel(
    area: &Area<'_>,
    s: &InnovationSeries<'_>,
    bottom: bool,
) -> Result<(), PlotError> {
    let (t0, t1) = time_span(s.t_s.iter().copied());
    let settle = settled_from(t0, t1);
    let y = fitted(
        s.name,
        s.unit,
        s.t_s
            .iter()
            .zip(s.innovation.iter().zip(&s.sqrt_s))
            .filter(|(t, _)| **t >= settle)
            .flat_map(|(_, (v, d))| [*v, -2.0 * d, 2.0 * d]),
    );
    let x = Axis::linear("time", "s", (t0, t1), 4);
    let p = Panel::new(
        area,
        &s.title,
        x,
        y.clone(),
        Layout::titled(y_label_area(&[&y]), bottom),
    )?;
    let scaled = |c: f64| s.sqrt_s.iter().map(|v| c * v).collect::<Vec<_>>();
    p.band(s.t_s, &scaled(-2.0), &scaled(2.0), ORANGE.mix(0.15))?;
    p.band(s.t_s, &scaled(-1.0), &scaled(1.0), ORANGE.mix(0.35))?;
    p.hline(0.0, BLACK.mix(0.5).stroke_width(1))?;
    let points: Vec<(f64, f64)> = s
        .t_s
        .iter()
        .copied()
        .zip(s.innovation.iter().copied())
        .filter(|(_, v)| v.is_finite())
        .collect();
    if points.len() <= MAX_MARKERS {
        p.dots(points, 2, BLUE.filled())
    } else {
        p.line(points, BLUE.stroke_width(1))
    }
}

/// The NIS νᵀS⁻¹ν of every fix on a log axis against the χ²(mᵢ) band of its own number of
/// measured components mᵢ (grey, the band's ends as lines), the fixes outside it in vermillion;
/// `title` names the test of the whole sequence.
pub fn imu_nis(t_s: &[f64], nis: &[f64], [lower, upper]: [&[f64]; 2], title: &str) -> PlotResult {
    let (t0, t1) = time_span(t_s.iter().copied());
    let values = nis
        .iter()
        .chain(lower)
        .chain(upper)
        .copied()
        .filter(|v| *v > 0.0);
    let axis = Axis::log10("NIS", "", extent(values).unwrap_or((1e-3, 10.0)));
    let time = Axis::linear("time", "s", (t0, t1), 8);
    let y_area_px = y_label_area(&[&axis]);
    let legend = [
        Entry::new(Swatch::Marker(BLUISH_GREEN.filled()), "NIS of a fix"),
        Entry::new(Swatch::Marker(VERMILLION.filled()), "outside its band"),
        Entry::new(
            Swatch::Line(BLACK.stroke_width(1)),
            "χ²(mᵢ) band, mᵢ the components measured",
        ),
    ];
    render_under_legend(&legend, &[ROW_PX + 60], 6, |parts| {
        let p = Panel::new(
            &parts[0],
            title,
            time,
            axis,
            Layout::titled(y_area_px, true),
        )?;
        let at = |v: &[f64]| {
            t_s.iter()
                .copied()
                .zip(v.iter().copied())
                .collect::<Vec<_>>()
        };
        p.line(at(lower), BLACK.stroke_width(1))?;
        p.line(at(upper), BLACK.stroke_width(1))?;
        let (mut within, mut outside) = (Vec::new(), Vec::new());
        for i in 0..nis.len().min(t_s.len()) {
            let point = (t_s[i], nis[i]);
            if (lower[i]..=upper[i]).contains(&nis[i]) {
                within.push(point);
            } else {
                outside.push(point);
            }
        }
        if within.len() <= MAX_MARKERS {
            p.dots(within, 2, BLUISH_GREEN.filled())?;
        } else {
            p.line(within, BLUISH_GREEN.stroke_width(1))?;
        }
        // Drawn last and always as markers: the fixes the diagnosis counts.
        p.dots(outside, 2, VERMILLION.filled())
    })
}
