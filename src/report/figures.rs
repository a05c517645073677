//! The report's figures: which plot shows which check and their captions; their numbers come
//! from the [`super::outline`].

use super::RenderError;
use super::outline::{CheckFigure, Figure, Numbers};
use super::rich::rich;
use super::view::FigureView;
use super::words::{case_title, letter};
use crate::checks::{CheckId, Verdicts};
use crate::format::{count, fixed, percent, sig};
use crate::plot;
use crate::study::{CaseOutcome, Study};

/// Removes the SVG namespace declaration: inline SVG in HTML needs none, and the report then
/// holds no address at all.
pub fn inline_svg(svg: String) -> String {
    svg.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1)
}

/// A numbered figure from its drawing; `caption` may hold `_{…}`/`^{…}` notation.
pub fn figure(
    id: &str,
    number: usize,
    title: &str,
    caption: &str,
    svg: plot::PlotResult,
) -> Result<FigureView, RenderError> {
    let svg = svg.map_err(|source| RenderError::Figure {
        figure: id.to_string(),
        source,
    })?;
    Ok(FigureView {
        id: id.to_string(),
        number,
        title: title.to_string(),
        caption_html: rich(caption),
        svg: inline_svg(svg),
    })
}

fn check_figure(
    which: CheckFigure,
    o: &CaseOutcome,
    number: usize,
    id_stem: &str,
) -> Result<FigureView, RenderError> {
    let s = &o.run.stats;
    let v: &Verdicts = &o.verdicts;
    let get = |id| v.get(id);
    let case = case_title(o.case);
    let share = percent(get(CheckId::MEAN_ERROR).false_alarm_rate);
    let id = format!("{}-{id_stem}", which.id());
    match which {
        CheckFigure::MeanError => figure(
            &id,
            number,
            "Ensemble mean error and its prediction",
            &format!(
                "The a priori and a posteriori ensemble mean error e^{{ave}} of each state at every GPS fix ({case}, N = {}), against the band ±{}·σ/√N, where σ is the filter's standard deviation and {} the Bonferroni bound of the check's share α_{{c}} = {share}. Thin lines: the mean error predicted by one noise-free pass of the filter over the truth's deterministic part (a posteriori black, a priori grey).",
                count(s.realizations),
                fixed(get(CheckId::MEAN_ERROR).upper, 2),
                fixed(get(CheckId::MEAN_ERROR).upper, 2),
            ),
            plot::mean_error(s, get(CheckId::MEAN_ERROR), &o.prediction.fixes),
        ),
        CheckFigure::Covariance => figure(
            &id,
            number,
            "Ensemble variance against the filter's covariance",
            &format!(
                "Left: the ensemble variance P^{{ave}} (N − 1 normalization) and the filter's P, a priori and a posteriori, on a logarithmic axis ({case}). Right: their ratio, with the χ² band [{}, {}] that holds the check's share α_{{c}} = {share}.",
                sig(get(CheckId::COVARIANCE_MATCH).lower, 4),
                sig(get(CheckId::COVARIANCE_MATCH).upper, 4)
            ),
            plot::covariance(s, get(CheckId::COVARIANCE_MATCH)),
        ),
        CheckFigure::Orthogonality => figure(
            &id,
            number,
            "Orthogonality of error and estimate",
            &format!(
                "The normalized correlation √N·corr(e − e^{{ave}}, δx̂) of every error component with every estimate component, a priori and a posteriori, at every fix ({case}), against ±{}.",
                fixed(get(CheckId::ORTHOGONALITY).upper, 2)
            ),
            plot::orthogonality(s, get(CheckId::ORTHOGONALITY)),
        ),
        CheckFigure::Whiteness => figure(
            &id,
            number,
            "Residual whiteness",
            &format!(
                "Left: the largest |z| of the four component pairs of the residual correlation over {} t_{{m}} < t_{{i}} ({case}), bound {}. Right: the single pair t_{{m}} = {} s, t_{{i}} = {} s, against ±{}.",
                match s.residual_layout.max_lag() {
                    None => "every pair of fixes".to_string(),
                    Some(l) => format!("the pairs of fixes at most {l} fixes apart"),
                },
                fixed(get(CheckId::RESIDUAL_WHITENESS).upper, 2),
                fixed(v.residual_pair.t_m_s, 1),
                fixed(v.residual_pair.t_i_s, 1),
                fixed(v.residual_pair.bound, 2)
            ),
            plot::residual_whiteness(s, get(CheckId::RESIDUAL_WHITENESS), &v.residual_pair),
        ),
        CheckFigure::Consistency => figure(
            &id,
            number,
            "Average NEES and NIS",
            &format!(
                "The ensemble average of the normalized estimation error squared (expected 3) and of the normalized innovation squared (expected 2) at every fix ({case}), with their χ² bounds."
            ),
            plot::consistency(s, get(CheckId::NEES), get(CheckId::NIS)),
        ),
    }
}

