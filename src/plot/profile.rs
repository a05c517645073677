//! Noise statistics estimated from a drive: the likelihood profile of each statistic, and the
//! estimates of many simulated drives against their truth.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::{extent, padded};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Layout, Panel};
use super::{BLACK, BLUE, BLUISH_GREEN, GREY, PlotResult, REFERENCE, VERMILLION};

/// Height of one statistic's panel, px.
const ROW_PX: u32 = 210;
/// Extra height of the bottom panel, which holds the x axis's title, px.
const AXIS_TITLE_PX: u32 = 24;
/// A profile whose values span more than this factor is drawn on a decade axis; a narrower
/// one on a linear axis (over so small a span the two differ little, and whole decades would
/// leave the profile a sliver of its panel).
const DECADE_AXIS_SPAN: f64 = 100.0;
/// Estimate / truth spanning more than this factor is drawn on an octave axis, a narrower span
/// on a linear one.
const OCTAVE_AXIS_SPAN: f64 = 4.0;
/// The deviance axis reaches this multiple of the threshold.
const DEVIANCE_TOP: f64 = 2.5;

/// The likelihood profile of one statistic.
#[derive(Clone, Debug)]
pub struct ProfileSeries {
    /// The panel's title, with `_{…}` markup allowed.
    pub title: String,
    /// The statistic's symbol for its axis, e.g. "σ_{p}".
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// (value, −2·Δℓ), in increasing value.
    pub points: Vec<(f64, f64)>,
    /// The maximum-likelihood value.
    pub value: f64,
    /// The interval's lower end; `None` when it is open (reaches the search's lower bound).
    pub lower: Option<f64>,
    /// The interval's upper end; `None` when it is open.
    pub upper: Option<f64>,
    /// The search's bounds.
    pub bounds: (f64, f64),
    /// The true value, when known.
    pub truth: Option<f64>,
}

/// The x axis of a profile spanning `lo..hi`.
fn value_axis(name: &str, unit: &str, (lo, hi): (f64, f64)) -> Axis {
    if hi > DECADE_AXIS_SPAN * lo {
        Axis::log10(name, unit, (lo, hi))
    } else {
        Axis::linear(name, unit, padded((lo, hi), 0.06), 8)
    }
}

/// The y axis of estimate / truth spanning `lo..hi`.
fn ratio_axis((lo, hi): (f64, f64)) -> Axis {
    let name = "estimate / truth";
    if hi > OCTAVE_AXIS_SPAN * lo {
        Axis::factor(name, (lo, hi))
    } else {
        Axis::linear(name, "", padded((lo, hi), 0.06), 6)
    }
}

/// Per statistic, −2·Δℓ against the statistic's value (log axis): the profile (each point the
/// maximum over the other statistics), the χ²₁ threshold whose crossings are the interval's
/// ends, the estimate, the interval along the threshold, and the search's bound where an end is
/// open (the interval is drawn reaching it).
pub fn likelihood_profile(series: &[ProfileSeries], threshold: f64) -> PlotResult {
    let y = Axis::linear(
        "−2Δℓ",
        "",
        (-0.04 * DEVIANCE_TOP * threshold, DEVIANCE_TOP * threshold),
        6,
    );
    let y_area_px = y_label_area(&[&y]);
    let mut legend = vec![
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "profile −2Δℓ"),
        Entry::new(
            Swatch::Line(VERMILLION.stroke_width(1)),
            format!("threshold χ²₁ = {}", crate::format::fixed(threshold, 2)),
        ),
        Entry::new(Swatch::Marker(BLACK.filled()), "estimate"),
        Entry::new(Swatch::Line(BLUE.mix(0.45).stroke_width(6)), "interval"),
        Entry::new(
            Swatch::Line(GREY.stroke_width(2)),
            "search bound (an open end reaches it)",
        ),
    ];
    if series.iter().any(|s| s.truth.is_some()) {
        legend.push(Entry::new(
            Swatch::Line(BLUISH_GREEN.stroke_width(2)),
            "truth",
        ));
    }
    let n = series.len();
    let heights: Vec<u32> = (0..n)
        .map(|i| ROW_PX + if i + 1 == n { AXIS_TITLE_PX } else { 0 })
        .collect();
    render_under_legend(&legend, &heights, 6, |areas| {
        for (s, area) in series.iter().zip(areas) {
            profile_panel(area, s, &y, y_area_px, threshold)?;
        }
        Ok(())
    })
}

