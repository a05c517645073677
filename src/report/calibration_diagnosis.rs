//! The diagnosis on a calibration's page: the sentences the numbers choose, a table of each
//! measured component's whiteness and mean square, the fixes outside the per-fix NIS band, the
//! bias's path, and two figures (the innovations' autocorrelation, the bias's departure).

use serde::Serialize;

use super::RenderError;
use super::rich::rich;
use super::view::{FigureView, VerdictView};
use crate::calibrate::diagnose::{BiasDiagnostics, Diagnostics, MeasurementDiagnostics};
use crate::calibrate::diagnose::{NisPerFix, lag_runs};
use crate::calibrate::summary::Calibration;
use crate::format::{count, percent, short, sig};
use crate::plot;

/// Fixes outside the per-fix NIS band named by time on the page.
const TIMES_SHOWN: usize = 20;

/// One measured component's tests, as text.
#[derive(Clone, Debug, Serialize)]
pub struct DiagnosisRow {
    /// "position" or "velocity".
    pub measurement: String,
    /// The whiteness verdict.
    pub verdict: VerdictView,
    /// The lags outside their band ("none", "1–20").
    pub lags_outside: String,
    /// ρ̂(1) with its band.
    pub lag_one: String,
    /// The mean square of u with its band and place.
    pub mean_square: String,
    /// The GPS's share of the predicted variance.
    pub gps_share: String,
    /// The GPS σ assumed, and the one the residuals suggest.
    pub gps_sigma: String,
}

/// The diagnosis as the page shows it.
#[derive(Clone, Debug, Serialize)]
pub struct DiagnosisView {
    /// How the tests are taken, as HTML.
    pub method_html: String,
    /// The sentences, plain text.
    pub findings: Vec<String>,
    /// The table's number.
    pub table_number: usize,
    /// One row per measured component.
    pub rows: Vec<DiagnosisRow>,
    /// The fixes outside the per-fix NIS band, as HTML.
    pub nis_html: String,
    /// The bias's path, as HTML.
    pub bias_html: String,
    /// The autocorrelation and the bias's departure.
    pub figures: Vec<FigureView>,
}

/// The view of `cal`'s diagnosis, its table numbered `table_number` and its figures from
/// `first_figure` on.
///
/// # Errors
/// [`RenderError::Figure`] when a figure cannot be drawn.
pub fn build(
    cal: &Calibration,
    table_number: usize,
    first_figure: usize,
) -> Result<DiagnosisView, RenderError> {
    let d = &cal.summary.diagnostics;
    let fig = |id: &str, svg: Result<String, plot::PlotError>| {
        svg.map_err(|source| RenderError::Figure {
            figure: id.to_string(),
            source,
        })
    };
    let figures = vec![
        FigureView {
            id: "fig-autocorrelation".into(),
            number: first_figure,
            title: "Whiteness of the innovations".into(),
            caption_html: rich(
                "The sample autocorrelation ρ̂(ℓ) of each component's normalized innovations \
                 u_{i} = r_{i}/√S_{i} at lags ℓ = 1…L fixes, within the band ±h(ℓ) that holds \
                 a white sequence's ρ̂(ℓ) with probability 1 − α_{w}/L; a lag outside it \
                 (vermillion) makes the component not white.",
            ),
            svg: fig(
                "fig-autocorrelation",
                plot::calibration_autocorrelation(&d.measurements),
            )?,
        },
        FigureView {
            id: "fig-bias-departure".into(),
            number: first_figure + 1,
            title: "The bias's path against its model".into(),
            caption_html: rich(
                "At each fix, the filtered bias minus the smoothed one in σ of their \
                 difference, d = (b̂ − b̂^{s})/√(P − P^{s}), N(0, 1) for a consistent filter \
                 whatever its bias model, with the bound on max |d| at α. Figure 1 shows the \
                 smoothed bias itself with its ±1σ band.",
            ),
            svg: fig(
                "fig-bias-departure",
                plot::calibration_bias_departure(&cal.fixes, &d.bias),
            )?,
        },
    ];
    Ok(DiagnosisView {
        method_html: method(d),
        findings: d.findings.clone(),
        table_number,
        rows: d.measurements.iter().map(row).collect(),
        nis_html: nis_words(&d.nis_per_fix),
        bias_html: bias_words(&d.bias),
        figures,
    })
}

