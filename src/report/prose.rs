//! The report's words that depend on the results: the abstract's findings, the conclusions, the
//! sentences on failed checks and the interpretation choices. Every sentence is chosen from the
//! verdicts and numbers; none is written for a result the run did not produce. Strings may hold
//! `_{…}`/`^{…}` notation, which [`super::rich::rich`] turns into sub- and superscripts.

use crate::checks::{Check, CheckId, FailureWords, Verdict};
use crate::config::{AccelerometerOutput, Case, TruthModel};
use crate::format::{count, fixed, percent, sig};
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
fn named(study: &Study, o: &CaseOutcome) -> String {
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

fn failed_list(o: &CaseOutcome) -> String {
    let titles: Vec<String> = o
        .verdicts
        .failed()
        .map(|c| c.definition.title.to_string())
        .collect();
    and_list(&titles)
}

fn untestable_list(o: &CaseOutcome) -> Vec<&'static str> {
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

/// The filter's a posteriori σ at the last fix, per state.
pub fn claimed_sigma(study: &Study) -> [f64; ErrorState::DIM] {
    let last = study.schedule.fixes.last().expect("at least two fixes");
    std::array::from_fn(|k| last.p_post[(k, k)].sqrt())
}

/// "0.098 m, 0.0069 m/s and 4.7 × 10⁻⁴ m/s²".
fn per_state(x: [f64; ErrorState::DIM]) -> String {
    and_list(
        &ErrorState::VARIABLES
            .iter()
            .zip(x)
            .map(|(v, x)| format!("{} {}", sig(x, 2), v.unit))
            .collect::<Vec<_>>(),
    )
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

/// The pairs of fixes the whiteness check tested, in words.
pub fn whiteness_pairs(o: &CaseOutcome) -> String {
    let pairs = count(o.verdicts.get(CheckId::RESIDUAL_WHITENESS).members as u64 / 4);
    match o.run.stats.residual_layout.max_lag() {
        None => format!("all {pairs} pairs of fixes"),
        Some(l) => format!("the {pairs} pairs of fixes at most {l} fixes apart"),
    }
}

/// Whether the prediction explains the case's mean error within the mean-error check's bound.
fn explained(o: &CaseOutcome) -> bool {
    o.prediction.worst_se <= o.verdicts.get(CheckId::MEAN_ERROR).upper
}

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

/// The velocity lag of the Euler (left Riemann) sum behind the integral of a(t): about
/// (Δt/2)·(a(t) − a(0)), so at most Δt·A/2 for this profile (a(0) = 0), m/s.
pub fn euler_velocity_drift(study: &Study) -> String {
    let c = &study.model.config;
    sig(
        0.5 * study.model.timeline.dt_s * c.profile.accel_amplitude_m_s2,
        2,
    )
}

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

/// The share of each of `checks` checks, in words: "0.14 %".
pub fn share_words(alpha: f64, checks: usize) -> String {
    percent(alpha / checks as f64)
}

/// The number of checks the study ran (every case runs the same catalogue).
pub fn checks_run(study: &Study) -> usize {
    study.cases.first().map_or(0, |o| o.verdicts.checks.len())
}
