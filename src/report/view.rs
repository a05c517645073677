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
