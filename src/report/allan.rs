//! The page of `accelcal allan` (its view, its template `allan.html` on the report's base
//! template, stylesheet and math) and the Allan figure the report's static-noise section shares
//! with it, drawn by [`crate::plot::allan_deviation`]. Pure: HTML out, no IO.

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::math::Math;
use super::view::FigureView;
use super::{RenderError, stylesheet};
use crate::allan::{Analysis, Term, TermEstimate};
use crate::format::{count, sig};
use crate::plot::{self, AllanMark, AllanSeries, TermCurve};

/// The fitted model of the Allan variance (IEEE Std 952, annex C), as LaTeX.
const MODEL: &str = r"\sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau} + \frac{2\ln 2}{\pi}B^2 + \frac{K^2\tau}{3}";

/// Points along each curve of the figure.
pub const CURVE_POINTS: usize = 200;

/// The label of a term's line.
fn term_label(term: Term) -> &'static str {
    match term {
        Term::Quantization => "Q: slope −1",
        Term::VelocityRandomWalk => "N: slope −½",
        Term::BiasInstability => "B: slope 0",
        Term::AccelerationRandomWalk => "K: slope +½",
        Term::RateRamp => "R: slope +1",
    }
}

/// The figure's data: the deviation at every τ, each resolved term's σ(τ) and the fitted sum,
/// evaluated at [`CURVE_POINTS`] log-spaced τ over the whole decades the points span.
pub fn series(a: &Analysis) -> AllanSeries {
    let decades = |f: fn(f64, f64) -> f64, start: f64| {
        a.points.iter().map(|p| p.tau_s.log10()).fold(start, f)
    };
    let (x0, x1) = (
        decades(f64::min, f64::INFINITY).floor(),
        decades(f64::max, f64::NEG_INFINITY).ceil(),
    );
    let x1 = x1.max(x0 + 1.0);
    let taus: Vec<f64> = (0..=CURVE_POINTS)
        .map(|i| 10f64.powf(x0 + (x1 - x0) * i as f64 / CURVE_POINTS as f64))
        .collect();
    let curve = |sigma: &dyn Fn(f64) -> f64| taus.iter().map(|&t| (t, sigma(t))).collect();
    AllanSeries {
        marks: a
            .points
            .iter()
            .map(|p| AllanMark {
                tau_s: p.tau_s,
                adev: p.adev,
                interval: p.interval,
            })
            .collect(),
        terms: a
            .fit
            .terms
            .iter()
            .filter(|t| t.value.is_some())
            .map(|t| TermCurve {
                label: term_label(t.term).to_string(),
                slot: Term::ALL.iter().position(|&u| u == t.term).unwrap_or(0),
                points: curve(&|tau| (t.squared * t.term.coefficient(tau)).sqrt()),
            })
            .collect(),
        sum: curve(&|tau| a.fit.avar_at(tau).max(0.0).sqrt()),
    }
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
    /// The Allan plot.
    pub figure: FigureView,
    /// The fitted model σ²(τ), as MathML (left out of view.json).
    #[serde(skip)]
    pub model_math: String,
    /// The terms.
    pub terms: Vec<TermRow>,
    /// The deviation at every τ.
    pub points: Vec<PointRow>,
    /// The command that wrote the page.
    pub command: String,
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
        Term::RateRamp => (
            "rate ramp <i>R</i>",
            format!("{} m/s³", range(t, 1.0, 3)),
            format!("{} µg/s", range(t, micro_g, 3)),
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
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn.
pub fn view(
    a: &Analysis,
    source: &str,
    command: &str,
    math: &Math,
) -> Result<AllanView, RenderError> {
    let confidence = sig(100.0 * a.confidence, 3);
    let figure = figure(
        "allan-plot",
        1,
        "The Allan deviation of the log",
        &format!(
            "The overlapping Allan deviation (dots) at octave-spaced τ with its {confidence} % χ² intervals (whiskers; equivalent degrees of freedom of Greenhall and Riley for the noise identified at each τ by its lag-1 autocorrelation), each resolved noise term as a line of its slope, and their sum (grey)."
        ),
        plot::allan_deviation(&series(a)),
    )?;
    Ok(AllanView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        source: source.to_string(),
        extent: format!(
            "{} samples, τ₀ = {} s ({} Hz), {} s",
            count(a.samples as u64),
            sig(a.sample_period_s, 6),
            sig(1.0 / a.sample_period_s, 6),
            sig(a.samples as f64 * a.sample_period_s, 4)
        ),
        confidence,
        figure,
        model_math: math.inline(MODEL),
        terms: a.fit.terms.iter().map(term_row).collect(),
        points: point_rows(a),
        command: command.to_string(),
    })
}

/// The page of an analysis of the log `source`, written by `command`.
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn or the template cannot be filled.
pub fn render(a: &Analysis, source: &str, command: &str) -> Result<String, RenderError> {
    let v = view(a, source, command, &Math::new())?;
    let style = stylesheet();
    Ok(AllanPage {
        v: &v,
        style: &style,
    }
    .render()?)
}
