//! The HTML report of a [`Study`]: draws the figures, builds the view, fills the templates. Pure:
//! it returns the page and its view as text, and the caller writes them.
//!
//! Layers: [`registry`] lists the sections ([`registry::SECTIONS`]), each a
//! [`kind::SectionKind`] (its place, what it numbers, its view, its data.json record);
//! [`outline`] orders the sections the study holds and numbers every table, figure and equation;
//! each section's file builds its view from the study ([`sections`] the core sections, with the
//! view structs of [`page`] and the rows and cells of [`view`]; [`drift`], [`noise`],
//! [`real_drive`], [`static_noise`] one optional section each), with [`words`], [`quantities`],
//! [`findings`] and [`prose`] for the words, [`params`] for the parameter table, [`cases`] for the
//! per-case tables, [`figures`] for the figures and [`equations`] for every formula as MathML;
//! [`html`] fills one template per section, and the templates under `templates/` only place that
//! text. [`json`] assembles view.json and data.json from the sections' parts. [`allan`] is the
//! page of `accelcal allan`, on the same base template, stylesheet and math; [`calibration`] the
//! page of a calibration.

pub mod allan;
pub mod allan_imu;
pub mod calibration;
pub mod calibration_diagnosis;
mod calibration_figures;
pub mod calibration_imu;
mod calibration_imu_assumptions;
mod calibration_imu_figures;
mod calibration_imu_words;
pub mod cases;
pub mod drift;
pub mod equations;
pub mod estimate;
pub mod figures;
pub mod findings;
pub mod html;
pub mod ins;
pub mod intrinsics;
pub mod json;
pub mod kind;
pub mod labels;
pub mod math;
pub mod noise;
pub mod outline;
pub mod page;
pub mod params;
pub mod prose;
pub mod quantities;
pub mod real_drive;
pub mod real_drive_3d;
mod real_drive_3d_noise;
pub mod real_drive_3d_words;
pub mod registry;
pub mod rich;
pub mod sections;
pub mod sensitivity;
pub mod standard;
pub mod static_noise;
pub mod view;
pub mod words;

use askama::Template;
use base64::Engine;

use crate::study::Study;
use equations::Equations;
use kind::SectionKind;
use math::Math;
use outline::{Node, Outline, Section};
use page::{ReportView, SectionNode, TocEntry};
use registry::SECTIONS;

/// The report could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A figure could not be drawn.
    #[error("cannot draw figure {figure}: {source}")]
    Figure {
        /// The figure's id.
        figure: String,
        /// What plotters said.
        source: crate::plot::PlotError,
    },
    /// The static log of the noise-statistics section could not be analysed.
    #[error("cannot analyse the static log: {0}")]
    StaticNoise(#[from] crate::allan::AllanError),
    /// The templates could not be filled.
    #[error("cannot fill the report templates: {0}")]
    Template(#[from] askama::Error),
}

/// A rendered report: the page, and its view as JSON.
#[derive(Clone, Debug)]
pub struct Page {
    /// index.html.
    pub html: String,
    /// view.json: what the page shows, as text.
    pub view_json: String,
    /// The view itself.
    pub view: ReportView,
}

/// The stylesheet, with the math font embedded as a data URL.
pub fn stylesheet() -> String {
    let font = base64::engine::general_purpose::STANDARD
        .encode(include_bytes!("../../assets/math-font.woff2"));
    format!(
        "@font-face {{ font-family: \"AccelcalMath\"; src: url(data:font/woff2;base64,{font}) format(\"woff2\"); ascent-override: 75%; descent-override: 25%; line-gap-override: 0%; }}\n{}",
        include_str!("../../assets/report.css")
    )
}

/// What the report is made from: the study, and how the run that made it was set up.
#[derive(Clone, Copy)]
pub struct ReportInput<'a> {
    /// The study.
    pub study: &'a Study,
    /// The command that reproduces the report.
    pub command: &'a str,
    /// Threads the ensembles ran on (the run times depend on it, the numbers do not).
    pub threads: usize,
    /// The coverage of `accelcal allan`'s intervals over simulated static logs
    /// ([`crate::allan::section::report_coverage`]); the page has its section when given.
    pub static_noise: Option<&'a crate::allan::section::Coverage>,
}

/// Builds the view of `input`, its sections in the order of `outline`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn build(
    input: &ReportInput,
    outline: &Outline,
    math: &Math,
) -> Result<ReportView, RenderError> {
    let study = input.study;
    let numbers = outline.numbers();
    let differences = params::filter_differences(study);
    let context = kind::Context {
        input,
        numbers: &numbers,
        math,
        differences: &differences,
    };
    let node = |section: Section| -> Option<Result<SectionNode, RenderError>> {
        let view = section.kind.build(&context, section.instance)?;
        Some(view.map(|view| SectionNode {
            key: section.key(),
            view: view.into(),
            children: Vec::new(),
        }))
    };
    let sections = outline
        .nodes
        .iter()
        .filter_map(|n: &Node| {
            let built = node(n.section)?;
            Some(built.and_then(|mut parent| {
                parent.children = n
                    .children
                    .iter()
                    .filter_map(|&c| node(c))
                    .collect::<Result<_, _>>()?;
                Ok(parent)
            }))
        })
        .collect::<Result<Vec<_>, RenderError>>()?;
    Ok(ReportView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        seed: study.model.config.ensemble.seed.to_string(),
        toc: sections
            .iter()
            .map(|n| TocEntry {
                anchor: n.view.anchor(),
                title: n.view.title(),
            })
            .collect(),
        sections,
    })
}

/// The outline of the report of `input`: every section of [`SECTIONS`] the study holds, in
/// their order.
pub fn outline_of(input: &ReportInput) -> Outline {
    Outline::of(input, SECTIONS)
}

/// The report's `data.json`: the study's configuration, realization and ensembles, then the
/// record of every section of [`SECTIONS`] that has one, in their order.
pub fn data_json(input: &ReportInput) -> String {
    data_json_of(input, SECTIONS)
}

/// `data.json` with the records of the sections `kinds`, in their order.
pub fn data_json_of(input: &ReportInput, kinds: &[&'static dyn SectionKind]) -> String {
    let (mut text, pretty) = crate::export::report_data_head(input.study);
    for (key, record) in kinds.iter().filter_map(|k| k.record(input)) {
        let value = record.to_json(pretty);
        text = if pretty {
            json::append(&text, key, &value)
        } else {
            json::append_compact(&text, key, &value)
        };
    }
    text
}

/// Renders the report of `input` as HTML, with its view as JSON.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the templates cannot be filled.
pub fn render(input: &ReportInput) -> Result<Page, RenderError> {
    render_outline(input, &outline_of(input))
}

/// Renders the report of `input` with its sections in the order of `outline`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the templates cannot be filled.
pub fn render_outline(input: &ReportInput, outline: &Outline) -> Result<Page, RenderError> {
    let math = Math::new();
    let view = build(input, outline, &math)?;
    let eq = Equations::render(&math);
    let style = stylesheet();
    let sections_html = view
        .sections
        .iter()
        .map(|node| html::section(node, &eq))
        .collect::<Result<Vec<_>, _>>()?;
    let html = html::ReportPage {
        v: &view,
        sections_html: &sections_html,
        style: &style,
    }
    .render()?;
    let view_json = view.to_json();
    Ok(Page {
        html,
        view_json,
        view,
    })
}
