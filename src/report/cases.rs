//! The view of each case: its verdict table, residual pair, accuracy and prediction, and the
//! verdict summary across cases.

use super::rich::rich;
use super::view::{
    AccuracyCell, AccuracyRow, CaseView, CheckRow, FigureView, PairView, PerformanceRow,
    PredictionRow, SummaryCell, SummaryRow, VerdictView,
};
use super::words::{and_list, case_title, failure_sentence, letter};
use crate::checks::{Check, CheckId, Untestable, Verdict, Verdicts};
use crate::format::{count, fixed, sig};
use crate::state::{ErrorState, StateModel, Variable};
use crate::study::CaseOutcome;

/// The verdict in words: "pass", "fail", "untestable at N = 10, needs N ≥ 22".
pub fn verdict_words(verdict: Verdict, n: u64) -> String {
    match verdict {
        Verdict::Pass => "pass".to_string(),
        Verdict::Fail => "fail".to_string(),
        Verdict::Untestable(Untestable::TooFewRealizations { needs }) => {
            format!("untestable at N = {}, needs N ≥ {}", count(n), count(needs))
        }
        Verdict::Untestable(Untestable::NoMembers) => "untestable: no member varies".to_string(),
    }
}

/// Worst against band, in a few characters.
fn worst_and_band(c: &Check) -> (String, String) {
    if c.is_normal() {
        (
            format!("|z| = {}", fixed(c.worst_value(), 2)),
            format!("|z| ≤ {}", fixed(c.upper, 2)),
        )
    } else {
        (
            sig(c.worst_value(), 4),
            format!("[{}, {}]", sig(c.lower, 4), sig(c.upper, 4)),
        )
    }
}

/// The row of check `c` in an ensemble of `n` realizations with fixes at `fix_times_s`.
pub fn check_row(c: &Check, n: u64, fix_times_s: &[f64]) -> CheckRow {
    let (worst, band) = worst_and_band(c);
    CheckRow {
        id: c.id.name().to_string(),
        what: c.definition.hypothesis.to_string(),
        statistic: c.definition.statistic.to_string(),
        members: count(c.members as u64),
        worst,
        worst_at: c
            .worst
            .map_or_else(String::new, |w| w.member.describe(fix_times_s)),
        band,
        outside: count(c.failures as u64),
        verdict: VerdictView::of(c.verdict),
        verdict_words: verdict_words(c.verdict, n),
    }
}

/// The verdict summary: one row per check the cases ran, one cell per case.
pub fn summary(cases: &[CaseOutcome]) -> Vec<SummaryRow> {
    let Some(first) = cases.first() else {
        return Vec::new();
    };
    first
        .verdicts
        .checks
        .iter()
        .map(|check| SummaryRow {
            id: check.id.name().to_string(),
            title: check.definition.title.to_string(),
            cells: cases
                .iter()
                .map(|o| {
                    let c = o.verdicts.get(check.id);
                    let (worst, band) = worst_and_band(c);
                    SummaryCell {
                        verdict: VerdictView::of(c.verdict),
                        detail: match (c.is_normal(), c.failures > 0) {
                            (true, false) => format!("{worst} ≤ {}", fixed(c.upper, 2)),
                            (true, true) => format!("{worst} > {}", fixed(c.upper, 2)),
                            (false, false) => format!("{worst} ∈ {band}"),
                            (false, true) => format!("{worst} ∉ {band}"),
                        },
                    }
                })
                .collect(),
        })
        .collect()
}

fn pair_view(o: &CaseOutcome) -> PairView {
    let p = &o.verdicts.residual_pair;
    let labels = [
        ("r_{p}(t_{i}) · r_{p}(t_{m})", "m²"),
        ("r_{p}(t_{i}) · r_{v}(t_{m})", "m²/s"),
        ("r_{v}(t_{i}) · r_{p}(t_{m})", "m²/s"),
        ("r_{v}(t_{i}) · r_{v}(t_{m})", "m²/s²"),
    ];
    PairView {
        t_m: fixed(p.t_m_s, 1),
        t_i: fixed(p.t_i_s, 1),
        rows: (0..4)
            .map(|c| {
                let (j, k) = (c / 2, c % 2);
                [
                    rich(labels[c].0),
                    format!("{} {}", sig(p.mean_product[j][k], 3), labels[c].1),
                    fixed(p.z[j][k], 2),
                ]
            })
            .collect(),
        bound: fixed(p.bound, 2),
        verdict: VerdictView::of(p.verdict),
    }
}

/// The state variables, in state order.
pub fn states() -> [Variable; ErrorState::DIM] {
    <ErrorState as StateModel<{ ErrorState::DIM }, { ErrorState::MEAS }>>::STATES
}

