//! The page of `accelcal allan --imu` (its view and its template `allan_imu.html`, on the
//! report's base template and stylesheet): each channel's Allan figure as the one-column page
//! draws it, the terms of every channel and each sensor's largest in SI and datasheet units.
//! Pure: HTML out, no IO.

use askama::Template;
use serde::Serialize;

use super::allan::{series, term_row, verdict_sentence};
use super::figures::figure;
use super::view::FigureView;
use super::{RenderError, stylesheet};
use crate::allan::imu::{ImuAnalysis, Largest};
use crate::allan::{GaussMarkov, Term, TermEstimate};
use crate::format::{count, interval, sig};
use crate::input::records::{Channel, Sensor};
use crate::plot;

/// The page.
#[derive(Template)]
#[template(path = "allan_imu.html")]
pub struct AllanImuPage<'a> {
    /// The view.
    pub v: &'a AllanImuView,
    /// The stylesheet.
    pub style: &'a str,
}

/// One row of a terms table.
#[derive(Clone, Debug, Serialize)]
pub struct ImuTermRow {
    /// The term, in words.
    pub name: String,
    /// Where it comes from: an axis, or the axis of the largest.
    pub axis: String,
    /// Its value (interval) or bound in SI units.
    pub si: String,
    /// The same in datasheet units.
    pub datasheet: String,
}

/// One channel's part of the page.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelView {
    /// The column.
    pub column: String,
    /// Its figure.
    pub figure: FigureView,
    /// Whether the model holds and which reading the terms come from.
    pub verdict: String,
    /// Whether the fit was rejected.
    pub rejected: bool,
    /// Its terms.
    pub terms: Vec<ImuTermRow>,
}

/// Everything the page shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct AllanImuView {
    /// The program's version.
    pub version: String,
    /// The log.
    pub source: String,
    /// Samples, τ₀, duration, channels, in words.
    pub extent: String,
    /// The confidence as a percentage.
    pub confidence: String,
    /// Each sensor's largest terms.
    pub summary: Vec<ImuTermRow>,
    /// Every channel.
    pub channels: Vec<ChannelView>,
    /// The command that wrote the page.
    pub command: String,
}

/// Degrees per radian.
const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;

/// `t`'s value with its interval, or its bound, times `scale`.
fn range(t: &TermEstimate, scale: f64) -> String {
    match (t.value, t.lower) {
        (Some(v), Some(lo)) => {
            let (v, lo, hi) = interval(v * scale, lo * scale, t.upper * scale, 3);
            format!("{v} [{lo}, {hi}]")
        }
        _ => format!("unresolved, ≤ {}", sig(t.upper * scale, 3)),
    }
}

/// A gyro term in SI and datasheet units (°/√h for N, °/h for B, °/h/√h for K, µrad for Q,
/// °/h² for R; IEEE Std 952-1997, annex C, gives the same units).
fn gyro_cells(t: &TermEstimate) -> (String, String) {
    let (scale, unit) = match t.term {
        Term::Quantization => (1e6, "µrad"),
        Term::VelocityRandomWalk => (DEG_PER_RAD * 60.0, "°/√h"),
        Term::BiasInstability => (DEG_PER_RAD * 3600.0, "°/h"),
        Term::AccelerationRandomWalk => (DEG_PER_RAD * 3600.0 * 60.0, "°/h/√h"),
        Term::RateRamp => (DEG_PER_RAD * 3600.0 * 3600.0, "°/h²"),
    };
    let si = format!("{} {}", range(t, 1.0), Sensor::Gyroscope.term_unit(t.term));
    (si, format!("{} {unit}", range(t, scale)))
}

/// A term's row for `channel`: the accelerometer's cells as the one-column page writes them.
fn row(channel: Channel, t: &TermEstimate, axis: &str) -> ImuTermRow {
    let sensor = channel.sensor();
    let (si, datasheet) = match sensor {
        Sensor::Accelerometer => {
            let r = term_row(t);
            (r.si, r.datasheet)
        }
        Sensor::Gyroscope => gyro_cells(t),
    };
    ImuTermRow {
        name: format!("{} {}", sensor.key(), sensor.term_name(t.term)),
        axis: axis.to_string(),
        si,
        datasheet,
    }
}

/// The Gauss–Markov row of `channel`: σ and T_c with their intervals, or "not resolved" and why
/// (µg or °/h and hours in datasheet units).
fn gauss_markov_row(channel: Channel, g: &GaussMarkov, axis: &str) -> ImuTermRow {
    let sensor = channel.sensor();
    let datasheet_scale = match sensor {
        Sensor::Accelerometer => (1e6 / 9.806_65, "µg"),
        Sensor::Gyroscope => (DEG_PER_RAD * 3600.0, "°/h"),
    };
    let cells = match (g.sigma, g.sigma_lower, g.correlation_time_s) {
        (Some(v), Some(lo), Some(tc)) if g.resolved => {
            let (tlo, thi) = (
                g.correlation_time_lower_s.unwrap_or(f64::NAN),
                g.correlation_time_upper_s.unwrap_or(f64::NAN),
            );
            let sigma = |scale: f64| {
                let (v, lo, hi) = interval(v * scale, lo * scale, g.sigma_upper * scale, 3);
                format!("{v} [{lo}, {hi}]")
            };
            let tc_in = |scale: f64| {
                let (v, lo, hi) = interval(tc * scale, tlo * scale, thi * scale, 3);
                format!("{v} [{lo}, {hi}]")
            };
            (
                format!(
                    "σ = {} {}; correlation time {} s",
                    sigma(1.0),
                    sensor.rate_unit(),
                    tc_in(1.0)
                ),
                format!(
                    "σ = {} {}; correlation time {} h",
                    sigma(datasheet_scale.0),
                    datasheet_scale.1,
                    tc_in(1.0 / 3600.0)
                ),
            )
        }
        _ => {
            let why = g.reason.as_deref().unwrap_or("not resolved");
            (format!("not resolved ({why})"), "not resolved".to_string())
        }
    };
    ImuTermRow {
        name: format!("{} Gauss–Markov bias σ and correlation time", sensor.key()),
        axis: axis.to_string(),
        si: cells.0,
        datasheet: cells.1,
    }
}

