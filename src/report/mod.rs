//! The HTML report of a [`Study`]: draws the figures, builds the view, fills the templates. Pure:
//! it returns the page and its view as text, and the caller writes them.
//!
//! Layers: [`view`] holds the view types, [`prose`] and [`params`] the words and the parameter
//! table, [`figures`] the figures and the numbering, [`equations`] every formula as MathML; the
//! templates under `templates/` only place that text.

pub mod calibration;
pub mod cases;
pub mod equations;
pub mod figures;
pub mod math;
pub mod params;
pub mod prose;
pub mod rich;
pub mod sensitivity;
pub mod view;

use askama::Template;
use base64::Engine;

use crate::format::{count, fixed, percent, short, sig};
use crate::study::Study;
use equations::Equations;
use figures::Numbering;
use math::Math;
use view::{CatalogueEntry, EquationNumbers, Figures, ReportView, TableNumbers};

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
    /// The templates could not be filled.
    #[error("cannot fill the report templates: {0}")]
    Template(#[from] askama::Error),
}

/// The report page.
#[derive(Template)]
#[template(path = "report.html")]
pub struct ReportPage<'a> {
    /// The view.
    pub v: &'a ReportView,
    /// The equations.
    pub eq: &'a Equations,
    /// The stylesheet.
    pub style: &'a str,
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

/// σ_b after 1 s and 5 s where the run is that long, and at the end.
fn bias_sigma_progress(study: &Study) -> String {
    let fixes = &study.schedule.fixes;
    let last = fixes.last().expect("at least two fixes");
    let end_s = last.time_s;
    let mut milestones: Vec<String> = [1.0, 5.0]
        .into_iter()
        .filter(|&t| t < end_s - 1e-9)
        .filter_map(|t| fixes.iter().find(|f| f.time_s >= t - 1e-9))
        .map(|f| {
            format!(
                "{} m/s² after {} s",
                sig(f.p_post[(2, 2)].sqrt(), 2),
                short(f.time_s)
            )
        })
        .collect();
    milestones.push(format!(
        "{} m/s² at the end ({} s)",
        sig(last.p_post[(2, 2)].sqrt(), 2),
        short(end_s)
    ));
    match milestones.split_last() {
        Some((end, [])) => end.clone(),
        Some((end, rest)) => format!("{} and {end}", rest.join(", ")),
        None => String::new(),
    }
}

/// The checks the study ran, as the theory section shows them.
fn catalogue(study: &Study, math: &Math) -> Vec<CatalogueEntry> {
    let capital = |s: &str| format!("{}{}", s[..1].to_uppercase(), &s[1..]);
    study.cases[0]
        .verdicts
        .checks
        .iter()
        .map(|c| {
            let d = c.definition;
            CatalogueEntry {
                id: d.id.name().to_string(),
                title: capital(d.title),
                hypothesis: format!("{}.", capital(d.hypothesis)),
                rationale: d.rationale.to_string(),
                members: d.members.to_string(),
                formula: math.block(d.formula),
            }
        })
        .collect()
}

/// Numbers the display equations in reading order.
fn equation_numbers() -> EquationNumbers {
    let mut n = 0;
    let mut next = || {
        n += 1;
        n
    };
    EquationNumbers {
        profile: next(),
        analytic_truth: next(),
        accelerometer: next(),
        interval_mean: next(),
        integration: next(),
        gps: next(),
        euler_truth: next(),
        dynamics: next(),
        measurement: next(),
        lag: next(),
        prediction: next(),
    }
}

