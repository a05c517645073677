//! The figures of `accelcal intrinsics`: where the poses point, and how far each pose's
//! magnitude falls from gravity's in units of its σ.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Layout, Panel, columns};
use super::{BLACK, BLUE, PlotResult, REFERENCE, VERMILLION, WIDTH_PX};

/// Height of the poses' row, px.
const POSES_PX: u32 = 470;
/// Height of the residuals' row, px.
const RESIDUALS_PX: u32 = 330;

/// Lambert's azimuthal equal-area projection of the unit vector `u` onto its hemisphere's
/// plane (x, y), seen from the pole the hemisphere holds: areas on the sphere keep their share.
fn lambert(u: &[f64; 3]) -> (f64, f64) {
    let k = (2.0 / (1.0 + u[2].abs())).sqrt();
    let mirror = if u[2] < 0.0 { -1.0 } else { 1.0 };
    (k * u[0] * mirror, k * u[1])
}

/// The poses' up directions in the sensor's axes (each pose's mean specific force, normalized)
/// on the two hemispheres z ≥ 0 and z < 0, by Lambert's equal-area projection: poses spread over
/// both discs determine every parameter; poses bunched in one place leave some free.
pub fn intrinsics_poses(ups: &[[f64; 3]], suggested: Option<[f64; 3]>) -> PlotResult {
    let edge = 2f64.sqrt();
    let x = Axis::linear("x", "", (-1.5, 1.5), 7);
    let y = Axis::linear("y", "", (-1.5, 1.5), 7);
    let y_area_px = y_label_area(&[&y]);
    let mut legend = vec![Entry::new(
        Swatch::Marker(BLUE.filled()),
        "a pose's up direction",
    )];
    if suggested.is_some() {
        legend.push(Entry::new(
            Swatch::Marker(VERMILLION.stroke_width(3)),
            "the pose to add",
        ));
    }
    render_under_legend(&legend, &[POSES_PX], 10, |rows| {
        let cols = columns(&rows[0], &[WIDTH_PX / 2]);
        for (c, upper) in [(0, true), (1, false)] {
            let title = if upper {
                "Up directions with z ≥ 0, seen from +z"
            } else {
                "Up directions with z < 0, seen from −z (x mirrored)"
            };
            let p = Panel::new(
                &cols[c],
                title,
                x.clone(),
                y.clone(),
                Layout::titled(y_area_px, true),
            )?;
            let circle: Vec<(f64, f64)> = (0..=180)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::PI / 90.0;
                    (edge * a.cos(), edge * a.sin())
                })
                .collect();
            p.line(circle, BLACK.stroke_width(1))?;
            p.hline(0.0, REFERENCE.stroke_width(1))?;
            p.vline(0.0, REFERENCE.stroke_width(1))?;
            let mine = |u: &&[f64; 3]| (u[2] >= 0.0) == upper;
            p.dots(ups.iter().filter(mine).map(lambert), 6, BLUE.filled())?;
            if let Some(s) = suggested.as_ref().filter(|s| mine(s)) {
                p.dots([lambert(s)], 9, VERMILLION.stroke_width(3))?;
            }
        }
        Ok(())
    })
}

/// Each pose's normalized residual r_j/σ_j against the pose's number, with the band ±`bound`.
pub fn intrinsics_residuals(residuals: &[f64], bound: f64) -> PlotResult {
    let n = residuals.len() as f64;
    let x = Axis::linear("pose", "", (0.5, n + 0.5), 10);
    let m = residuals.iter().fold(bound, |m, r| m.max(r.abs())).max(1.0) * 1.15;
    let y = Axis::linear("residual / σ", "", (-m, m), 7);
    let y_area_px = y_label_area(&[&y]);
    let legend = [
        Entry::new(Swatch::Marker(BLUE.filled()), "pose's |M(f̄ − b)| − g, in σ"),
        Entry::new(Swatch::Line(BLACK.stroke_width(1)), format!("±{bound:.2}")),
    ];
    render_under_legend(&legend, &[RESIDUALS_PX], 10, |rows| {
        let p = Panel::new(
            &rows[0],
            "Each pose's magnitude against gravity",
            x,
            y,
            Layout::titled(y_area_px, true),
        )?;
        p.hline(0.0, REFERENCE.stroke_width(1))?;
        p.hline(bound, BLACK.stroke_width(1))?;
        p.hline(-bound, BLACK.stroke_width(1))?;
        p.dots(
            residuals
                .iter()
                .enumerate()
                .map(|(i, r)| ((i + 1) as f64, *r)),
            5,
            BLUE.filled(),
        )?;
        Ok(())
    })
}
