//! The page of `accelcal allan` (its view, its template `allan.html` on the report's base
//! template, stylesheet and math) and the Allan figure the report's static-noise section shares
//! with it, drawn by [`crate::plot::allan_deviation`]. Pure: HTML out, no IO.

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::math::Math;
use super::view::FigureView;
use super::{RenderError, stylesheet};
use crate::allan::reading::departing_span;
use crate::allan::{Analysis, Feature, Reading, Term, TermEstimate};
use crate::format::{count, interval, sig};
use crate::plot::{self, AllanMark, AllanSeries, TermCurve};

/// The fitted model of the Allan variance (IEEE Std 952, annex C), as LaTeX.
const MODEL: &str = r"\sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau} + \frac{2\ln 2}{\pi}B^2 + \frac{K^2\tau}{3} + \frac{R^2\tau^2}{2}";

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
            .zip(&a.departures)
            .map(|(p, d)| AllanMark {
                tau_s: p.tau_s,
                adev: p.adev,
                interval: p.interval,
                departs: !d.holds,
            })
            .collect(),
        terms: a
            .terms
            .iter()
            .filter(|t| t.value.is_some())
            .map(|t| TermCurve {
                label: term_label(t.term).to_string(),
                slot: Term::ALL.iter().position(|&u| u == t.term).unwrap_or(0),
                points: curve(&|tau| (t.squared * t.term.coefficient(tau)).sqrt()),
            })
            .collect(),
        sum: holding_stretches(a)
            .into_iter()
            .map(|(lo, hi)| {
                taus.iter()
                    .filter(|&&t| t >= lo && t <= hi)
                    .map(|&t| (t, a.fit.avar_at(t).max(0.0).sqrt()))
                    .collect()
            })
            .collect(),
        unit: "m/s²",
    }
}

/// The stretches of τ where the fit holds: runs of consecutive points inside whose intervals the
/// fitted curve lies, each from its first τ to its last (a lone point: a half octave either side).
fn holding_stretches(a: &Analysis) -> Vec<(f64, f64)> {
    let mut out = vec![];
    let mut run: Option<(f64, f64)> = None;
    for (p, d) in a.points.iter().zip(&a.departures) {
        run = match (d.holds, run) {
            (true, Some((lo, _))) => Some((lo, p.tau_s)),
            (true, None) => Some((p.tau_s, p.tau_s)),
            (false, r) => {
                out.extend(r);
                None
            }
        };
    }
    out.extend(run);
    out.into_iter()
        .map(|(lo, hi)| {
            if lo == hi {
                (lo / 2f64.sqrt(), hi * 2f64.sqrt())
            } else {
                (lo, hi)
            }
        })
        .collect()
}

