//! The report's view model: every field is text ready for a template. Templates never format
//! numbers; this module and its siblings [`super::prose`], [`super::params`] and
//! [`super::cases`] choose every number's precision and every verdict's words. Fields whose
//! names end in `_html` hold HTML made by [`super::rich::rich`] (escaped, with sub- and
//! superscripts); the rest are plain text. The whole view is also written as `view.json` beside
//! the page, so that a test or a person can read what the page shows.

use std::fmt;

use serde::Serialize;

use crate::checks::Verdict;

/// A verdict as the page shows it: its word is also its CSS class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum VerdictView {
    /// Every member in its band.
    Pass,
    /// Some member outside its band.
    Fail,
    /// The check cannot fail at this N.
    Untestable,
}

impl VerdictView {
    /// The view of `verdict`.
    pub fn of(verdict: Verdict) -> Self {
        match verdict {
            Verdict::Pass => VerdictView::Pass,
            Verdict::Fail => VerdictView::Fail,
            Verdict::Untestable(_) => VerdictView::Untestable,
        }
    }

    /// Whether the check could not be tested (its row then says why).
    pub fn is_untestable(&self) -> bool {
        *self == VerdictView::Untestable
    }
}

impl fmt::Display for VerdictView {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            VerdictView::Pass => "pass",
            VerdictView::Fail => "fail",
            VerdictView::Untestable => "untestable",
        })
    }
}

/// A figure: number, title, caption and the SVG itself.
#[derive(Clone, Debug, Serialize)]
pub struct FigureView {
    /// Element id, e.g. `fig-mean-error-euler-sample`.
    pub id: String,
    /// Figure number, in reading order.
    pub number: usize,
    /// Title, set in bold before the caption.
    pub title: String,
    /// Caption, as HTML.
    pub caption_html: String,
    /// The inline SVG (left out of view.json).
    #[serde(skip)]
    pub svg: String,
}

/// A row of the parameter table.
#[derive(Clone, Debug, Serialize)]
pub struct ParamRow {
    /// The quantity, as HTML.
    pub quantity_html: String,
    /// Its value.
    pub value: String,
    /// Its unit.
    pub unit: String,
    /// The configuration field that sets it.
    pub field: String,
}

/// A row of a verdict table.
#[derive(Clone, Debug, Serialize)]
pub struct CheckRow {
    /// The check's identifier.
    pub id: String,
    /// The hypothesis it tests.
    pub what: String,
    /// The member statistic.
    pub statistic: String,
    /// Number of distinct members.
    pub members: String,
    /// The worst member's statistic.
    pub worst: String,
    /// Where the worst member is.
    pub worst_at: String,
    /// The acceptance band.
    pub band: String,
    /// Members outside the band.
    pub outside: String,
    /// Pass, fail or untestable (its word is also the CSS class).
    pub verdict: VerdictView,
    /// The verdict in words ("untestable at N = 10, needs N ≥ 22").
    pub verdict_words: String,
}

/// One cell of the verdict summary: a check on a case.
#[derive(Clone, Debug, Serialize)]
pub struct SummaryCell {
    /// Pass, fail or untestable.
    pub verdict: VerdictView,
    /// Worst against bound, e.g. "|z| = 1.92 ≤ 4.76".
    pub detail: String,
}

/// A row of the verdict summary: one check over every case.
#[derive(Clone, Debug, Serialize)]
pub struct SummaryRow {
    /// The check's identifier.
    pub id: String,
    /// Its title.
    pub title: String,
    /// One cell per case.
    pub cells: Vec<SummaryCell>,
}

/// The statement's single residual pair of one case.
#[derive(Clone, Debug, Serialize)]
pub struct PairView {
    /// t_m, s.
    pub t_m: String,
    /// t_i, s.
    pub t_i: String,
    /// Rows: (product as HTML, mean product with unit, z).
    pub rows: Vec<[String; 3]>,
    /// Bound on |z|.
    pub bound: String,
    /// Pass, fail or untestable.
    pub verdict: VerdictView,
}

