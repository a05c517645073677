//! The section "Three axes: a whole IMU calibrated by GNSS": the drive, one realization's six
//! biases and attitude errors against the truth, the checks on an ensemble of extended Kalman
//! filters (each realization judged by its own covariance), and the negative controls.

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::kind::{Built, Context, Record, SectionKind, SectionView};
use super::outline::{Figure, Label, Numbers, Table};
use super::view::FigureView;
use super::words::count_words;
use super::{RenderError, ReportInput, rich};
use crate::checks::{CATALOGUE, CheckId, Verdict, Verdicts};
use crate::format::{count, fixed, sig};
use crate::ins::names::{MEASUREMENTS, VARIABLES};
use crate::plot::{self, TraceSeries};
use crate::stats::binomial_band;
use crate::study::ins::{Control, InsResults, SCALE_PPM};

const TRACK: Figure = Figure::Named("ins-track");
const TRACE: Figure = Figure::Named("ins-trace");
const VERDICTS: Table = Table::Named("ins-verdicts");
const BIASES: Table = Table::Named("ins-biases");

/// One filter's row of the verdicts table.
#[derive(Clone, Debug, Serialize)]
pub struct VerdictRow {
    /// The filter, in words.
    pub filter: String,
    /// Each check's verdict, in catalogue order.
    pub verdicts: Vec<String>,
    /// Where the first failing check starts to fail, in words (empty when none fails).
    pub first_failure: String,
}

/// One bias's row of the calibration table.
#[derive(Clone, Debug, Serialize)]
pub struct BiasRow {
    /// The state, in words.
    pub state: String,
    /// The filter's σ at the end, RMS over the ensemble, in datasheet units.
    pub sigma: String,
    /// The achieved RMS error at the end.
    pub rms: String,
    /// Their ratio.
    pub ratio: String,
    /// Realizations with the truth inside 1.96 σ, and the band.
    pub within: String,
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct InsView {
    /// The drive.
    pub track: FigureView,
    /// One realization.
    pub trace: FigureView,
    /// Table numbers: verdicts, biases.
    pub verdicts_table: usize,
    /// The biases' table.
    pub biases_table: usize,
    /// Realizations per ensemble.
    pub realizations: String,
    /// The drive's length, s.
    pub duration_s: String,
    /// How many checks the catalogue holds, in words ("seven").
    pub checks_count: String,
    /// The checks' names, the table's columns.
    pub checks: Vec<String>,
    /// The consistent filter, then the controls.
    pub rows: Vec<VerdictRow>,
    /// The six biases.
    pub biases: Vec<BiasRow>,
    /// The sentences the numbers decide, as HTML.
    pub findings_html: String,
}

/// The first failing member of `v` (earliest fix): its check's title, time and words.
fn first_failure(v: &Verdicts, times_s: &[f64]) -> Option<(&'static str, f64, String)> {
    v.checks
        .iter()
        .filter_map(|c| c.first_failure.map(|m| (m, c.definition.title)))
        .min_by_key(|(m, _)| m.fix())
        .map(|(m, title)| {
            (
                title,
                times_s[m.fix()],
                m.describe_with(times_s, &VARIABLES, &MEASUREMENTS),
            )
        })
}

fn row(filter: &str, v: &Verdicts, times_s: &[f64]) -> VerdictRow {
    VerdictRow {
        filter: filter.to_string(),
        verdicts: v
            .checks
            .iter()
            .map(|c| c.verdict.name().to_string())
            .collect(),
        first_failure: first_failure(v, times_s)
            .map(|(title, t, _)| format!("{title}, {} s", fixed(t, 0)))
            .unwrap_or_default(),
    }
}

/// A bias in datasheet units: gyro °/h, accelerometer mg.
fn datasheet(k: usize, x: f64) -> String {
    if k < 12 {
        format!("{} °/h", sig(x.to_degrees() * 3600.0, 3))
    } else {
        format!("{} mg", sig(x / 9.806_65e-3, 3))
    }
}

fn failed(v: &Verdicts) -> Vec<&'static str> {
    v.checks
        .iter()
        .filter(|c| c.verdict == Verdict::Fail)
        .map(|c| c.definition.title)
        .collect()
}

