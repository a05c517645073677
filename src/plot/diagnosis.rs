//! The figures of a calibration's diagnosis: the innovations' autocorrelation per measured
//! component against its band, and the filtered bias's departure from the smoothed one in σ of
//! their difference against its bound. Each takes the numbers of
//! [`Diagnostics`](crate::calibrate::diagnose::Diagnostics) and the per-fix series.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{max_abs, time_span};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Layout, Panel};
use super::{BLUE, ORANGE, PlotResult, REFERENCE, VERMILLION, capitalized};
use crate::calibrate::diagnose::{BiasDiagnostics, MeasurementDiagnostics, bias_departure};
use crate::calibrate::summary::FixReport;
use crate::format::{percent, short};
use crate::state::ErrorState;

/// Height of one row, px.
const ROW_PX: u32 = 230;
/// Up to this many fixes the departure is drawn as markers; more as a line through them.
const MAX_MARKERS: usize = 600;

/// A symmetric axis ±(1.15 × the largest of `values`), at least ±0.1.
fn symmetric(name: &str, unit: &str, values: impl IntoIterator<Item = f64>) -> Axis {
    let m = (1.15 * max_abs(values)).max(0.1);
    Axis::linear(name, unit, (-m, m), 6)
}

/// One row per measured component: ρ̂(ℓ) of its normalized innovations at lags 1…L as stems,
/// vermillion where outside the band ±h(ℓ) (shaded), the verdict in the title.
pub fn calibration_autocorrelation(measurements: &[MeasurementDiagnostics]) -> PlotResult {
    let lags = measurements
        .iter()
        .map(|m| m.whiteness.max_lag)
        .max()
        .unwrap_or(0)
        .max(1);
    let lag_axis = Axis::linear("lag", "fixes", (0.5, lags as f64 + 0.5), lags.min(10));
    let axes: Vec<Axis> = measurements
        .iter()
        .map(|m| {
            let w = &m.whiteness;
            symmetric(
                &format!("ρ̂ of the {} innovations", m.measurement),
                "",
                w.autocorrelation.iter().chain(&w.band).copied(),
            )
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let legend = [
        Entry::new(Swatch::Marker(BLUE.filled()), "ρ̂ inside its band"),
        Entry::new(Swatch::Marker(VERMILLION.filled()), "outside"),
        Entry::new(Swatch::Block(ORANGE.mix(0.25).filled()), "band ±h(ℓ)"),
    ];
    let heights: Vec<u32> = (0..measurements.len())
        .map(|k| ROW_PX + if k + 1 == measurements.len() { 30 } else { 0 })
        .collect();
    render_under_legend(&legend, &heights, 0, |parts| {
        for (k, (m, axis)) in measurements.iter().zip(axes).enumerate() {
            let w = &m.whiteness;
            let title = format!(
                "{} innovations: {} at α = {} over lags 1–{}",
                capitalized(m.measurement),
                match w.verdict {
                    "pass" => "white",
                    "fail" => "not white",
                    _ => "untestable",
                },
                percent(w.false_alarm_rate),
                w.max_lag
            );
            let last = k + 1 == measurements.len();
            let p = Panel::new(
                &parts[k],
                &title,
                lag_axis.clone(),
                axis,
                Layout::titled(y_area_px, last),
            )?;
            // The band held over each lag's width, so a lone lag shows its band too.
            let x: Vec<f64> = (1..=w.max_lag)
                .flat_map(|l| [l as f64 - 0.5, l as f64 + 0.5])
                .collect();
            let h: Vec<f64> = w.band.iter().flat_map(|&h| [h, h]).collect();
            let lo: Vec<f64> = h.iter().map(|h| -h).collect();
            p.band(&x, &lo, &h, ORANGE.mix(0.25))?;
            p.hline(0.0, REFERENCE.stroke_width(1))?;
            for (l, (&r, &h)) in w.autocorrelation.iter().zip(&w.band).enumerate() {
                let colour = if r.abs() > h { VERMILLION } else { BLUE };
                let at = (l + 1) as f64;
                p.line([(at, 0.0), (at, r)], colour.stroke_width(2))?;
                p.dots([(at, r)], 4, colour.filled())?;
            }
        }
        Ok(())
    })
}

/// d_i = (b̂_i − b̂^s_i) / √(P_i,bb − P^s_i,bb) at every fix where it is taken, against the
/// bound ±`bias.departure_bound_sigmas`; the title gives the largest |d_i| and the verdict.
pub fn calibration_bias_departure(fixes: &[FixReport], bias: &BiasDiagnostics) -> PlotResult {
    let b = ErrorState::BIAS;
    let points: Vec<(f64, f64)> = fixes
        .iter()
        .filter_map(|f| {
            let d = bias_departure(
                [f.filtered[b], f.filtered_sigma[b].powi(2)],
                [f.smoothed[b], f.smoothed_sigma[b].powi(2)],
            )?;
            Some((f.t_s, d))
        })
        .collect();
    let time = Axis::linear("time", "s", time_span(fixes.iter().map(|f| f.t_s)), 8);
    let bound = bias.departure_bound_sigmas;
    let bounded = if bound.is_finite() { bound } else { 0.0 };
    let axis = symmetric(
        "departure d",
        "σ",
        points.iter().map(|p| p.1).chain([bounded]),
    );
    let y_area_px = y_label_area(&[&axis]);
    let legend = [
        Entry::new(Swatch::Marker(BLUE.filled()), "d at a fix"),
        Entry::new(
            Swatch::Line(VERMILLION.stroke_width(1)),
            format!("±{} bound", short(bound)),
        ),
    ];
    render_under_legend(&legend, &[ROW_PX + 30], 0, |parts| {
        let p = Panel::new(
            &parts[0],
            &format!(
                "Filtered − smoothed bias in σ of the difference: max |d| = {} ({}), bias model {}",
                short(bias.departure_max_sigmas),
                bias.verdict,
                bias.bias_model
            ),
            time,
            axis,
            Layout::titled(y_area_px, true),
        )?;
        p.hline(0.0, REFERENCE.stroke_width(1))?;
        p.hline(bound, VERMILLION.stroke_width(1))?;
        p.hline(-bound, VERMILLION.stroke_width(1))?;
        if points.len() <= MAX_MARKERS {
            p.dots(points, 3, BLUE.filled())
        } else {
            p.line(points, BLUE.stroke_width(1))
        }
    })
}
