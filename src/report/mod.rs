//! The HTML report of a [`Study`]: draws the figures, builds the view, fills the templates. Pure:
//! it returns the page and its view as text, and the caller writes them.
//!
//! Layers: [`outline`] orders the sections and numbers every table, figure and equation;
//! [`sections`] builds each section's view ([`page`], with the rows and cells of [`view`]) from
//! the study, with [`prose`] and
//! [`params`] for the words and the parameter table, [`cases`] for the per-case tables,
//! [`figures`] for the figures and [`equations`] for every formula as MathML; [`html`] fills one
//! template per section, and the templates under `templates/` only place that text.

pub mod calibration;
pub mod calibration_diagnosis;
mod calibration_figures;
pub mod cases;
pub mod drift;
pub mod equations;
pub mod estimate;
pub mod figures;
pub mod html;
pub mod math;
pub mod noise;
pub mod outline;
pub mod page;
pub mod params;
pub mod prose;
pub mod real_drive;
pub mod rich;
pub mod sections;
pub mod sensitivity;
pub mod view;

use askama::Template;
use base64::Engine;

use crate::study::Study;
use equations::Equations;
use math::Math;
use outline::Outline;
use page::{ReportView, SectionNode, TocEntry};

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
    let context = sections::Context {
        input,
        numbers: &numbers,
        math,
        differences: &differences,
    };
    let sections = outline
        .nodes
        .iter()
        .map(|node| {
            Ok(SectionNode {
                view: context.view(node.section)?,
                children: node
                    .children
                    .iter()
                    .map(|&c| {
                        Ok(SectionNode {
                            view: context.view(c)?,
                            children: Vec::new(),
                        })
                    })
                    .collect::<Result<_, RenderError>>()?,
            })
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

/// The outline of the report of `input`: every case, the sensitivity section when the study ran
/// it, the static-noise section when its coverage is given, the drifting-bias section and the
/// section on noise statistics from a drive and the real drive's when the study ran them.
pub fn outline_of(input: &ReportInput) -> Outline {
    let outline = Outline::standard(
        input.study.cases.len(),
        input.study.sensitivity.is_some(),
        input.static_noise.is_some(),
    );
    let outline = if input.study.drift.is_some() {
        outline.with_drift()
    } else {
        outline
    };
    let outline = if input.study.noise.is_some() {
        outline.with_noise(input.study.white_noise.is_some())
    } else {
        outline
    };
    if input.study.real_drive.is_some() {
        outline.with_real_drive()
    } else {
        outline
    }
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
    let view_json = serde_json::to_string_pretty(&view).expect("the view is plain text");
    Ok(Page {
        html,
        view_json,
        view,
    })
}
