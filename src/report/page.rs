//! The page's view: one view struct per section, the sections in the order of the outline, and
//! the table of contents. Like every view, fields are text ready for a template (`_html` fields
//! hold HTML made by [`super::rich::rich`]); the whole page view is written as `view.json`.

use serde::Serialize;

use super::view::{
    AccuracyRow, CaseView, CatalogueEntry, EquationNumbers, FigureView, ParamRow, PerformanceRow,
    PredictionRow, SensitivityView, SummaryRow,
};

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
    /// Noise statistics from a static log.
    StaticNoise(Box<crate::allan::section::AllanSection>),
    /// A drifting bias.
    Drift(Box<super::drift::DriftView>),
    /// A real drive.
    RealDrive(Box<super::real_drive::RealDriveView>),
    /// Noise statistics from a drive.
    Noise(Box<super::noise::NoiseView>),
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
            SectionView::StaticNoise(_) => "allan".to_string(),
            SectionView::Drift(_) => "drifting-bias".to_string(),
            SectionView::RealDrive(_) => "real-drive".to_string(),
            SectionView::Noise(_) => "noise-estimate".to_string(),
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
            SectionView::StaticNoise(_) => "Noise statistics from a static log".to_string(),
            SectionView::Drift(_) => "A drifting bias".to_string(),
            SectionView::RealDrive(_) => "A real drive".to_string(),
            SectionView::Noise(_) => "Noise statistics from a drive".to_string(),
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
