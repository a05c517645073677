//! The page of `accelcal allan` and the report's section on it, as views of formatted text and
//! the askama templates `allan.html` and `sections/allan.html`. Pure: HTML out, no IO.

use askama::Template;
use serde::Serialize;

use super::figure::allan_plot;
use super::{Analysis, Term, TermEstimate};
use crate::format::{count, sig};

/// Standard gravity, m/s² (for µg).
pub const STANDARD_GRAVITY_M_S2: f64 = 9.80665;

/// One term in the table: its name, SI value with interval, and datasheet units.
#[derive(Clone, Debug, Serialize)]
pub struct TermRow {
    /// The term and its symbol, as HTML.
    pub name_html: String,
    /// The value with its interval in SI units, or "unresolved, ≤ …".
    pub si: String,
    /// The same in datasheet units.
    pub datasheet: String,
}

/// One τ of the deviation table.
#[derive(Clone, Debug, Serialize)]
pub struct PointRow {
    /// τ, s.
    pub tau: String,
    /// σ(τ), m/s².
    pub adev: String,
    /// Its interval.
    pub interval: String,
    /// EDF.
    pub edf: String,
    /// The identified α.
    pub alpha: String,
}

/// Everything the page shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct AllanView {
    /// The program's version.
    pub version: String,
    /// The log and its extent, in words.
    pub source: String,
    /// Samples, τ₀, duration, in words.
    pub extent: String,
    /// The confidence as a percentage.
    pub confidence: String,
    /// The Allan plot (SVG).
    pub svg: String,
    /// The terms.
    pub terms: Vec<TermRow>,
    /// The deviation at every τ.
    pub points: Vec<PointRow>,
    /// The command that wrote the page.
    pub command: String,
}

/// The page.
#[derive(Template)]
#[template(path = "allan.html")]
pub struct AllanPage<'a> {
    /// The view.
    pub v: &'a AllanView,
    /// The stylesheet.
    pub style: &'a str,
}

fn range(t: &TermEstimate, scale: f64, digits: usize) -> String {
    match (t.value, t.lower) {
        (Some(v), Some(lo)) => {
            let [v, lo, hi] = [v, lo, t.upper].map(|x| x * scale);
            // Enough digits that an interval narrower than the last digit still shows its ends
            // apart from the estimate (at most three more).
            let apart = |d: usize| {
                (lo == v || sig(lo, d) != sig(v, d)) && (hi == v || sig(hi, d) != sig(v, d))
            };
            let d = (digits..digits + 4)
                .find(|&d| apart(d))
                .unwrap_or(digits + 3);
            format!("{} [{}, {}]", sig(v, d), sig(lo, d), sig(hi, d))
        }
        _ => format!("unresolved, ≤ {}", sig(t.upper * scale, digits)),
    }
}

/// The table row of a term: SI and datasheet units (µg/√Hz and m/s/√h for N, µg for B, µg/√s
/// for K, m/s for Q).
pub fn term_row(t: &TermEstimate) -> TermRow {
    let micro_g = 1e6 / STANDARD_GRAVITY_M_S2;
    let (name_html, si, datasheet) = match t.term {
        Term::Quantization => (
            "quantization <i>Q</i>",
            format!("{} m/s", range(t, 1.0, 3)),
            format!("{} mm/s", range(t, 1e3, 3)),
        ),
        Term::VelocityRandomWalk => (
            "velocity random walk <i>N</i>",
            format!("{} m/s/√s", range(t, 1.0, 3)),
            format!(
                "{} µg/√Hz; {} m/s/√h",
                range(t, micro_g, 3),
                range(t, 60.0, 3)
            ),
        ),
        Term::BiasInstability => (
            "bias instability <i>B</i>",
            format!("{} m/s²", range(t, 1.0, 3)),
            format!("{} µg", range(t, micro_g, 3)),
        ),
        Term::AccelerationRandomWalk => (
            "acceleration random walk <i>K</i>",
            format!("{} m/s²/√s", range(t, 1.0, 3)),
            format!("{} µg/√s", range(t, micro_g, 3)),
        ),
    };
    TermRow {
        name_html: name_html.to_string(),
        si,
        datasheet,
    }
}

fn point_rows(a: &Analysis) -> Vec<PointRow> {
    a.points
        .iter()
        .map(|p| PointRow {
            tau: sig(p.tau_s, 4),
            adev: sig(p.adev, 4),
            interval: p.interval.map_or("—".to_string(), |(lo, hi)| {
                format!("[{}, {}]", sig(lo, 3), sig(hi, 3))
            }),
            edf: p.edf.map_or("—".to_string(), |e| sig(e, 3)),
            alpha: p.noise.map_or("—".to_string(), |n| {
                let mark = if p.identified_here { "" } else { " (carried)" };
                format!("{}{mark}", n.alpha).replace('-', "−")
            }),
        })
        .collect()
}

/// The view of an analysis of the log `source`, written by `command`.
pub fn view(a: &Analysis, source: &str, command: &str) -> AllanView {
    AllanView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        source: source.to_string(),
        extent: format!(
            "{} samples, τ₀ = {} s ({} Hz), {} s",
            count(a.samples as u64),
            sig(a.sample_period_s, 6),
            sig(1.0 / a.sample_period_s, 6),
            sig(a.samples as f64 * a.sample_period_s, 4)
        ),
        confidence: sig(100.0 * a.confidence, 3),
        svg: allan_plot(a),
        terms: a.fit.terms.iter().map(term_row).collect(),
        points: point_rows(a),
        command: command.to_string(),
    }
}

/// The page of an analysis.
///
/// # Errors
/// When the template cannot be filled.
pub fn render(a: &Analysis, source: &str, command: &str) -> Result<String, askama::Error> {
    let v = view(a, source, command);
    let style = include_str!("../../assets/report.css");
    AllanPage { v: &v, style }.render()
}