/// One statistic's panel of [`likelihood_profile`].
fn profile_panel(
    area: &super::panel::Area<'_>,
    s: &ProfileSeries,
    y: &Axis,
    y_area_px: u32,
    threshold: f64,
) -> Result<(), super::PlotError> {
    let (lo, hi) = (s.lower.unwrap_or(s.bounds.0), s.upper.unwrap_or(s.bounds.1));
    let span = extent(
        s.points
            .iter()
            .map(|p| p.0)
            .filter(|v| *v > 0.0)
            .chain([lo, hi, s.value])
            .chain(s.truth),
    )
    .unwrap_or((0.1, 10.0));
    let x = value_axis(&s.name, &s.unit, span);
    let p = Panel::new(
        area,
        &s.title,
        x,
        y.clone(),
        Layout::titled(y_area_px, true),
    )?;
    p.hline(0.0, REFERENCE.stroke_width(1))?;
    p.hline(threshold, VERMILLION.stroke_width(1))?;
    for (end, open) in [(lo, s.lower.is_none()), (hi, s.upper.is_none())] {
        if open {
            p.vline(end, GREY.stroke_width(2))?;
        }
    }
    p.line(
        [(lo, threshold), (hi, threshold)],
        BLUE.mix(0.45).stroke_width(6),
    )?;
    if let Some(t) = s.truth {
        p.vline(t, BLUISH_GREEN.stroke_width(2))?;
    }
    // The interval's closed ends lie on the profile at the threshold: they are its crossings.
    let mut line: Vec<(f64, f64)> = s.points.clone();
    line.extend(
        [s.lower, s.upper]
            .into_iter()
            .flatten()
            .map(|e| (e, threshold)),
    );
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    p.line(line, BLUE.stroke_width(2))?;
    p.dots(s.points.iter().copied(), 2, BLUE.filled())?;
    for end in [s.lower, s.upper].into_iter().flatten() {
        p.dots([(end, threshold)], 4, BLACK.stroke_width(2))?;
    }
    p.dots([(s.value, 0.0)], 5, BLACK.filled())
}

/// One statistic's estimates over many drives, relative to the truth.
#[derive(Clone, Debug)]
pub struct RatioSeries {
    /// The panel's title, with `_{…}` markup allowed.
    pub title: String,
    /// Per drive whose statistic was identifiable: (estimate, lower, upper) / truth.
    pub drives: Vec<(f64, f64, f64)>,
}

