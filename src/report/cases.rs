//! The view of each case: its verdict table, residual pair, accuracy and prediction, and the
//! verdict summary across cases.

use super::prose::{and_list, case_title, failure_sentence, letter};
use super::rich::rich;
use super::view::{CaseView, CheckRow, FigureView, PairView, SummaryCell, SummaryRow, VerdictView};
use crate::checks::{Check, CheckId, Untestable, Verdict};
use crate::format::{count, fixed, sig};
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

/// The view of case `o`, the `index`-th; its tables are numbered `tables` (verdicts, pair).
pub fn case_view(
    o: &CaseOutcome,
    index: usize,
    tables: (usize, usize),
    figures: Vec<FigureView>,
    claimed: [f64; 3],
) -> CaseView {
    let v = &o.verdicts;
    let n = o.run.stats.realizations;
    let fix_times_s: Vec<f64> = o.run.stats.fixes.iter().map(|f| f.time_s).collect();
    let failed: Vec<String> = v.failed().map(|c| c.definition.title.to_string()).collect();
    let untestable: Vec<String> = v
        .checks
        .iter()
        .filter(|c| matches!(c.verdict, Verdict::Untestable(_)))
        .map(|c| c.definition.title.to_string())
        .collect();
    let verdict = match (failed.is_empty(), untestable.is_empty()) {
        (true, true) => "every check passes".to_string(),
        (false, true) => format!("fails {}", and_list(&failed)),
        (true, false) => format!("{} untestable at this N", and_list(&untestable)),
        (false, false) => format!(
            "fails {}; {} untestable at this N",
            and_list(&failed),
            and_list(&untestable)
        ),
    };
    let achieved = o.achieved_rms_final();
    let mean = v.get(CheckId::MEAN_ERROR);
    CaseView {
        id: o.case.id().replace('_', "-"),
        letter: letter(index),
        title: case_title(o.case).to_string(),
        truth: o.case.truth.name().to_string(),
        output: o.case.output.name().to_string(),
        consistent: v.all_passed(),
        realizations: count(n),
        verdict,
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
        achieved: achieved.iter().map(|x| sig(*x, 3)).collect(),
        claimed: claimed.iter().map(|x| sig(*x, 3)).collect(),
        ratio: (0..3).map(|k| fixed(achieved[k] / claimed[k], 3)).collect(),
        worst_se: fixed(o.prediction.worst_se, 2),
        mean_bound: fixed(mean.upper, 2),
        explained: o.prediction.worst_se <= mean.upper,
        predicted_nees: sig(o.prediction.predicted_nees_final, 4),
        measured_nees: sig(o.prediction.measured_nees_final, 4),
        max_mean_over_sigma: o.max_mean_over_sigma.iter().map(|x| sig(*x, 2)).collect(),
        failures_html: v
            .failed()
            .map(|c| rich(&failure_sentence(c, &fix_times_s)))
            .collect(),
        rate: count(o.run.realizations_per_s().round() as u64),
        elapsed: fixed(o.run.elapsed_s, 2),
        figures,
    }
}
