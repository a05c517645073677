//! The report's conclusions, one paragraph each, chosen from the verdicts and numbers; none is
//! written for a result the run did not produce. Strings may hold `_{…}`/`^{…}` notation, which
//! [`super::rich::rich`] turns into sub- and superscripts. The text helpers are in
//! [`super::words`], the numbers the sentences quote in [`super::quantities`] and the abstract's
//! findings in [`super::findings`].

use super::quantities::{claimed_sigma, euler_velocity_drift, explained, whiteness_pairs};
use super::words::{failure_sentence, named};
use crate::checks::{CheckId, Verdict};
use crate::config::{AccelerometerOutput, TruthModel};
use crate::format::{count, fixed, percent, sig};
use crate::state::ErrorState;
use crate::study::{CaseOutcome, Study};

// The helpers other sections import from here.
pub use super::quantities::checks_run;
pub use super::words::{and_list, share_words};

/// The conclusions, one paragraph each.
/// `dynamics_eq` is the number of the error-dynamics equation, `accuracy_table` that of the
/// accuracy table.
pub fn conclusions(
    study: &Study,
    differences: &[String],
    dynamics_eq: usize,
    accuracy_table: usize,
) -> Vec<String> {
    let mut out = vec![bias_paragraph(study, accuracy_table)];
    out.extend(consistent_paragraph(study));
    for o in study.cases.iter().filter(|o| !o.verdicts.all_passed()) {
        out.push(failing_paragraph(study, o, dynamics_eq));
    }
    out.extend(user_paragraph(study));
    if !differences.is_empty() {
        out.push(format!(
            "This run's filter was deliberately given statistics that differ from the truth ({}); the checks above measure the consequences.",
            differences.join("; ")
        ));
    }
    out
}

/// The bias calibration, as achieved in the physically real consistent case if there is one.
fn bias_paragraph(study: &Study, accuracy_table: usize) -> String {
    let b = ErrorState::BIAS;
    let r = &study.realization;
    let last = r.fixes.last().expect("at least two fixes");
    let claimed = claimed_sigma(study);
    let prior = study.model.config.filter_bias_var_m2_s4().sqrt();
    let real = study
        .cases
        .iter()
        .find(|o| o.case.truth == TruthModel::Analytic && o.verdicts.all_passed());
    let bias_err = (last.post[b] - r.bias_m_s2) / last.sigma_post[b];
    match real {
        Some(o) => format!(
            "The calibration reaches a bias RMS error of {} m/s² after {} s over the {} realizations of {}, {} times smaller than the prior {} m/s², and the filter's own σ, {} m/s², matches it. In the recorded realization the estimate {} m/s² lies {} σ from the true {} m/s².",
            sig(o.achieved_rms_final()[b], 2),
            fixed(last.t_s, 1),
            count(o.run.stats.realizations),
            named(study, o),
            sig(prior / o.achieved_rms_final()[b], 2),
            sig(prior, 2),
            sig(claimed[b], 2),
            sig(last.post[b], 3),
            fixed(bias_err.abs(), 1),
            sig(r.bias_m_s2, 3),
        ),
        None => format!(
            "No physically real case is consistent in this run, so the filter's σ of {} m/s² for the bias after {} s is only its claim; the accuracy achieved is in Table {accuracy_table}.",
            sig(claimed[b], 2),
            fixed(last.t_s, 1),
        ),
    }
}

/// What the cases that pass every check show; `None` when none does.
fn consistent_paragraph(study: &Study) -> Option<String> {
    let consistent: Vec<&CaseOutcome> = study
        .cases
        .iter()
        .filter(|o| o.verdicts.all_passed())
        .collect();
    let first = consistent.first()?;
    let names: Vec<String> = consistent.iter().map(|o| named(study, o)).collect();
    let (subject, these) = if consistent.len() == 1 {
        (format!("With {}", names[0]), "this case")
    } else {
        (format!("With {}", and_list(&names)), "these cases")
    };
    Some(format!(
        "{subject}, every check passes over N = {} realizations each at a study-wide false-alarm rate of {}: the mean error is zero within its bounds, the ensemble variance matches P, errors are orthogonal to estimates, the residuals are white over {}, and NEES and NIS stay in their χ² bands. The filter is consistent with {these}.",
        count(first.run.stats.realizations),
        percent(first.verdicts.false_alarm_rate),
        whiteness_pairs(first),
    ))
}

/// What failed in case `o` and why; `dynamics_eq` is the error-dynamics equation's number.
fn failing_paragraph(study: &Study, o: &CaseOutcome, dynamics_eq: usize) -> String {
    let v = &o.verdicts;
    let passed = v.checks.iter().filter(|c| c.passed()).count();
    let fix_times_s: Vec<f64> = o.run.stats.fixes.iter().map(|f| f.time_s).collect();
    let mut s = format!(
        "With {}, {passed} of {} checks pass. ",
        named(study, o),
        v.checks.len()
    );
    let untestable: Vec<String> = v
        .checks
        .iter()
        .filter(|c| matches!(c.verdict, Verdict::Untestable(_)))
        .map(|c| {
            format!(
                "{} (needs N ≥ {})",
                c.definition.title,
                count(c.min_realizations)
            )
        })
        .collect();
    if !untestable.is_empty() {
        s.push_str(&format!(
            "At N = {} the {} checks are untestable, so they say nothing about this filter. ",
            count(o.run.stats.realizations),
            and_list(&untestable),
        ));
    }
    let sentences: Vec<String> = v
        .failed()
        .map(|c| failure_sentence(c, &fix_times_s))
        .collect();
    s.push_str(&sentences.join(" "));
    if o.case.output == AccelerometerOutput::Sample
        && o.case.truth == TruthModel::Analytic
        && v.get(CheckId::MEAN_ERROR).verdict == Verdict::Fail
        && explained(o)
    {
        s.push_str(&format!(
            " The cause is the assumption behind eq. ({dynamics_eq}): the point-sampled accelerometer's Euler integration lags the closed-form integral by a deterministic amount, about (Δt/2)·a(t) in velocity and up to Δt·A/2 = {} m/s, which the filter partly mistakes for bias. One noise-free pass of the filter predicts the mean error to within {} standard errors.",
            euler_velocity_drift(study),
            fixed(o.prediction.worst_se, 1)
        ));
    }
    s
}

/// What it means for a user, when the data shows it: point samples fail where interval means pass.
fn user_paragraph(study: &Study) -> Option<String> {
    let find = |output| {
        study
            .cases
            .iter()
            .find(|o| o.case.truth == TruthModel::Analytic && o.case.output == output)
    };
    let sample = find(AccelerometerOutput::Sample)?;
    let interval = find(AccelerometerOutput::IntervalMean)?;
    if sample.verdicts.all_passed() || !interval.verdicts.all_passed() {
        return None;
    }
    let v = ErrorState::VELOCITY;
    let ratio = sample.achieved_rms_final()[v] / claimed_sigma(study)[v];
    Some(format!(
        "For a user: an accelerometer that reports point samples, integrated by the Euler rule, leaves a velocity lag that the filter's model does not contain, and the filter's σ then understates the velocity error {} times. Either model the lag — the noise-free pass above computes it exactly and can be subtracted — or use an accelerometer's delta-velocity (interval-mean) output, with which every check passes and the claimed σ is the accuracy achieved.",
        fixed(ratio, 2)
    ))
}