/// Builds the view of `study`; `command` reproduces it.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn build(study: &Study, command: &str, math: &Math) -> Result<ReportView, RenderError> {
    let model = &study.model;
    let c = &model.config;
    let tl = &model.timeline;
    let r = &study.realization;
    let last = r.fixes.last().expect("at least two fixes");
    let first = &study.schedule.fixes[0];
    let eqn = equation_numbers();
    // Tables and figures are numbered in the order the page shows them.
    let mut numbers = Numbering::default();
    let params_table = numbers.table();
    let (trajectory, realization) = figures::realization_figures(study, &mut numbers)?;
    let summary_table = numbers.table();
    let accuracy_table = numbers.table();
    let (accuracy, mean_error) = figures::comparison_figures(study, &mut numbers)?;
    let prediction_table = numbers.table();
    let claimed = prose::claimed_sigma(study);
    let mut cases = Vec::with_capacity(study.cases.len());
    for (i, o) in study.cases.iter().enumerate() {
        let tables = (numbers.table(), numbers.table());
        let figures = figures::check_figures(o, &mut numbers)?;
        cases.push(cases::case_view(o, i, tables, figures, claimed));
    }
    let tables = TableNumbers {
        params: params_table,
        summary: summary_table,
        accuracy: accuracy_table,
        prediction: prediction_table,
        performance: numbers.table(),
    };
    let sensitivity = study
        .sensitivity
        .as_ref()
        .map(|s| sensitivity::view(s, &mut numbers))
        .transpose()?;
    let differences = params::filter_differences(study);
    Ok(ReportView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        realizations: count(c.ensemble.realizations),
        fixes: count(tl.fixes() as u64),
        steps: count(tl.steps as u64),
        accel_rate: short(c.accelerometer.sample_rate_hz),
        gps_rate: short(c.gps.sample_rate_hz),
        steps_per_fix: tl.steps_per_fix.to_string(),
        first_fix: fixed(tl.fix_time_s(0), 2),
        false_alarm: percent(c.checks.false_alarm_rate),
        false_alarm_share: prose::share_words(c.checks.false_alarm_rate, prose::checks_run(study)),
        check_count: prose::checks_run(study).to_string(),
        check_titles: prose::and_list(
            &study.cases[0]
                .verdicts
                .checks
                .iter()
                .map(|c| c.definition.title.to_string())
                .collect::<Vec<_>>(),
        ),
        seed: c.ensemble.seed.to_string(),
        filter_matches_truth: differences.is_empty(),
        params: params::params(study),
        choices_html: params::choices(study, &differences)
            .iter()
            .map(|c| rich::rich(c))
            .collect(),
        catalogue: catalogue(study, math),
        summary: cases::summary(&study.cases),
        realization_case: {
            let i = study
                .cases
                .iter()
                .position(|o| o.case == study.realization_case)
                .unwrap_or(0);
            format!(
                "case {} ({})",
                prose::letter(i),
                prose::case_title(study.realization_case)
            )
        },
        bias_true: sig(r.bias_m_s2, 3),
        bias_estimate: sig(last.post[2], 3),
        bias_error_sigmas: fixed((r.bias_m_s2 - last.post[2]) / last.sigma_post[2], 2),
        bias_prior_sigma: sig(c.filter_bias_var_m2_s4().sqrt(), 2),
        end_time: short(last.t_s),
        first_fix_sigma_p: sig(first.p_post[(0, 0)].sqrt(), 2),
        first_fix_sigma_v: sig(first.p_post[(1, 1)].sqrt(), 2),
        bias_sigma_progress: bias_sigma_progress(study),
        euler_velocity_drift: prose::euler_velocity_drift(study),
        interval_position_error: sig(tl.dt_s * tl.dt_s * c.profile.accel_amplitude_m_s2 / 12.0, 2),
        threads: rayon::current_num_threads().to_string(),
        fig: Figures {
            trajectory,
            realization,
            accuracy,
            mean_error,
        },
        abstract_html: rich::rich(&prose::abstract_findings(study, &differences)),
        conclusions_html: prose::conclusions(study, &differences, eqn.dynamics, tables.accuracy)
            .iter()
            .map(|c| rich::rich(c))
            .collect(),
        cases,
        sensitivity,
        tables,
        eqn,
        filter_differences: differences,
        config_toml: c.to_toml_string(),
        command: command.to_string(),
    })
}

/// Renders the report of `study` as HTML, with its view as JSON. `command` reproduces it.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the templates cannot be filled.
pub fn render(study: &Study, command: &str) -> Result<Page, RenderError> {
    let math = Math::new();
    let view = build(study, command, &math)?;
    let eq = Equations::render(&math);
    let style = stylesheet();
    let html = ReportPage {
        v: &view,
        eq: &eq,
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
