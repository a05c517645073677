//! The HTML report: runs the study, draws the figures, fills the templates, and writes
//! `index.html` and `data.json` into the output directory, atomically.
//!
//! Layers: [`view`] turns results into text; [`equations`] holds every formula as MathML;
//! the templates under `templates/` only place that text.

pub mod equations;
pub mod format;
pub mod math;
pub mod view;

use anyhow::{Context, Result};
use askama::Template;
use base64::Engine;

use crate::app::{load_model, verdict_lines};
use crate::cli::ReportArgs;
use crate::export;
use crate::output::write_all_atomic;
use crate::plot;
use crate::study::{EnsembleOutcome, Study};
use equations::Equations;
use math::Math;
use view::{FigureView, Figures, ReportView};

/// The report page.
#[derive(Template)]
#[template(path = "report.html")]
pub struct ReportPage<'a> {
    pub v: &'a ReportView,
    pub eq: &'a Equations,
    pub style: &'a str,
}

/// The stylesheet, with the math font embedded as a data URL.
pub fn stylesheet() -> String {
    let font = base64::engine::general_purpose::STANDARD
        .encode(include_bytes!("../../assets/math-font.woff2"));
    format!(
        "@font-face {{ font-family: \"AccelcalMath\"; src: url(data:font/woff2;base64,{font}) format(\"woff2\"); }}\n{}",
        include_str!("../../assets/report.css")
    )
}

/// Removes the SVG namespace declaration: inline SVG in HTML needs none, and the report then
/// holds no address at all.
fn inline_svg(svg: String) -> String {
    svg.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1)
}

fn figure(
    id: &str,
    number: usize,
    title: &str,
    caption: String,
    svg: plot::PlotResult,
) -> Result<FigureView> {
    Ok(FigureView {
        id: id.to_string(),
        number,
        title: title.to_string(),
        caption,
        svg: inline_svg(svg.with_context(|| format!("cannot draw figure {id}"))?),
    })
}

/// The five figures of the Monte Carlo checks for one ensemble, numbered from `first`.
fn check_figures(e: &EnsembleOutcome, first: usize, suffix: &str) -> Result<Vec<FigureView>> {
    let s = &e.run.stats;
    let v = &e.verdicts;
    let get = |id: &str| v.get(id).expect("every check is evaluated");
    let truth = e.truth.name();
    let alpha = format::percent(get("mean_error").false_alarm_rate);
    Ok(vec![
        figure(
            &format!("fig-mean-error{suffix}"),
            first,
            "Ensemble mean error",
            format!(
                "The a priori and a posteriori ensemble mean error eᵃᵛᵉ of each state at every GPS fix ({truth} truth, N = {}), against the band ±{}·σ/√N, where σ is the filter's standard deviation and {} the Bonferroni bound at α = {alpha}.",
                format::count(s.realizations),
                format::fixed(get("mean_error").bound, 2),
                format::fixed(get("mean_error").bound, 2),
            ),
            plot::mean_error(s, get("mean_error")),
        )?,
        figure(
            &format!("fig-covariance{suffix}"),
            first + 1,
            "Ensemble variance against the filter's covariance",
            format!(
                "Top: the ensemble variance Pᵃᵛᵉ (N − 1 normalization) and the filter's P, a priori and a posteriori, on a logarithmic axis ({truth} truth). Bottom: their ratio, with the χ² band [{}, {}] that holds the family-wise false-alarm rate α = {alpha}.",
                format::sig(get("covariance_match").lower, 4),
                format::sig(get("covariance_match").upper, 4)
            ),
            plot::covariance(s, get("covariance_match")),
        )?,
        figure(
            &format!("fig-orthogonality{suffix}"),
            first + 2,
            "Orthogonality of error and estimate",
            format!(
                "The normalized correlation √N·corr(e − e_ave, δx̂) of every error component with every estimate component, a priori and a posteriori, at every fix ({truth} truth), against ±{}.",
                format::fixed(get("orthogonality").bound, 2)
            ),
            plot::orthogonality(s, get("orthogonality")),
        )?,
        figure(
            &format!("fig-whiteness{suffix}"),
            first + 3,
            "Residual whiteness",
            format!(
                "Left: the largest |z| of the four component pairs of the residual correlation over every pair of fixes tₘ < tᵢ ({truth} truth), bound {}. Right: the single pair tₘ = {} s, tᵢ = {} s, against ±{}.",
                format::fixed(get("residual_whiteness").bound, 2),
                format::fixed(v.residual_pair.t_m_s, 1),
                format::fixed(v.residual_pair.t_i_s, 1),
                format::fixed(v.residual_pair.bound, 2)
            ),
            plot::residual_whiteness(s, get("residual_whiteness"), &v.residual_pair),
        )?,
        figure(
            &format!("fig-consistency{suffix}"),
            first + 4,
            "Average NEES and NIS",
            format!(
                "The ensemble average of the normalized estimation error squared (expected 3) and of the normalized innovation squared (expected 2) at every fix ({truth} truth), with their χ² bounds."
            ),
            plot::consistency(s, get("nees"), get("nis")),
        )?,
    ])
}

