//! Text helpers of the report's sentences: a case's name and letter, lists in words, what a
//! failed check means, a value per state. They format what they are given and decide nothing.

use crate::checks::{Check, FailureWords, Verdict};
use crate::config::{AccelerometerOutput, Case, TruthModel};
use crate::format::{count, percent, sig};
use crate::state::ErrorState;
use crate::study::{CaseOutcome, Study};

/// The case in words.
pub fn case_title(case: Case) -> &'static str {
    match (case.truth, case.output) {
        (TruthModel::Euler, AccelerometerOutput::Sample) => "Euler-integrated truth, point samples",
        (TruthModel::Analytic, AccelerometerOutput::Sample) => "closed-form truth, point samples",
        (TruthModel::Analytic, AccelerometerOutput::IntervalMean) => {
            "closed-form truth, interval means"
        }
        (TruthModel::Euler, AccelerometerOutput::IntervalMean) => {
            "Euler-integrated truth, interval means"
        }
    }
}

/// "A", "B", "C", … for the case at `index`.
pub fn letter(index: usize) -> String {
    char::from(b'A' + (index % 26) as u8).to_string()
}

/// "case B (closed-form truth, point samples)".
pub(crate) fn named(study: &Study, o: &CaseOutcome) -> String {
    let i = study
        .cases
        .iter()
        .position(|c| c.case == o.case)
        .expect("a case of the study");
    format!("case {} ({})", letter(i), case_title(o.case))
}

/// What a failed check means, in one or two sentences.
pub fn failure_sentence(c: &Check, fix_times_s: &[f64]) -> String {
    let at = c
        .worst
        .map_or_else(String::new, |w| w.member.describe(fix_times_s));
    let words = FailureWords {
        outside: format!(
            "{} of {} members",
            count(c.failures as u64),
            count(c.members as u64)
        ),
        band: format!("[{}, {}]", sig(c.lower, 4), sig(c.upper, 4)),
        at,
    };
    (c.definition.failure)(c, &words)
}

pub(crate) fn failed_list(o: &CaseOutcome) -> String {
    let titles: Vec<String> = o
        .verdicts
        .failed()
        .map(|c| c.definition.title.to_string())
        .collect();
    and_list(&titles)
}

pub(crate) fn untestable_list(o: &CaseOutcome) -> Vec<&'static str> {
    o.verdicts
        .checks
        .iter()
        .filter(|c| matches!(c.verdict, Verdict::Untestable(_)))
        .map(|c| c.definition.title)
        .collect()
}

/// "a, b and c".
pub fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// "0.098 m, 0.0069 m/s and 4.7 × 10⁻⁴ m/s²".
pub(crate) fn per_state(x: [f64; ErrorState::DIM]) -> String {
    and_list(
        &ErrorState::VARIABLES
            .iter()
            .zip(x)
            .map(|(v, x)| format!("{} {}", sig(x, 2), v.unit))
            .collect::<Vec<_>>(),
    )
}

/// The share of each of `checks` checks, in words: "0.14 %".
pub fn share_words(alpha: f64, checks: usize) -> String {
    percent(alpha / checks as f64)
}

/// A count as a sentence writes it: in words up to twelve ("seven"), in figures above.
pub fn count_words(n: usize) -> String {
    const WORDS: [&str; 13] = [
        "zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
        "eleven", "twelve",
    ];
    WORDS
        .get(n)
        .map_or_else(|| count(n as u64), |w| (*w).to_string())
}

#[cfg(test)]
mod tests {
    use super::count_words;

    #[test]
    fn small_counts_in_words_larger_in_figures() {
        assert_eq!(count_words(0), "zero");
        assert_eq!(count_words(7), "seven");
        assert_eq!(count_words(12), "twelve");
        assert_eq!(count_words(13), crate::format::count(13));
    }
}
