//! The abstract's findings: which cases pass, what the analytic cases achieve against what
//! their filter claims, their deterministic mean error, what cannot be tested at this N. Every
//! sentence is chosen from the verdicts and numbers; strings may hold `_{…}`/`^{…}` notation,
//! which [`super::rich::rich`] turns into sub- and superscripts.

use super::quantities::{checks_run, claimed_sigma, explained};
use super::words::{and_list, failed_list, letter, named, per_state, untestable_list};
use crate::checks::{CheckId, Verdict};
use crate::config::TruthModel;
use crate::format::{count, fixed, sig};
use crate::state::ErrorState;
use crate::study::{CaseOutcome, Study};

/// The abstract's findings; `differences` lists the mistuned statistics.
pub fn abstract_findings(study: &Study, differences: &[String]) -> String {
    let mut s = String::new();
    if !differences.is_empty() {
        s.push_str(&format!(
            "In this run the filter deliberately assumes statistics that differ from the truth ({}). ",
            differences.join("; ")
        ));
    }
    s.push_str(&verdict_findings(study, differences));
    for o in study
        .cases
        .iter()
        .filter(|o| o.case.truth == TruthModel::Analytic)
    {
        s.push_str(&accuracy_sentence(study, o));
        s.push_str(&deterministic_mean_error(o));
        s.push(' ');
    }
    let untestable: Vec<String> = study
        .cases
        .iter()
        .flat_map(untestable_list)
        .map(String::from)
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    if !untestable.is_empty() {
        s.push_str(&format!(
            "At N = {} the {} checks cannot fail and are reported as untestable. ",
            count(study.model.config.ensemble.realizations),
            and_list(&untestable)
        ));
    }
    s.trim_end().to_string()
}

/// Which cases pass every check and which fail what, in a sentence.
fn verdict_findings(study: &Study, differences: &[String]) -> String {
    let mut s = String::new();
    let consistent: Vec<String> = study
        .cases
        .iter()
        .enumerate()
        .filter(|(_, o)| o.verdicts.all_passed())
        .map(|(i, _)| letter(i))
        .collect();
    let failing: Vec<String> = study
        .cases
        .iter()
        .enumerate()
        .filter(|(_, o)| o.verdicts.failed().next().is_some())
        .map(|(i, o)| format!("case {} fails {}", letter(i), failed_list(o)))
        .collect();
    let total = checks_run(study);
    if !consistent.is_empty() {
        let (noun, verb) = if consistent.len() == 1 {
            ("Case", "passes")
        } else {
            ("Cases", "pass")
        };
        s.push_str(&format!(
            "{noun} {} {verb} all {total} checks{}",
            and_list(&consistent),
            if failing.is_empty() { ". " } else { "; " }
        ));
    }
    if !failing.is_empty() {
        let f = and_list(&failing);
        if consistent.is_empty() {
            s.push_str(&format!("{}{}", f[..1].to_uppercase(), &f[1..]));
        } else {
            s.push_str(&f);
        }
        let model_world_fails = study
            .cases
            .iter()
            .any(|o| o.case.truth == TruthModel::Euler && o.verdicts.failed().next().is_some());
        s.push_str(if !differences.is_empty() && model_world_fails {
            ": the checks detect the mistuning. "
        } else {
            ". "
        });
    }
    s
}

/// What case `o` achieves against what its filter claims, in one sentence.
fn accuracy_sentence(study: &Study, o: &CaseOutcome) -> String {
    let claimed = claimed_sigma(study);
    let achieved = o.achieved_rms_final();
    let ratio: [f64; ErrorState::DIM] = std::array::from_fn(|k| achieved[k] / claimed[k]);
    let end = fixed(study.schedule.fixes.last().expect("fixes").time_s, 0);
    let worst = (0..ErrorState::DIM)
        .max_by(|&a, &b| (ratio[a] - 1.0).abs().total_cmp(&(ratio[b] - 1.0).abs()))
        .expect("a state");
    if (ratio[worst] - 1.0).abs() <= 0.05 {
        format!(
            "With {}, the achieved RMS errors at {end} s are {}, within {} % of the filter's σ.",
            named(study, o),
            per_state(achieved),
            sig(100.0 * (ratio[worst] - 1.0).abs(), 2)
        )
    } else {
        // Over the run, each state's largest ratio and where it is.
        let peak = |k: usize| {
            o.achieved_rms
                .iter()
                .zip(&study.schedule.fixes)
                .map(|(rms, f)| (rms[k] / f.p_post[(k, k)].sqrt(), f.time_s))
                .fold((0.0, 0.0), |best, x| if x.0 > best.0 { x } else { best })
        };
        let off: Vec<String> = (0..ErrorState::DIM)
            .filter(|&k| (ratio[k] - 1.0).abs() > 0.05 || k == worst)
            .map(|k| {
                let (p, t) = peak(k);
                format!(
                    "its {} error is {} times its claim ({} at its worst, at {} s)",
                    ErrorState::VARIABLES[k].key,
                    fixed(ratio[k], 2),
                    fixed(p, 2),
                    fixed(t, 1)
                )
            })
            .collect();
        format!(
            "With {}, the filter claims σ = {} at {end} s but achieves RMS errors of {}: {}.",
            named(study, o),
            per_state(claimed),
            per_state(achieved),
            and_list(&off)
        )
    }
}

/// " Its mean error is deterministic: …" when case `o` fails the mean-error check; else empty.
fn deterministic_mean_error(o: &CaseOutcome) -> String {
    if o.verdicts.all_passed() || o.verdicts.get(CheckId::MEAN_ERROR).verdict != Verdict::Fail {
        return String::new();
    }
    format!(
        " Its mean error is deterministic: one noise-free pass of the filter predicts it {}.",
        if explained(o) {
            format!(
                "to within {} standard errors, inside the check's bound",
                fixed(o.prediction.worst_se, 1)
            )
        } else {
            format!(
                "only to within {} standard errors, beyond the check's bound",
                fixed(o.prediction.worst_se, 1)
            )
        }
    )
}
