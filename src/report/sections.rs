//! The view of each section of the report, built from the study with every number of the outline
//! known.

use super::cases::{self, case_label, states};
use super::figures;
use super::math::Math;
use super::outline::{Equation, Figure, Numbers, Section, Table};
use super::page::{
    AbstractView, AppendixView, ConclusionsView, IntroductionView, PerformanceView, ProblemView,
    ResultsView, SectionView, TheoryView,
};
use super::view::{CatalogueEntry, EquationNumbers};
use super::{RenderError, ReportInput, params, prose, rich, sensitivity};
use crate::allan::section::AllanSection;
use crate::format::{count, fixed, percent, short, sig};
use crate::state::ErrorState;
use crate::study::Study;

/// What every section is built from.
pub struct Context<'a> {
    /// The study and how the page was made.
    pub input: &'a ReportInput<'a>,
    /// The number of every table, figure and equation.
    pub numbers: &'a Numbers,
    /// The LaTeX → MathML converter.
    pub math: &'a Math,
    /// The statistics the filter assumes differently from the truth, in words.
    pub differences: &'a [String],
}

impl Context<'_> {
    fn study(&self) -> &Study {
        self.input.study
    }

    /// The static-noise section: the report's simulated static log analysed again, with the
    /// coverage the study measured.
    ///
    /// # Panics
    /// When the input holds no static-noise coverage.
    fn static_noise(&self) -> Result<AllanSection, RenderError> {
        use crate::allan::section::{REPORT_LOG, REPORT_SAMPLES, section};
        let coverage = self
            .input
            .static_noise
            .expect("the outline shows the static noise only when its coverage is given");
        let n = self.numbers;
        let figure = n.figure(Figure::AllanDeviation);
        let table = n.table(Table::StaticNoise);
        debug_assert_eq!(n.table(Table::StaticNoiseCoverage), table + 1);
        Ok(section(
            &REPORT_LOG,
            REPORT_SAMPLES,
            0,
            coverage,
            figure,
            table,
        )?)
    }

    /// The view of `section`.
    ///
    /// # Errors
    /// [`RenderError`] when a figure cannot be drawn.
    ///
    /// # Panics
    /// When `section` is the sensitivity section of a study that did not run it.
    pub fn view(&self, section: Section) -> Result<SectionView, RenderError> {
        let study = self.study();
        Ok(match section {
            Section::Abstract => SectionView::Abstract(self.abstract_view()),
            Section::Introduction => SectionView::Introduction(IntroductionView {}),
            Section::Problem => SectionView::Problem(Box::new(self.problem()?)),
            Section::Theory => SectionView::Theory(Box::new(self.theory())),
            Section::Results => SectionView::Results(Box::new(self.results()?)),
            Section::Case(i) => {
                let o = &study.cases[i];
                let n = self.numbers;
                let tables = (n.table(Table::Checks(i)), n.table(Table::Pair(i)));
                let figures = figures::check_figures(o, i, n)?;
                let claimed = prose::claimed_sigma(study);
                SectionView::Case(Box::new(cases::case_view(o, i, tables, figures, claimed)))
            }
            Section::Performance => SectionView::Performance(self.performance()),
            Section::Sensitivity => SectionView::Sensitivity(Box::new(sensitivity::view(
                study
                    .sensitivity
                    .as_ref()
                    .expect("the outline shows sensitivity only when the study ran it"),
                self.numbers,
            )?)),
            Section::StaticNoise => SectionView::StaticNoise(Box::new(self.static_noise()?)),
            Section::Drift => SectionView::Drift(Box::new(super::drift::view(
                study
                    .drift
                    .as_ref()
                    .expect("the outline shows the drifting bias only when the study ran it"),
                self.numbers,
            )?)),
            Section::RealDrive => SectionView::RealDrive(Box::new(super::real_drive::view(
                study
                    .real_drive
                    .as_ref()
                    .expect("the outline shows the real drive only when the study ran it"),
                self.numbers,
            )?)),
            Section::Noise(_) => SectionView::Noise(Box::new(super::noise::view(
                study
                    .noise
                    .as_ref()
                    .expect("the outline shows the noise estimate only when the study ran it"),
                study.white_noise.as_ref(),
                self.numbers,
            )?)),
            Section::Conclusions => SectionView::Conclusions(self.conclusions()),
            Section::Appendix => SectionView::Appendix(AppendixView {
                command: self.input.command.to_string(),
                config_toml: study.model.config.to_toml_string(),
            }),
        })
    }

    fn abstract_view(&self) -> AbstractView {
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
            check_count: prose::checks_run(study).to_string(),
            check_titles: prose::and_list(&titles),
            false_alarm: percent(c.checks.false_alarm_rate),
            findings_html: rich::rich(&prose::abstract_findings(study, self.differences)),
        }
    }

    fn problem(&self) -> Result<ProblemView, RenderError> {
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

    fn theory(&self) -> TheoryView {
        let study = self.study();
        let c = &study.model.config;
        let tl = &study.model.timeline;
        TheoryView {
            eqn: equation_numbers(self.numbers),
            steps_per_fix: tl.steps_per_fix.to_string(),
            euler_velocity_drift: prose::euler_velocity_drift(study),
            interval_position_error: sig(
                tl.dt_s * tl.dt_s * c.profile.accel_amplitude_m_s2 / 12.0,
                2,
            ),
            realizations: count(c.ensemble.realizations),
            false_alarm: percent(c.checks.false_alarm_rate),
            false_alarm_share: prose::share_words(
                c.checks.false_alarm_rate,
                prose::checks_run(study),
            ),
            check_count: prose::checks_run(study).to_string(),
            catalogue: catalogue(study, self.math),
            steps: count(tl.steps as u64),
            fixes: count(tl.fixes() as u64),
        }
    }

    fn results(&self) -> Result<ResultsView, RenderError> {
        let study = self.study();
        let c = &study.model.config;
        let r = &study.realization;
        let last = r.fixes.last().expect("at least two fixes");
        let first = &study.schedule.fixes[0];
        let n = self.numbers;
        let claimed = prose::claimed_sigma(study);
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

    fn performance(&self) -> PerformanceView {
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

    fn conclusions(&self) -> ConclusionsView {
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
        prose::letter(i),
        prose::case_title(study.realization_case)
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