/// Per statistic, each identifiable drive's estimate / truth with its interval, sorted by the
/// estimate (an octave axis when they span more than a factor of four); an interval that misses the truth (1) is
/// drawn in vermillion.
pub fn estimate_ratios(series: &[RatioSeries]) -> PlotResult {
    const COVERED: RGBColor = BLUE;
    const MISSED: RGBColor = VERMILLION;
    let axes: Vec<Axis> = series
        .iter()
        .map(|s| {
            ratio_axis(
                extent(
                    s.drives
                        .iter()
                        .flat_map(|d| [d.1, d.2])
                        .filter(|v| *v > 0.0)
                        .chain([1.0]),
                )
                .unwrap_or((0.5, 2.0)),
            )
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let legend = [
        Entry::new(Swatch::Marker(BLACK.filled()), "estimate / truth"),
        Entry::new(
            Swatch::Line(COVERED.stroke_width(2)),
            "interval covers the truth",
        ),
        Entry::new(Swatch::Line(MISSED.stroke_width(2)), "interval misses it"),
        Entry::new(Swatch::Line(GREY.stroke_width(1)), "1: the truth"),
    ];
    let n = series.len();
    let heights: Vec<u32> = (0..n)
        .map(|i| ROW_PX + if i + 1 == n { AXIS_TITLE_PX } else { 0 })
        .collect();
    render_under_legend(&legend, &heights, 6, |areas| {
        for (i, ((s, area), y)) in series.iter().zip(areas).zip(&axes).enumerate() {
            let mut drives = s.drives.clone();
            drives.sort_by(|a, b| a.0.total_cmp(&b.0));
            let m = drives.len().max(1) as f64;
            let x = Axis::linear("drive, by its estimate", "", (0.0, m + 1.0), 8);
            let p = Panel::new(
                area,
                &s.title,
                x,
                y.clone(),
                Layout::titled(y_area_px, i + 1 == n),
            )?;
            p.hline(1.0, GREY.stroke_width(1))?;
            for (j, d) in drives.iter().enumerate() {
                let c = if d.1 <= 1.0 && 1.0 <= d.2 {
                    COVERED
                } else {
                    MISSED
                };
                let at = j as f64 + 1.0;
                p.line([(at, d.1), (at, d.2)], c.stroke_width(2))?;
            }
            let at = |j: usize| j as f64 + 1.0;
            p.dots(
                drives.iter().enumerate().map(|(j, d)| (at(j), d.0)),
                2,
                BLACK.filled(),
            )?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(lower: Option<f64>) -> ProfileSeries {
        let mut points = vec![(0.5, 1.0), (1.0, 0.0), (2.0, 2.0), (4.0, 6.0)];
        if lower.is_none() {
            points.insert(0, (1e-3, 3.0));
        }
        ProfileSeries {
            title: "W".to_string(),
            name: "W".to_string(),
            unit: "(m/s²)²".to_string(),
            points,
            value: 1.0,
            lower,
            upper: Some(3.0),
            bounds: (1e-3, 1e3),
            truth: Some(1.2),
        }
    }

    /// Lines of `style` (`stroke="#RRGGBB" stroke-width="w"`) in `svg`.
    fn lines_of(svg: &str, color: RGBColor, width: u32) -> usize {
        let stroke = format!(
            "stroke=\"#{:02X}{:02X}{:02X}\" stroke-width=\"{width}\"",
            color.0, color.1, color.2
        );
        svg.matches(&stroke).count()
    }

    #[test]
    fn the_profile_shows_threshold_estimate_ends_and_open_bounds() {
        let closed = likelihood_profile(&[series(Some(0.3))], 3.84).unwrap();
        let open = likelihood_profile(&[series(None)], 3.84).unwrap();
        for svg in [&closed, &open] {
            assert!(svg.contains("threshold χ²₁ = 3.84"));
            // The threshold line and its legend swatch.
            assert_eq!(lines_of(svg, VERMILLION, 1), 2);
            // The estimate: a filled black dot of radius 5.
            assert!(svg.contains("r=\"5\""));
            // The truth and its swatch.
            assert_eq!(lines_of(svg, BLUISH_GREEN, 2), 2);
        }
        // Closed ends are ringed (radius 4, as is the legend's marker); an open end draws the
        // search's bound (one more grey line than the legend's swatch) and has no ring.
        assert_eq!(closed.matches("r=\"4\"").count(), 1 + 2);
        assert_eq!(open.matches("r=\"4\"").count(), 1 + 1);
        assert_eq!(lines_of(&closed, GREY, 2), 1);
        assert_eq!(lines_of(&open, GREY, 2), 2);
        // A profile over more than two decades has a decade axis.
        assert!(open.contains("10⁻³") || open.contains("10⁻²"));
    }
}
