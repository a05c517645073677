//! The views of the core sections (abstract, introduction, problem, theory, results, cases,
//! performance, conclusions), built from the study with every number of the outline known, as
//! methods of [`Context`]; their kinds are in [`super::standard`].

use super::cases::{self, case_label, states};
use super::figures;
use super::kind::Context;
use super::math::Math;
use super::outline::{Equation, Numbers, Table};
use super::page::{
    AbstractView, ConclusionsView, PerformanceView, ProblemView, ResultsView, TheoryView,
};
use super::view::{CatalogueEntry, EquationNumbers};
use super::{RenderError, findings, params, prose, quantities, rich, words};
use crate::format::{count, fixed, percent, short, sig};
use crate::state::ErrorState;
use crate::study::Study;

impl Context<'_> {
    pub(super) fn abstract_view(&self) -> AbstractView {
        let study = self.study();
        let c = &study.model.config;
        let titles: Vec<String> = study.cases[0]
            .verdicts
            .checks
            .iter()
            .map(|c| c.definition.title.to_string())
            .collect();
        AbstractView {
            accel_rate: short(c.accelerometer.sample_rate_hz),
            gps_rate: short(c.gps.sample_rate_hz),
            realizations: count(c.ensemble.realizations),
            check_count: quantities::checks_run(study).to_string(),
            check_titles: words::and_list(&titles),
            false_alarm: percent(c.checks.false_alarm_rate),
            findings_html: rich::rich(&findings::abstract_findings(study, self.differences)),
        }
    }

    pub(super) fn problem(&self) -> Result<ProblemView, RenderError> {
        let study = self.study();
        let c = &study.model.config;
        Ok(ProblemView {
            eqn: equation_numbers(self.numbers),
            accel_rate: short(c.accelerometer.sample_rate_hz),
            gps_rate: short(c.gps.sample_rate_hz),
            steps_per_fix: study.model.timeline.steps_per_fix.to_string(),
            params_table: self.numbers.table(Table::Params),
            params: params::params(study),
            filter_matches_truth: self.differences.is_empty(),
            filter_differences: self.differences.to_vec(),
            choices_html: params::choices(study, self.differences)
                .iter()
                .map(|c| rich::rich(c))
                .collect(),
            trajectory: figures::trajectory_figure(study, self.numbers)?,
        })
    }

    pub(super) fn theory(&self) -> TheoryView {
        let study = self.study();
        let c = &study.model.config;
        let tl = &study.model.timeline;
        TheoryView {
            eqn: equation_numbers(self.numbers),
            steps_per_fix: tl.steps_per_fix.to_string(),
            euler_velocity_drift: quantities::euler_velocity_drift(study),
            interval_position_error: sig(
                tl.dt_s * tl.dt_s * c.profile.accel_amplitude_m_s2 / 12.0,
                2,
            ),
            realizations: count(c.ensemble.realizations),
            false_alarm: percent(c.checks.false_alarm_rate),
            false_alarm_share: words::share_words(
                c.checks.false_alarm_rate,
                quantities::checks_run(study),
            ),
            check_count: quantities::checks_run(study).to_string(),
            catalogue: catalogue(study, self.math),
            steps: count(tl.steps as u64),
            fixes: count(tl.fixes() as u64),
        }
    }

    pub(super) fn results(&self) -> Result<ResultsView, RenderError> {
        let study = self.study();
        let c = &study.model.config;
        let r = &study.realization;
        let last = r.fixes.last().expect("at least two fixes");
        let first = &study.schedule.fixes[0];
        let n = self.numbers;
        let claimed = quantities::claimed_sigma(study);
        let (accuracy, mean_error) = figures::comparison_figures(study, n)?;
        let each = |f: &dyn Fn(usize) -> String| (0..study.cases.len()).map(f).collect();
        let (p, v, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
        Ok(ResultsView {
            realization: figures::realization_figure(study, n)?,
            realization_case: realization_case(study),
            first_fix: fixed(study.model.timeline.fix_time_s(0), 2),
            first_fix_sigma_p: sig(first.p_post[(p, p)].sqrt(), 2),
            first_fix_sigma_v: sig(first.p_post[(v, v)].sqrt(), 2),
            bias_sigma_progress: bias_sigma_progress(study),
            bias_true: sig(r.bias_m_s2, 3),
            bias_estimate: sig(last.post[b], 3),
            bias_error_sigmas: fixed((r.bias_m_s2 - last.post[b]) / last.sigma_post[b], 2),
            realizations: count(c.ensemble.realizations),
            false_alarm: percent(c.checks.false_alarm_rate),
            summary_table: n.table(Table::Summary),
            cases: each(&|i| case_label(&study.cases[i], i)),
            summary: cases::summary(&study.cases),
            accuracy_table: n.table(Table::Accuracy),
            end_time: short(last.t_s),
            state_columns: states()
                .iter()
                .map(|s| format!("{} ({})", s.key, s.unit))
                .collect(),
            accuracy_rows: (0..study.cases.len())
                .map(|i| cases::accuracy_row(&study.cases[i], i, claimed))
                .collect(),
            accuracy,
            prediction_eq: n.equation(Equation::Prediction),
            prediction_table: n.table(Table::Prediction),
            prediction_rows: (0..study.cases.len())
                .map(|i| cases::prediction_row(&study.cases[i], i))
                .collect(),
            mean_error,
        })
    }

    pub(super) fn performance(&self) -> PerformanceView {
        let study = self.study();
        PerformanceView {
            table: self.numbers.table(Table::Performance),
            threads: self.input.threads.to_string(),
            accel_rate: short(study.model.config.accelerometer.sample_rate_hz),
            rows: (0..study.cases.len())
                .map(|i| cases::performance_row(&study.cases[i], i))
                .collect(),
        }
    }

    pub(super) fn conclusions(&self) -> ConclusionsView {
        let n = self.numbers;
        ConclusionsView {
            paragraphs_html: prose::conclusions(
                self.study(),
                self.differences,
                n.equation(Equation::Dynamics),
                n.table(Table::Accuracy),
            )
            .iter()
            .map(|c| rich::rich(c))
            .collect(),
        }
    }
}