/// One case: its verdicts, accuracy, prediction and figures (a subsection of the results).
#[derive(Clone, Debug, Serialize)]
pub struct CaseView {
    /// Element id stem, e.g. `euler-sample`.
    pub id: String,
    /// "A", "B", "C".
    pub letter: String,
    /// "Euler-integrated truth, point samples".
    pub title: String,
    /// Truth model name.
    pub truth: String,
    /// Accelerometer output name.
    pub output: String,
    /// Whether every check passes.
    pub consistent: bool,
    /// N.
    pub realizations: String,
    /// "every check passes" or what failed.
    pub verdict: String,
    /// "5 of 7".
    pub passed_count: String,
    /// Number of its verdict table.
    pub table_number: usize,
    /// One row per check.
    pub checks: Vec<CheckRow>,
    /// Number of its residual-pair table.
    pub pair_table_number: usize,
    /// The single residual pair.
    pub pair: PairView,
    /// Achieved RMS error over the filter's σ at the last fix, per state: "0.998, 1.00 and 1.01".
    pub ratios_words: String,
    /// The states in that order: "position, velocity and bias".
    pub states_words: String,
    /// Worst |e_ave − m_pred| / (σ/√N).
    pub worst_se: String,
    /// Whether the prediction explains the mean error within the mean-error check's bound.
    pub explained: bool,
    /// Largest |a posteriori mean error| / σ per state over the run.
    pub max_mean_over_sigma: Vec<String>,
    /// Sentences on what failed, as HTML; empty when nothing did.
    pub failures_html: Vec<String>,
    /// Its check figures.
    pub figures: Vec<FigureView>,
}

/// One state's accuracy on one case at the last fix.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyCell {
    /// Achieved RMS error.
    pub achieved: String,
    /// The filter's σ.
    pub claimed: String,
    /// Achieved over claimed.
    pub ratio: String,
}

/// A row of the accuracy table: one case.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyRow {
    /// "A: Euler-integrated truth, point samples".
    pub case: String,
    /// One cell per state.
    pub cells: Vec<AccuracyCell>,
}

/// A row of the prediction table: one case.
#[derive(Clone, Debug, Serialize)]
pub struct PredictionRow {
    /// "A: Euler-integrated truth, point samples".
    pub case: String,
    /// Worst |e_ave − m_pred| / (σ/√N).
    pub worst_se: String,
    /// The mean-error check's bound.
    pub mean_bound: String,
    /// Predicted average a posteriori NEES at the last fix.
    pub predicted_nees: String,
    /// Measured average a posteriori NEES at the last fix.
    pub measured_nees: String,
}

/// A row of the performance table: one case.
#[derive(Clone, Debug, Serialize)]
pub struct PerformanceRow {
    /// "A: Euler-integrated truth, point samples".
    pub case: String,
    /// N.
    pub realizations: String,
    /// Run time, s.
    pub elapsed: String,
    /// Realizations per second.
    pub rate: String,
}

/// Numbers of the display equations, in reading order.
#[derive(Clone, Debug, Serialize)]
pub struct EquationNumbers {
    /// The acceleration profile.
    pub profile: usize,
    /// The closed-form truth.
    pub analytic_truth: usize,
    /// The accelerometer, point samples.
    pub accelerometer: usize,
    /// The accelerometer, interval means.
    pub interval_mean: usize,
    /// The accelerometer's Euler integration.
    pub integration: usize,
    /// The GPS.
    pub gps: usize,
    /// The truth integrated like the accelerometer.
    pub euler_truth: usize,
    /// The error dynamics.
    pub dynamics: usize,
    /// The measurement of the error state.
    pub measurement: usize,
    /// The velocity lag of point samples.
    pub lag: usize,
    /// The predicted mean error.
    pub prediction: usize,
}

/// The abstract.
#[derive(Clone, Debug, Serialize)]
pub struct AbstractView {
    /// Accelerometer rate, Hz.
    pub accel_rate: String,
    /// GPS rate, Hz.
    pub gps_rate: String,
    /// N.
    pub realizations: String,
    /// Number of checks each case runs.
    pub check_count: String,
    /// Their titles, "mean error, variance, … and NIS".
    pub check_titles: String,
    /// Study-wide false-alarm rate.
    pub false_alarm: String,
    /// The results, as HTML.
    pub findings_html: String,
}

/// The introduction (its words do not depend on the run).
#[derive(Clone, Debug, Serialize)]
pub struct IntroductionView {}

/// The problem and its parameters.
#[derive(Clone, Debug, Serialize)]
pub struct ProblemView {
    /// Equation numbers.
    pub eqn: EquationNumbers,
    /// Accelerometer rate, Hz.
    pub accel_rate: String,
    /// GPS rate, Hz.
    pub gps_rate: String,
    /// Samples between fixes.
    pub steps_per_fix: String,
    /// Number of the parameter table.
    pub params_table: usize,
    /// The parameter table.
    pub params: Vec<ParamRow>,
    /// Whether the filter assumes the truth's statistics.
    pub filter_matches_truth: bool,
    /// What the filter assumes differently.
    pub filter_differences: Vec<String>,
    /// Interpretation choices, as HTML.
    pub choices_html: Vec<String>,
    /// Acceleration profile and trajectory.
    pub trajectory: FigureView,
}