/// The check figures of case `o`, the `index`-th, numbered by `numbers`.
pub fn check_figures(
    o: &CaseOutcome,
    index: usize,
    numbers: &Numbers,
) -> Result<Vec<FigureView>, RenderError> {
    let stem = o.case.id().replace('_', "-");
    CheckFigure::ALL
        .iter()
        .map(|&which| {
            let number = numbers.figure(Figure::Check(index, which));
            check_figure(which, o, number, &stem)
        })
        .collect()
}

/// The series of the cross-case figures.
fn series(study: &Study) -> Vec<plot::CaseSeries<'_>> {
    study
        .cases
        .iter()
        .enumerate()
        .map(|(i, o)| plot::CaseSeries {
            label: format!("{}: {}", letter(i), case_title(o.case)),
            stats: &o.run.stats,
            achieved_rms: &o.achieved_rms,
        })
        .collect()
}

/// The trajectory of the recorded realization, numbered by `numbers`.
pub fn trajectory_figure(study: &Study, numbers: &Numbers) -> Result<FigureView, RenderError> {
    let r = &study.realization;
    let case = case_title(study.realization_case);
    figure(
        "fig-trajectory",
        numbers.figure(Figure::Trajectory),
        "Acceleration profile and true trajectory",
        &format!(
            "Left: the true acceleration a(t), velocity and position of realization {} (seed {}, {case}), with the accelerometer's integration from the prior means. Right: the realization's bias, velocity drift δv = v − v_{{c}} and position drift δp = p − p_{{c}}, with the filter's estimates of each.",
            r.index, r.seed,
        ),
        plot::trajectory(r),
    )
}

/// The estimation error of the recorded realization, numbered by `numbers`.
pub fn realization_figure(study: &Study, numbers: &Numbers) -> Result<FigureView, RenderError> {
    let r = &study.realization;
    let case = case_title(study.realization_case);
    let consistent = study.case(study.realization_case).verdicts.all_passed();
    figure(
        "fig-realization",
        numbers.figure(Figure::Realization),
        "Estimation error of one realization",
        &format!(
            "The error δx − δx̂ of position, velocity and bias at every accelerometer sample ({case}{}), with the filter's ±1σ. Left: the whole run; right: the filter's σ over a short window, growing between fixes and dropping at each fix (open circles before the update, dots after); the bias σ is a staircase, constant between fixes.",
            if consistent {
                ", a case whose checks all pass"
            } else {
                ""
            }
        ),
        plot::realization_errors(r),
    )
}

/// The figures that compare the cases.
pub fn comparison_figures(
    study: &Study,
    numbers: &Numbers,
) -> Result<(FigureView, FigureView), RenderError> {
    let cases = series(study);
    let accuracy = figure(
        "fig-accuracy",
        numbers.figure(Figure::Accuracy),
        "Achieved accuracy against the filter's claim",
        "The achieved RMS a posteriori error √(mean² + variance) of each state over the ensemble, divided by the filter's σ, at every fix, for every case. A consistent filter stays at 1, within the sampling scatter; a ratio above 1 is accuracy the filter claims but does not reach.",
        plot::accuracy_ratio(&cases),
    )?;
    let bound = study.cases[0].verdicts.get(CheckId::MEAN_ERROR).upper;
    let mean_error = figure(
        "fig-mean-error-cases",
        numbers.figure(Figure::MeanErrorCases),
        "Mean error of every case, in units of the filter's σ",
        &format!(
            "The a posteriori |e^{{ave}}| / σ of each state at every fix on a logarithmic axis, for every case, with the mean-error check's bound {}/√N in the same units (black). Sampling noise alone stays below the bound; a systematic error stands decades above it.",
            fixed(bound, 2)
        ),
        plot::mean_error_in_sigma(&cases, bound),
    )?;
    Ok((accuracy, mean_error))
}