/// One sentence on whether the model holds and which reading the terms come from, for the page
/// and the printed line.
pub fn verdict_sentence(a: &Analysis) -> String {
    let g = &a.fit.goodness;
    let features: Vec<String> = a
        .features
        .iter()
        .map(|f| match *f {
            Feature::Sinusoid {
                frequency_hz,
                tau_peak_s,
                ..
            } => format!(
                "a hump at τ ≈ {} s, a sinusoid near {} Hz",
                sig(tau_peak_s, 2),
                sig(frequency_hz, 2)
            ),
            Feature::Trend { from_tau_s, .. } => {
                format!(
                    "a rise of slope +1 from τ ≈ {} s, a trend",
                    sig(from_tau_s, 2)
                )
            }
        })
        .collect();
    let named = if features.is_empty() {
        String::new()
    } else {
        format!("; {}", features.join("; "))
    };
    let span = departing_span(&a.points, &a.departures).map_or(String::new(), |s| {
        if s.count == 1 {
            format!(
                "; the fit leaves one point, at τ = {} s (σ̂/σ_fit = {})",
                sig(s.from_tau_s, 2),
                sig(s.largest_ratio, 2)
            )
        } else {
            format!(
                "; the fit leaves {} points from τ = {} to {} s, σ̂/σ_fit from {} to {}",
                s.count,
                sig(s.from_tau_s, 2),
                sig(s.to_tau_s, 2),
                sig(s.least_ratio, 2),
                sig(s.largest_ratio, 2)
            )
        }
    });
    match a.reading {
        Reading::Fit => format!(
            "the model fits (goodness of fit p = {} ≥ α = {}{span}){named}",
            sig(g.p_value, 2),
            g.alpha
        ),
        Reading::Ieee952 => format!(
            "the model is rejected (goodness of fit p = {} < α = {}{span}){named}; the terms are read off the curve as IEEE Std 952 does",
            sig(g.p_value, 2),
            g.alpha
        ),
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
    /// Whether to trust it, in a sentence (empty in the report's section).
    pub trust: String,
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
    /// The fitted σ(τ).
    pub fit: String,
    /// The standardized residual and whether the fit departs, in words.
    pub departure: String,
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
    /// Whether the model holds and which reading the terms come from, in a sentence.
    pub verdict: String,
    /// Whether the model was rejected (the terms read off the curve).
    pub rejected: bool,
    /// The deviation at every τ.
    pub points: Vec<PointRow>,
    /// The command that wrote the page.
    pub command: String,
}

fn range(t: &TermEstimate, scale: f64, digits: usize) -> String {
    match (t.value, t.lower) {
        (Some(v), Some(lo)) => {
            let [v, lo, hi] = [v, lo, t.upper].map(|x| x * scale);
            // The digits that show the interval's ends apart from each other and the estimate.
            let (v, lo, hi) = interval(v, lo, hi, digits);
            format!("{v} [{lo}, {hi}]")
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
        trust: String::new(),
    }
}

fn point_rows(a: &Analysis) -> Vec<PointRow> {
    a.points
        .iter()
        .zip(&a.departures)
        .map(|(p, d)| PointRow {
            fit: sig(d.fit_adev, 3),
            departure: match (d.standardized, d.holds) {
                (Some(z), true) => sig(z, 2).replace('-', "−"),
                (Some(z), false) => {
                    format!("{} (departs, {}×)", sig(z, 2), sig(d.ratio, 2)).replace('-', "−")
                }
                (None, _) => "—".to_string(),
            },
            tau: sig(p.tau_s, 4),
            adev: sig(p.adev, 4),
            interval: p.interval.map_or("—".to_string(), |(lo, hi)| {
                let (_, lo, hi) = interval(p.adev, lo, hi, 3);
                format!("[{lo}, {hi}]")
            }),
            edf: p.edf.map_or("—".to_string(), |e| sig(e, 3)),
            alpha: p.noise.map_or("—".to_string(), |n| {
                let mark = if p.identified_here { "" } else { " (carried)" };
                format!("{}{mark}", n.alpha).replace('-', "−")
            }),
        })
        .collect()
}

/// Whether to trust a reported term, in a sentence.
pub fn trust_sentence(a: &Analysis, t: &TermEstimate) -> String {
    match (a.reading, t.value.is_some(), t.term) {
        (Reading::Fit, true, _) => {
            "Fitted, and the model holds: the interval stands as stated.".to_string()
        }
        (Reading::Fit, false, _) => {
            "The log does not resolve it: only the bound stands (never below what the longest τ demand).".to_string()
        }
        (Reading::Ieee952, true, Term::BiasInstability) => {
            "Read from the curve's minimum (σ_min/0.664): the other terms' share at the minimum is in it, so take it as an upper estimate; the interval counts that point's EDF only.".to_string()
        }
        (Reading::Ieee952, true, _) => {
            "Read off the line of its slope through the points that follow it (IEEE Std 952): approximate; the interval counts those points' EDF, not the model's misfit.".to_string()
        }
        (Reading::Ieee952, false, _) => {
            "No stretch of the curve has its slope: only the bound stands.".to_string()
        }
    }
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
            "The overlapping Allan deviation (dots) at octave-spaced τ with its {confidence} % χ² intervals (whiskers; equivalent degrees of freedom of Greenhall and Riley for the noise identified at each τ by its lag-1 autocorrelation), each resolved reported noise term as a line of its slope, and the constrained model fit (grey) drawn only over the τ where it holds; the points it misses are ringed (the fit outside the point's χ² interval at 1 − α/k, α = 0.01 the goodness-of-fit test's, k the points with an EDF)."
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
        terms: a
            .terms
            .iter()
            .map(|t| TermRow {
                trust: trust_sentence(a, t),
                ..term_row(t)
            })
            .collect(),
        verdict: verdict_sentence(a),
        rejected: a.reading == Reading::Ieee952,
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
