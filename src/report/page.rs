//! The page's view: one view struct per section, the sections in the order of the outline, and
//! the table of contents. Like every view, fields are text ready for a template (`_html` fields
//! hold HTML made by [`super::rich::rich`]); the whole page view is written as `view.json`.

use std::sync::Arc;

use serde::Serialize;

use super::json;
use super::kind::SectionView;

use super::view::{
    AccuracyRow, CatalogueEntry, EquationNumbers, FigureView, ParamRow, PerformanceRow,
    PredictionRow, SummaryRow,
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

/// A section's view and its subsections'.
#[derive(Clone, Debug)]
pub struct SectionNode {
    /// The key of its kind ([`super::kind::SectionKind::key`]): `view.json`'s `"section"`.
    pub key: &'static str,
    /// The section's view.
    pub view: Arc<dyn SectionView>,
    /// Its subsections, in order.
    pub children: Vec<SectionNode>,
}

impl SectionNode {
    /// The view as `V`, when the section's view is one.
    pub fn get<V: SectionView>(&self) -> Option<&V> {
        self.view.as_any().downcast_ref::<V>()
    }

    /// The node as `view.json` shows it: `"section"`, the view's fields, then `"children"`
    /// when it has subsections.
    pub fn to_json(&self) -> String {
        let fields = json::prepend(&self.view.fields_json(), "section", &json::string(self.key));
        if self.children.is_empty() {
            fields
        } else {
            let children: Vec<String> = self.children.iter().map(SectionNode::to_json).collect();
            json::append(&fields, "children", &json::array(&children))
        }
    }
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
#[derive(Clone, Debug)]
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

impl ReportView {
    /// Every section and subsection, in reading order.
    pub fn all(&self) -> impl Iterator<Item = &SectionNode> {
        self.sections
            .iter()
            .flat_map(|n| std::iter::once(n).chain(&n.children))
    }

    /// The first section whose view is a `V`.
    pub fn find<V: SectionView>(&self) -> Option<&V> {
        self.all().find_map(SectionNode::get)
    }

    /// `view.json`: version, seed, contents and every section, indented.
    pub fn to_json(&self) -> String {
        #[derive(Serialize)]
        struct Head<'a> {
            version: &'a str,
            seed: &'a str,
            toc: &'a [TocEntry],
        }
        let head = serde_json::to_string_pretty(&Head {
            version: &self.version,
            seed: &self.seed,
            toc: &self.toc,
        })
        .expect("the view is plain text");
        let sections: Vec<String> = self.sections.iter().map(SectionNode::to_json).collect();
        json::append(&head, "sections", &json::array(&sections))
    }
}