/// What the consistent filter and each control show.
fn findings(s: &InsResults) -> String {
    let mut out = String::new();
    let f = failed(&s.verdicts);
    out.push_str(&if f.is_empty() && s.verdicts.all_passed() {
        format!(
            "With the statistics it assumes equal to the truth's, the filter passes every check at N = {}: each realization's errors are as large as its own P says, its innovations as S says, and neither is correlated where the filter says it is not.",
            count(s.realizations)
        )
    } else if f.is_empty() {
        format!(
            "With the statistics it assumes equal to the truth's, no check fails at N = {}, though some cannot be tested at this N.",
            count(s.realizations)
        )
    } else {
        format!(
            "Even with the truth's statistics the filter fails {} at N = {}{}: its linearization is not exact over this drive.",
            f.join(", "),
            count(s.realizations),
            since(first_failure(&s.verdicts, &s.times_s))
        )
    });
    out.push(' ');
    out.push_str(&scaled_sentence(&s.scaled));
    for c in &s.controls {
        out.push(' ');
        out.push_str(&control_sentence(c));
    }
    out
}

/// What the 21-state filter on sensors with scale factors shows.
fn scaled_sentence(c: &Control) -> String {
    let f = failed(&c.verdicts);
    let ppm = count(SCALE_PPM as u64);
    if f.is_empty() {
        format!(
            "On sensors whose six scale factors have σ {ppm} ppm, the filter that carries them as six more states (21) passes every check too."
        )
    } else {
        format!(
            "On sensors whose six scale factors have σ {ppm} ppm, the filter that carries them as six more states (21) fails {}{}.",
            f.join(", "),
            since(first_failure(&c.verdicts, &c.times_s))
        )
    }
}

fn control_sentence(c: &Control) -> String {
    let f = failed(&c.verdicts);
    if f.is_empty() {
        format!(
            "A filter that {} passes: over this drive the checks cannot tell it from the right one.",
            c.what
        )
    } else {
        format!(
            "A filter that {} fails {}{}.",
            c.what,
            f.join(", "),
            since(first_failure(&c.verdicts, &c.times_s))
        )
    }
}

/// ", first at 171 s (the a posteriori NEES at 171.0 s)".
fn since(first: Option<(&'static str, f64, String)>) -> String {
    first.map_or_else(String::new, |(title, t, member)| {
        format!(", {title} first at {} s ({member})", fixed(t, 0))
    })
}

/// The section's view.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn view(s: &InsResults, numbers: &Numbers) -> Result<InsView, RenderError> {
    let col = |i: usize| -> Vec<f64> { s.track.iter().map(|p| p[i]).collect() };
    let track = figure(
        "fig-ins-track",
        numbers.figure(TRACK),
        "The three-axis drive",
        "The default drive seen from above (north against east, metres from the start, the dot) and its ellipsoidal height: it accelerates from rest, brakes, turns both ways and climbs and dips, so that the GNSS fixes can tell every bias apart.",
        plot::ins_track(&col(0), &col(1), &col(2), &col(3)),
    )?;
    let t = &s.trace;
    let gyro = |x: f64| x.to_degrees() * 3600.0;
    let mg = |x: f64| x / 9.806_65e-3;
    let axis = ["x", "y", "z"];
    let mut series: Vec<TraceSeries> = Vec::new();
    for i in 0..6 {
        let (scale, unit, what): (&dyn Fn(f64) -> f64, _, _) = if i < 3 {
            (&gyro, "°/h", "Gyro")
        } else {
            (&mg, "mg", "Accelerometer")
        };
        series.push(TraceSeries {
            title: format!("{what} bias, {}", axis[i % 3]),
            unit,
            value: t.bias.iter().map(|b| scale(b[i])).collect(),
            sigma: t.bias_sigma.iter().map(|b| scale(b[i])).collect(),
            truth: Some(t.bias_truth.iter().map(|b| scale(b[i])).collect()),
            t_s: &t.t_s,
        });
    }
    for (i, name) in ["north", "east", "down"].iter().enumerate() {
        series.push(TraceSeries {
            title: format!("Attitude error about {name}"),
            unit: "°",
            value: t.attitude_error.iter().map(|e| e[i].to_degrees()).collect(),
            sigma: t.attitude_sigma.iter().map(|e| e[i].to_degrees()).collect(),
            truth: None,
            t_s: &t.t_s,
        });
    }
    let trace = figure(
        "fig-ins-trace",
        numbers.figure(TRACE),
        "One realization: six biases and the attitude",
        "Realization 0 after every fix: each bias's estimate with the filter's ±σ (band) against the true bias, and the attitude error with ±σ about zero. Gyro biases in °/h, accelerometer biases in mg (9.806 65·10⁻³ m/s²).",
        plot::ins_trace(&series),
    )?;
    let c = &s.calibration;
    let band = binomial_band(c.realizations, 0.95, s.config.checks.false_alarm_rate);
    let biases = (9..15)
        .map(|k| BiasRow {
            state: VARIABLES[k].name.to_string(),
            sigma: datasheet(k, c.filter_sigma[k]),
            rms: datasheet(k, c.achieved_rms[k]),
            ratio: fixed(c.achieved_rms[k] / c.filter_sigma[k], 2),
            within: format!("{} [{}, {}]", c.within_95[k], band.0, band.1),
        })
        .collect();
    let mut rows = vec![
        row("the truth's statistics", &s.verdicts, &s.times_s),
        row(s.scaled.what, &s.scaled.verdicts, &s.scaled.times_s),
    ];
    rows.extend(
        s.controls
            .iter()
            .map(|c| row(c.what, &c.verdicts, &c.times_s)),
    );
    Ok(InsView {
        track,
        trace,
        verdicts_table: numbers.table(VERDICTS),
        biases_table: numbers.table(BIASES),
        realizations: count(s.realizations),
        duration_s: fixed(s.config.drive.duration_s, 0),
        checks_count: count_words(CATALOGUE.len()),
        checks: CheckId::ALL.iter().map(|c| c.name().to_string()).collect(),
        rows,
        biases,
        findings_html: rich::rich(&findings(s)),
    })
}