/// "What failed" of a case: "every check passes", "fails mean error and NEES", ….
fn verdict_words_of(v: &Verdicts) -> String {
    let failed: Vec<String> = v.failed().map(|c| c.definition.title.to_string()).collect();
    let untestable: Vec<String> = v
        .checks
        .iter()
        .filter(|c| matches!(c.verdict, Verdict::Untestable(_)))
        .map(|c| c.definition.title.to_string())
        .collect();
    match (failed.is_empty(), untestable.is_empty()) {
        (true, true) => "every check passes".to_string(),
        (false, true) => format!("fails {}", and_list(&failed)),
        (true, false) => format!("{} untestable at this N", and_list(&untestable)),
        (false, false) => format!(
            "fails {}; {} untestable at this N",
            and_list(&failed),
            and_list(&untestable)
        ),
    }
}

/// "0.998, 1.00 and 1.01": achieved over claimed σ per state.
fn ratios_words(o: &CaseOutcome, claimed: [f64; ErrorState::DIM]) -> String {
    let achieved = o.achieved_rms_final();
    let ratios: Vec<String> = (0..ErrorState::DIM)
        .map(|k| fixed(achieved[k] / claimed[k], 3))
        .collect();
    and_list(&ratios)
}

/// "position, velocity and bias".
fn states_words() -> String {
    and_list(&states().map(|s| s.key.to_string()))
}

/// The view of case `o`, the `index`-th; its tables are numbered `tables` (verdicts, pair).
pub fn case_view(
    o: &CaseOutcome,
    index: usize,
    tables: (usize, usize),
    figures: Vec<FigureView>,
    claimed: [f64; ErrorState::DIM],
) -> CaseView {
    let v = &o.verdicts;
    let n = o.run.stats.realizations;
    let fix_times_s: Vec<f64> = o.run.stats.fixes.iter().map(|f| f.time_s).collect();
    CaseView {
        id: o.case.id().replace('_', "-"),
        letter: letter(index),
        title: case_title(o.case).to_string(),
        truth: o.case.truth.name().to_string(),
        output: o.case.output.name().to_string(),
        consistent: v.all_passed(),
        realizations: count(n),
        verdict: verdict_words_of(v),
        passed_count: format!(
            "{} of {}",
            v.checks.iter().filter(|c| c.passed()).count(),
            v.checks.len()
        ),
        table_number: tables.0,
        checks: v
            .checks
            .iter()
            .map(|c| check_row(c, n, &fix_times_s))
            .collect(),
        pair_table_number: tables.1,
        pair: pair_view(o),
        ratios_words: ratios_words(o, claimed),
        states_words: states_words(),
        worst_se: fixed(o.prediction.worst_se, 2),
        explained: o.prediction.worst_se <= v.get(CheckId::MEAN_ERROR).upper,
        max_mean_over_sigma: o.max_mean_over_sigma.iter().map(|x| sig(*x, 2)).collect(),
        failures_html: v
            .failed()
            .map(|c| rich(&failure_sentence(c, &fix_times_s)))
            .collect(),
        figures,
    }
}

/// "A: Euler-integrated truth, point samples" for the `index`-th case.
pub fn case_label(o: &CaseOutcome, index: usize) -> String {
    format!("{}: {}", letter(index), case_title(o.case))
}

/// The accuracy table's row of case `o`, the `index`-th.
pub fn accuracy_row(o: &CaseOutcome, index: usize, claimed: [f64; ErrorState::DIM]) -> AccuracyRow {
    let achieved = o.achieved_rms_final();
    AccuracyRow {
        case: case_label(o, index),
        cells: (0..ErrorState::DIM)
            .map(|k| AccuracyCell {
                achieved: sig(achieved[k], 3),
                claimed: sig(claimed[k], 3),
                ratio: fixed(achieved[k] / claimed[k], 3),
            })
            .collect(),
    }
}

/// The prediction table's row of case `o`, the `index`-th.
pub fn prediction_row(o: &CaseOutcome, index: usize) -> PredictionRow {
    PredictionRow {
        case: case_label(o, index),
        worst_se: fixed(o.prediction.worst_se, 2),
        mean_bound: fixed(o.verdicts.get(CheckId::MEAN_ERROR).upper, 2),
        predicted_nees: sig(o.prediction.predicted_nees_final, 4),
        measured_nees: sig(o.prediction.measured_nees_final, 4),
    }
}

/// The performance table's row of case `o`, the `index`-th.
pub fn performance_row(o: &CaseOutcome, index: usize) -> PerformanceRow {
    PerformanceRow {
        case: case_label(o, index),
        realizations: count(o.run.stats.realizations),
        elapsed: fixed(o.run.elapsed_s, 2),
        rate: count(o.run.realizations_per_s().round() as u64),
    }
}