/// Theory and algorithm.
#[derive(Clone, Debug, Serialize)]
pub struct TheoryView {
    /// Equation numbers.
    pub eqn: EquationNumbers,
    /// Samples between fixes.
    pub steps_per_fix: String,
    /// Δt·A/2, m/s.
    pub euler_velocity_drift: String,
    /// Δt²·A/12, the position error left with interval means, m.
    pub interval_position_error: String,
    /// N.
    pub realizations: String,
    /// Study-wide false-alarm rate.
    pub false_alarm: String,
    /// Each check's share of it.
    pub false_alarm_share: String,
    /// Number of checks each case runs.
    pub check_count: String,
    /// The checks each case runs.
    pub catalogue: Vec<CatalogueEntry>,
    /// Number of accelerometer samples.
    pub steps: String,
    /// Number of GPS fixes.
    pub fixes: String,
}

/// Results: one realization, the verdicts of every case, accuracy and the mean error.
#[derive(Clone, Debug, Serialize)]
pub struct ResultsView {
    /// Estimation error of one realization.
    pub realization: FigureView,
    /// The case of the recorded realization, in words.
    pub realization_case: String,
    /// Time of the first fix, s.
    pub first_fix: String,
    /// Position σ after the first fix, m.
    pub first_fix_sigma_p: String,
    /// Velocity σ after the first fix, m/s.
    pub first_fix_sigma_v: String,
    /// "0.0094 m/s² after 1 s, … and 0.00047 m/s² at the end": milestones within the run.
    pub bias_sigma_progress: String,
    /// The realization's true bias, m/s².
    pub bias_true: String,
    /// Its final estimate, m/s².
    pub bias_estimate: String,
    /// Estimate error in σ.
    pub bias_error_sigmas: String,
    /// N.
    pub realizations: String,
    /// Study-wide false-alarm rate.
    pub false_alarm: String,
    /// Number of the verdict summary.
    pub summary_table: usize,
    /// The cases, "A: Euler-integrated truth, point samples", the summary's columns.
    pub cases: Vec<String>,
    /// The verdict summary, one row per check.
    pub summary: Vec<SummaryRow>,
    /// Number of the accuracy table.
    pub accuracy_table: usize,
    /// Time of the last fix, s.
    pub end_time: String,
    /// The accuracy table's columns: "position (m)", one per state.
    pub state_columns: Vec<String>,
    /// The accuracy table's rows.
    pub accuracy_rows: Vec<AccuracyRow>,
    /// Achieved RMS error over the filter's σ, every case.
    pub accuracy: FigureView,
    /// Number of the mean-error prediction equation.
    pub prediction_eq: usize,
    /// Number of the prediction table.
    pub prediction_table: usize,
    /// The prediction table's rows.
    pub prediction_rows: Vec<PredictionRow>,
    /// |Mean error| / σ of every case, log scale.
    pub mean_error: FigureView,
}

/// The run times of the ensembles.
#[derive(Clone, Debug, Serialize)]
pub struct PerformanceView {
    /// Number of the table.
    pub table: usize,
    /// Threads of the ensemble runs.
    pub threads: String,
    /// Accelerometer rate, Hz.
    pub accel_rate: String,
    /// One row per case.
    pub rows: Vec<PerformanceRow>,
}

/// Conclusions.
#[derive(Clone, Debug, Serialize)]
pub struct ConclusionsView {
    /// One paragraph each, as HTML.
    pub paragraphs_html: Vec<String>,
}

/// Configuration and reproduction.
#[derive(Clone, Debug, Serialize)]
pub struct AppendixView {
    /// The command that reproduces the report.
    pub command: String,
    /// The configuration as TOML.
    pub config_toml: String,
}

/// The view of one section (the large ones boxed: a section is built once).
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "section", rename_all = "snake_case")]
pub enum SectionView {
    /// The abstract.
    Abstract(AbstractView),
    /// The introduction.
    Introduction(IntroductionView),
    /// The problem and its parameters.
    Problem(Box<ProblemView>),
    /// Theory and algorithm.
    Theory(Box<TheoryView>),
    /// Results.
    Results(Box<ResultsView>),
    /// One case.
    Case(Box<CaseView>),
    /// Run times.
    Performance(PerformanceView),
    /// Sensitivity to the assumed statistics.
    Sensitivity(Box<SensitivityView>),
    /// Conclusions.
    Conclusions(ConclusionsView),
    /// Configuration and reproduction.
    Appendix(AppendixView),
}