/// The summary's Gauss–Markov row of `sensor`: the axis of the largest resolved σ, else a row
/// saying no axis resolves it.
fn gauss_markov_summary(imu: &ImuAnalysis, sensor: Sensor) -> Option<ImuTermRow> {
    let first = imu.of(sensor).next()?;
    let resolved = imu
        .of(sensor)
        .filter(|c| c.analysis.gauss_markov.resolved)
        .max_by(|a, b| {
            let s = |c: &&crate::allan::imu::ChannelAnalysis| {
                c.analysis.gauss_markov.sigma.unwrap_or(0.0)
            };
            s(a).total_cmp(&s(b))
        });
    Some(match resolved {
        Some(c) => gauss_markov_row(
            c.channel,
            &c.analysis.gauss_markov,
            &format!("largest: {}", c.channel.column()),
        ),
        None => {
            let mut row = gauss_markov_row(first.channel, &first.analysis.gauss_markov, "none");
            row.si = "not resolved on any axis".to_string();
            row
        }
    })
}

/// The summary row of a sensor's largest term (the estimate itself, else its bound).
fn summary_row(imu: &ImuAnalysis, l: &Largest) -> Option<ImuTermRow> {
    let c = imu.channels.iter().find(|c| c.channel == l.channel)?;
    let t = c.analysis.term(l.term)?;
    let reading = match c.analysis.reading {
        crate::allan::Reading::Fit => "fit",
        crate::allan::Reading::Ieee952 => "IEEE 952",
    };
    Some(row(
        l.channel,
        t,
        &format!("largest: {} ({reading})", l.channel.column()),
    ))
}

/// The view of the analysis of the log `source`, written by `command`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn view(imu: &ImuAnalysis, source: &str, command: &str) -> Result<AllanImuView, RenderError> {
    let confidence = sig(100.0 * imu.confidence, 3);
    let mut channels = Vec::new();
    for (k, c) in imu.channels.iter().enumerate() {
        let sensor = c.channel.sensor();
        let mut s = series(&c.analysis);
        s.unit = sensor.rate_unit();
        let column = c.channel.column();
        let figure = figure(
            &format!("allan-{column}"),
            k + 1,
            &format!("The Allan deviation of {column}"),
            &format!(
                "The overlapping Allan deviation (dots) of {column} at octave-spaced τ with its {confidence} % χ² intervals (whiskers), each resolved reported term as a line of its slope, and the constrained model fit (grey) drawn only where it holds; points it misses are ringed."
            ),
            plot::allan_deviation(&s),
        )?;
        channels.push(ChannelView {
            column: column.to_string(),
            figure,
            verdict: verdict_sentence(&c.analysis),
            rejected: c.analysis.reading == crate::allan::Reading::Ieee952,
            terms: c
                .analysis
                .terms
                .iter()
                .map(|t| row(c.channel, t, c.channel.axis()))
                .chain([gauss_markov_row(
                    c.channel,
                    &c.analysis.gauss_markov,
                    c.channel.axis(),
                )])
                .collect(),
        });
    }
    let summary: Vec<ImuTermRow> = Sensor::ALL
        .into_iter()
        .flat_map(|sensor| {
            [
                Term::VelocityRandomWalk,
                Term::BiasInstability,
                Term::AccelerationRandomWalk,
            ]
            .into_iter()
            .filter_map(move |term| imu.largest(sensor, term))
        })
        .filter_map(|l| summary_row(imu, &l))
        .chain(
            Sensor::ALL
                .into_iter()
                .filter_map(|sensor| gauss_markov_summary(imu, sensor)),
        )
        .collect();
    let columns: Vec<&str> = imu.channels.iter().map(|c| c.channel.column()).collect();
    Ok(AllanImuView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        source: source.to_string(),
        extent: format!(
            "{} samples per channel, τ₀ = {} s ({} Hz), {} s; channels {}",
            count(imu.samples as u64),
            sig(imu.sample_period_s, 6),
            sig(1.0 / imu.sample_period_s, 6),
            sig(imu.samples as f64 * imu.sample_period_s, 4),
            columns.join(", ")
        ),
        confidence,
        summary,
        channels,
        command: command.to_string(),
    })
}

/// The page of the analysis of the log `source`, written by `command`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the template cannot be filled.
pub fn render(imu: &ImuAnalysis, source: &str, command: &str) -> Result<String, RenderError> {
    let v = view(imu, source, command)?;
    let style = stylesheet();
    Ok(AllanImuPage {
        v: &v,
        style: &style,
    }
    .render()?)
}