/// Renders the report of `study` as HTML. Pure: no IO.
pub fn render(study: &Study, command: &str) -> Result<(String, ReportView)> {
    let primary = study.primary();
    let other = study
        .ensembles
        .iter()
        .find(|e| e.truth != study.model.truth)
        .expect("two truth models");
    let r = &study.realization;
    let mut checks = check_figures(primary, 3, "")?.into_iter();
    let mut next = || checks.next().expect("five figures");
    let fig = Figures {
        trajectory: figure(
            "fig-trajectory",
            1,
            "Acceleration profile and true trajectory",
            format!(
                "Left: the true acceleration a(t), velocity and position of realization {} (seed {}, {} truth), with the accelerometer's integration from the prior means. Right: the realization's bias, velocity drift δv = v − v_c and position drift δp = p − p_c, with the filter's estimates of each.",
                r.index,
                r.seed,
                study.model.truth
            ),
            plot::trajectory(r),
        )?,
        realization: figure(
            "fig-realization",
            2,
            "Estimation error of one realization",
            "The error δx − δx̂ of position, velocity and bias at every accelerometer sample, with the filter's ±1σ. Left: the whole run; right: the filter's σ over a short window, growing between fixes and dropping at each fix (open circles before the update, dots after).".to_string(),
            plot::realization_errors(r),
        )?,
        mean_error: next(),
        covariance: next(),
        orthogonality: next(),
        whiteness: next(),
        consistency: next(),
        truths: figure(
            "fig-truths",
            8,
            "Effect of the truth model on the mean error",
            "The a posteriori ensemble mean error of each state in units of the filter's σ, for the closed-form (analytic) and the Euler-integrated truth. A consistent filter keeps it near zero, within a few σ/√N.".to_string(),
            plot::truth_models(&study.ensemble(crate::config::TruthModel::Analytic).run.stats, &study.ensemble(crate::config::TruthModel::Euler).run.stats),
        )?,
    };
    let other_figures = check_figures(other, 9, &format!("-{}", other.truth.name()))?;
    let view = view::build(study, fig, other_figures, command.to_string());
    let eq = Equations::render(&Math::new());
    let style = stylesheet();
    let html = ReportPage {
        v: &view,
        eq: &eq,
        style: &style,
    }
    .render()
    .context("cannot fill the report templates")?;
    Ok((html, view))
}

/// The command line that reproduces a report.
fn reproduce_command(args: &ReportArgs) -> String {
    let mut s = String::from("accelcal report");
    if let Some(c) = &args.model.config {
        s.push_str(&format!(" --config {}", c.display()));
    }
    if let Some(t) = args.model.truth {
        s.push_str(&format!(" --truth {t}"));
    }
    if let Some(seed) = args.model.seed {
        s.push_str(&format!(" --seed {seed}"));
    }
    if let Some(n) = args.realizations {
        s.push_str(&format!(" --realizations {n}"));
    }
    s
}

/// Runs the report command.
pub fn run(args: &ReportArgs) -> Result<()> {
    let model = load_model(&args.model, args.realizations)?;
    let study = Study::run(&model, args.model.quiet)?;
    let command = reproduce_command(args);
    let (html, _) = render(&study, &command)?;
    let data = export::report_data_json(&study);
    write_all_atomic(
        &args.out,
        &[
            ("index.html", html.as_bytes()),
            ("data.json", data.as_bytes()),
        ],
    )?;
    for e in &study.ensembles {
        print!("{}", verdict_lines(e.truth, &e.run, &e.verdicts));
    }
    println!(
        "report written to {}",
        args.out.join("index.html").display()
    );
    Ok(())
}