/// How the tests are taken.
fn method(d: &Diagnostics) -> String {
    let lags = d.measurements.first().map_or(0, |m| m.whiteness.max_lag);
    rich(&format!(
        "A consistent filter's innovations are independent, each N(0, S_{{i}}). Each component \
         normalized by its predicted σ, u_{{i}} = r_{{i}}/√S_{{i}}, is tested for whiteness (its \
         autocorrelation at lags 1–{lags}, L = min(20, n/10), each lag against a band from the \
         exact variance (n − ℓ)/(n(n + 2)) under whiteness, the lags splitting α_{{w}} = α/M = \
         {} evenly) and for its mean square (χ²(n)/n, at α/M). The fixes arrive at {} Hz. The \
         sentences below are chosen by these tests at α = {}.",
        percent(d.false_alarm_rate / d.measurements.len().max(1) as f64),
        short(d.fix_rate_hz),
        percent(d.false_alarm_rate)
    ))
}

/// A component's row of the table.
fn row(m: &MeasurementDiagnostics) -> DiagnosisRow {
    let w = &m.whiteness;
    let [lo, hi] = m.mean_square_band;
    DiagnosisRow {
        measurement: m.measurement.to_string(),
        verdict: match w.verdict {
            "pass" => VerdictView::Pass,
            "fail" => VerdictView::Fail,
            _ => VerdictView::Untestable,
        },
        lags_outside: if w.lags_outside.is_empty() {
            "none".to_string()
        } else {
            lag_runs(&w.lags_outside)
        },
        lag_one: match (w.autocorrelation.first(), w.band.first()) {
            (Some(r), Some(h)) => format!("{} (±{})", sig(*r, 2), sig(*h, 2)),
            _ => "—".to_string(),
        },
        mean_square: format!(
            "{} (band [{}, {}]): {}",
            sig(m.mean_square, 3),
            sig(lo, 3),
            sig(hi, 3),
            match m.mean_square_place {
                "in" => "as predicted",
                "below" => "below",
                _ => "above",
            }
        ),
        gps_share: percent(m.gps_share),
        gps_sigma: match m.gps_sigma_from_residuals {
            Some(s) => format!(
                "{} {} → {} {}",
                short(m.gps_sigma),
                m.unit,
                sig(s, 2),
                m.unit
            ),
            None => format!("{} {} → —", short(m.gps_sigma), m.unit),
        },
    }
}

/// The fixes outside the per-fix NIS band.
fn nis_words(p: &NisPerFix) -> String {
    let times: Vec<String> = p
        .outside_t_s
        .iter()
        .take(TIMES_SHOWN)
        .map(|t| short(*t))
        .collect();
    let listed = if times.is_empty() {
        String::new()
    } else {
        let more = if p.outside > times.len() { ", …" } else { "" };
        format!(" They are at t = {}{more} s.", times.join(", "))
    };
    rich(&format!(
        "{} fixes have their NIS outside the per-fix χ²(2) band [{}, {}] ({} above, {} below); \
         a consistent filter puts about {} outside and more than {} with probability at most \
         α = {}: {}.{listed}",
        count(p.outside as u64),
        sig(p.lower, 3),
        sig(p.upper, 3),
        count(p.above as u64),
        count(p.below as u64),
        sig(p.expected_outside, 2),
        count(p.outside_bound),
        percent(p.false_alarm_rate),
        if p.verdict == "pass" {
            "as chance explains"
        } else {
            "more than chance explains"
        }
    ))
}

/// The bias's path in words.
fn bias_words(b: &BiasDiagnostics) -> String {
    let path = if b.bias_model == "constant" {
        // The smoother of a constant bias gives one number; its spread is rounding.
        format!(
            "The filter holds the bias constant, so the smoothed bias is one number, {} m/s².",
            sig(b.smoothed_max_m_s2, 4)
        )
    } else {
        format!(
            "The smoothed bias runs from {} to {} m/s², {} times its median smoothed σ.",
            sig(b.smoothed_min_m_s2, 4),
            sig(b.smoothed_max_m_s2, 4),
            sig(b.smoothed_range_sigmas, 2)
        )
    };
    rich(&format!(
        "{path} Over the {} fixes where the smoother adds information, the filtered bias \
         departs from the smoothed by at most {} σ of their difference (at t = {} s), against a \
         bound of {} σ: {}.",
        count(b.departure_fixes as u64),
        sig(b.departure_max_sigmas, 3),
        short(b.departure_t_s),
        sig(b.departure_bound_sigmas, 3),
        match b.verdict {
            "pass" => "the bias moves as its model allows",
            "fail" => "the bias moves more than its model allows",
            _ => "untestable",
        }
    ))
}