/// data.json's `three_axes`: each filter's verdicts and the calibration at the end.
#[derive(Serialize)]
pub struct InsRecord {
    /// Realizations per ensemble.
    pub realizations: u64,
    /// Each filter (the consistent one first) and its checks' verdicts.
    pub filters: Vec<(
        String,
        std::collections::BTreeMap<&'static str, &'static str>,
    )>,
    /// Per error state at the end: the filter's σ and the achieved error, RMS over the ensemble.
    pub final_sigma: Vec<(&'static str, f64, f64)>,
}

fn record(s: &InsResults) -> InsRecord {
    let verdicts = |v: &Verdicts| {
        v.checks
            .iter()
            .map(|c| (c.id.name(), c.verdict.name()))
            .collect()
    };
    let mut filters = vec![
        ("the truth's statistics".to_string(), verdicts(&s.verdicts)),
        (s.scaled.what.to_string(), verdicts(&s.scaled.verdicts)),
    ];
    filters.extend(
        s.controls
            .iter()
            .map(|c| (c.what.to_string(), verdicts(&c.verdicts))),
    );
    InsRecord {
        realizations: s.realizations,
        filters,
        final_sigma: VARIABLES[..s.calibration.filter_sigma.len()]
            .iter()
            .enumerate()
            .map(|(k, v)| {
                (
                    v.key,
                    s.calibration.filter_sigma[k],
                    s.calibration.achieved_rms[k],
                )
            })
            .collect(),
    }
}

/// The section, when the study ran the three-axis study.
pub struct Ins;

impl SectionKind for Ins {
    fn key(&self) -> &'static str {
        "three_axes"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.study.ins.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Figure(TRACK),
            Label::Figure(TRACE),
            Label::Table(VERDICTS),
            Label::Table(BIASES),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let s = ctx.study().ins.as_ref()?;
        Some(view(s, ctx.numbers).map(|v| Box::new(v) as Box<dyn SectionView>))
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let s = input.study.ins.as_ref()?;
        Some(("three_axes", Box::new(record(s))))
    }
}

#[derive(Template)]
#[template(path = "sections/ins.html")]
struct InsHtml<'a> {
    d: &'a InsView,
}

crate::section_view!(InsView, InsHtml { d }, anchor: |_| "three-axes".to_string(), title: |_| "Three axes: a whole IMU calibrated by GNSS".to_string());