impl SectionView {
    /// The element id of the section.
    pub fn anchor(&self) -> String {
        match self {
            SectionView::Abstract(_) => "abstract".to_string(),
            SectionView::Introduction(_) => "introduction".to_string(),
            SectionView::Problem(_) => "problem".to_string(),
            SectionView::Theory(_) => "theory".to_string(),
            SectionView::Results(_) => "results".to_string(),
            SectionView::Case(c) => format!("case-{}", c.id),
            SectionView::Performance(_) => "performance".to_string(),
            SectionView::Sensitivity(_) => "sensitivity".to_string(),
            SectionView::Conclusions(_) => "conclusions".to_string(),
            SectionView::Appendix(_) => "appendix".to_string(),
        }
    }

    /// The section's heading.
    pub fn title(&self) -> String {
        match self {
            SectionView::Abstract(_) => "Abstract".to_string(),
            SectionView::Introduction(_) => "Introduction".to_string(),
            SectionView::Problem(_) => "The problem and its parameters".to_string(),
            SectionView::Theory(_) => "Theory and algorithm".to_string(),
            SectionView::Results(_) => "Results and performance".to_string(),
            SectionView::Case(c) => format!("Case {}: {}", c.letter, c.title),
            SectionView::Performance(_) => "Performance".to_string(),
            SectionView::Sensitivity(_) => "Sensitivity to the assumed statistics".to_string(),
            SectionView::Conclusions(_) => "Conclusions".to_string(),
            SectionView::Appendix(_) => "Appendix: configuration and reproduction".to_string(),
        }
    }
}

/// A section's view and its subsections'.
#[derive(Clone, Debug, Serialize)]
pub struct SectionNode {
    /// The section.
    #[serde(flatten)]
    pub view: SectionView,
    /// Its subsections, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub children: Vec<SectionNode>,
}

/// An entry of the table of contents.
#[derive(Clone, Debug, Serialize)]
pub struct TocEntry {
    /// The element id it links to.
    pub anchor: String,
    /// The section's heading.
    pub title: String,
}

/// Everything the report page shows: its sections in the order of the outline.
#[derive(Clone, Debug, Serialize)]
pub struct ReportView {
    /// accelcal version.
    pub version: String,
    /// Seed.
    pub seed: String,
    /// The table of contents: the top-level sections.
    pub toc: Vec<TocEntry>,
    /// The sections.
    pub sections: Vec<SectionNode>,
}

/// One entry of the check catalogue, for the theory section.
#[derive(Clone, Debug, Serialize)]
pub struct CatalogueEntry {
    /// The check's identifier.
    pub id: String,
    /// Its title, capitalized.
    pub title: String,
    /// The hypothesis, as a sentence.
    pub hypothesis: String,
    /// Why the statistic has its distribution.
    pub rationale: String,
    /// What one member is.
    pub members: String,
    /// The check's equations as MathML (left out of view.json).
    #[serde(skip)]
    pub formula: String,
}

/// A cell of the detection table: one check on one mistuned filter.
#[derive(Clone, Debug, Serialize)]
pub struct DetectionCell {
    /// Predicted probability ("—" where there is no closed form).
    pub predicted: String,
    /// Ensembles in which the check failed, of those run: "3/20".
    pub measured: String,
    /// "high" (sure to detect), "mid" or "low" (sure to miss): the shading of the cell.
    pub level: String,
}

/// A row of the detection table.
#[derive(Clone, Debug, Serialize)]
pub struct DetectionRow {
    /// The assumed statistic, in words.
    pub parameter: String,
    /// The factor on its σ.
    pub factor: String,
    /// Expected a posteriori NEES at the last fix.
    pub expected_nees: String,
    /// Actual over claimed bias σ at the last fix.
    pub bias_ratio: String,
    /// Actual bias σ over that of the filter that assumes the truth, at the last fix.
    pub bias_vs_tuned: String,
    /// One cell per check.
    pub cells: Vec<DetectionCell>,
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct SensitivityView {
    /// Actual against claimed σ.
    pub figure: FigureView,
    /// Number of the detection table.
    pub table_number: usize,
    /// The check identifiers, the table's columns.
    pub checks: Vec<String>,
    /// The table's rows.
    pub rows: Vec<DetectionRow>,
    /// Realizations per Monte Carlo ensemble.
    pub realizations: String,
    /// Ensembles per case.
    pub ensembles: String,
    /// Sampled ensembles per case behind the predictions.
    pub draws: String,
    /// Whether the detection was sampled at all (`sensitivity.draws` > 0).
    pub sampled: bool,
    /// The engine of the Monte Carlo ensembles, in words.
    pub engine_words: String,
    /// Ensembles per case, in words: "one independent Monte Carlo ensemble".
    pub ensembles_words: String,
    /// Words derived from the numbers, one paragraph each.
    pub findings_html: Vec<String>,
}