/// The numbers of the display equations.
fn equation_numbers(n: &Numbers) -> EquationNumbers {
    EquationNumbers {
        profile: n.equation(Equation::Profile),
        analytic_truth: n.equation(Equation::AnalyticTruth),
        accelerometer: n.equation(Equation::Accelerometer),
        interval_mean: n.equation(Equation::IntervalMean),
        integration: n.equation(Equation::Integration),
        gps: n.equation(Equation::Gps),
        euler_truth: n.equation(Equation::EulerTruth),
        dynamics: n.equation(Equation::Dynamics),
        measurement: n.equation(Equation::Measurement),
        lag: n.equation(Equation::Lag),
        prediction: n.equation(Equation::Prediction),
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

/// "case A (Euler-integrated truth, point samples)": the case of the recorded realization.
fn realization_case(study: &Study) -> String {
    let i = study
        .cases
        .iter()
        .position(|o| o.case == study.realization_case)
        .unwrap_or(0);
    format!(
        "case {} ({})",
        words::letter(i),
        words::case_title(study.realization_case)
    )
}

/// σ_b after 1 s and 5 s where the run is that long, and at the end.
fn bias_sigma_progress(study: &Study) -> String {
    let b = ErrorState::BIAS;
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
                sig(f.p_post[(b, b)].sqrt(), 2),
                short(f.time_s)
            )
        })
        .collect();
    milestones.push(format!(
        "{} m/s² at the end ({} s)",
        sig(last.p_post[(b, b)].sqrt(), 2),
        short(end_s)
    ));
    match milestones.split_last() {
        Some((end, [])) => end.clone(),
        Some((end, rest)) => format!("{} and {end}", rest.join(", ")),
        None => String::new(),
    }
}
