//! The parameter table and the list of statistics the filter assumes differently from the truth.

use super::prose::{checks_run, share_words};
use super::rich::rich;
use super::view::ParamRow;
use crate::config::STATISTICS;
use crate::config::statistics::ParamRow as StatisticRow;
use crate::format::{count, fixed, percent, sig};
use crate::study::Study;

/// A row: quantity (with `_{…}` notation), value, unit, configuration field.
fn row(q: &str, v: String, u: &str, f: &str) -> ParamRow {
    ParamRow {
        quantity_html: rich(q),
        value: v,
        unit: u.to_string(),
        field: f.to_string(),
    }
}

/// The rows of the parameter table (truth and run settings).
pub fn params(study: &Study) -> Vec<ParamRow> {
    let mut rows = motion_and_accelerometer(study);
    rows.extend(gps_prior_and_run(study));
    rows
}

/// The rows of the acceleration profile and the accelerometer.
fn motion_and_accelerometer(study: &Study) -> Vec<ParamRow> {
    let c = &study.model.config;
    let mut rows = vec![
        row(
            "acceleration amplitude A",
            sig(c.profile.accel_amplitude_m_s2, 3),
            "m/s²",
            "profile.accel_amplitude_m_s2",
        ),
        row(
            "angular frequency ω",
            format!(
                "{} (period {} s)",
                sig(c.profile.accel_angular_freq_rad_s, 4),
                sig(
                    std::f64::consts::TAU / c.profile.accel_angular_freq_rad_s,
                    3
                )
            ),
            "rad/s",
            "profile.accel_angular_freq_rad_s",
        ),
        row(
            "duration",
            sig(c.profile.duration_s, 3),
            "s",
            "profile.duration_s",
        ),
        row(
            "accelerometer rate (Δt)",
            format!(
                "{} ({} s)",
                sig(c.accelerometer.sample_rate_hz, 3),
                sig(study.model.timeline.dt_s, 3)
            ),
            "Hz",
            "accelerometer.sample_rate_hz",
        ),
    ];
    rows.extend(statistic_rows(study, "accelerometer"));
    rows.extend([row(
        "accelerometer output",
        format!(
            "{} (the report runs both sample and interval_mean)",
            c.accelerometer.output
        ),
        "",
        "accelerometer.output",
    )]);
    rows
}

/// The rows of the GPS, the prior and the run.
fn gps_prior_and_run(study: &Study) -> Vec<ParamRow> {
    let c = &study.model.config;
    let mut rows = vec![row(
        "GPS rate",
        sig(c.gps.sample_rate_hz, 3),
        "Hz",
        "gps.sample_rate_hz",
    )];
    rows.extend(statistic_rows(study, "gps"));
    rows.extend([
        row(
            "initial position p(0)",
            format!(
                "N({}, {}²)",
                sig(c.initial.position_mean_m, 3),
                sig(c.initial.position_sigma_m, 3)
            ),
            "m",
            "initial.position_*",
        ),
        row(
            "initial velocity v(0)",
            format!(
                "N({}, {}²)",
                sig(c.initial.velocity_mean_m_s, 3),
                sig(c.initial.velocity_sigma_m_s, 3)
            ),
            "m/s",
            "initial.velocity_*",
        ),
    ]);
    rows.extend(statistic_rows(study, "initial"));
    rows.extend([
        row(
            "realizations per ensemble N",
            count(c.ensemble.realizations),
            "",
            "ensemble.realizations",
        ),
        row("seed", c.ensemble.seed.to_string(), "", "ensemble.seed"),
        row(
            "study-wide false-alarm rate α",
            format!(
                "{} ({} per check)",
                percent(c.checks.false_alarm_rate),
                share_words(c.checks.false_alarm_rate, checks_run(study))
            ),
            "",
            "checks.false_alarm_rate",
        ),
    ]);
    rows
}

/// The rows of the noise statistics of the truth's `section` that have one of their own (see
/// [`crate::config::statistics::ParamRow`]), in the table's order.
fn statistic_rows(study: &Study, section: &str) -> Vec<ParamRow> {
    let c = &study.model.config;
    STATISTICS
        .iter()
        .filter(|s| s.truth_section() == section)
        .filter_map(|s| match (s.param_row, c.truth_value(s)) {
            (StatisticRow::Own(quantity), Some(x)) => {
                Some(row(quantity, sig(x, 3), s.unit, s.truth_path))
            }
            _ => None,
        })
        .collect()
}

/// One sentence per statistic the filter assumes differently from the truth (a bias model's
/// parameters aside, which the bias model's own sentences give).
pub fn filter_differences(study: &Study) -> Vec<String> {
    let c = &study.model.config;
    STATISTICS
        .iter()
        .filter(|s| s.bias_model.is_none())
        .filter_map(|s| Some((s, c.truth_value(s)?, c.filter_value(s)?)))
        .filter(|(_, a, b)| a != b)
        .map(|(s, a, b)| {
            format!(
                "{}: the filter assumes {} {unit}, the truth has {} {unit}",
                s.words,
                sig(b, 3),
                sig(a, 3),
                unit = s.unit
            )
        })
        .collect()
}

/// The interpretation choices this run made.
pub fn choices(study: &Study, differences: &[String]) -> Vec<String> {
    let c = &study.model.config;
    let tl = &study.model.timeline;
    let mut choices = vec![
        format!(
            "The problem writes the acceleration both as 10 sin(2π·0.1·t) and as A sin(ωt) with ω = 0.1 rad/s. This run uses ω = {} rad/s (a {} s period); the field profile.accel_angular_freq_rad_s selects the other reading.",
            sig(c.profile.accel_angular_freq_rad_s, 4),
            sig(std::f64::consts::TAU / c.profile.accel_angular_freq_rad_s, 3)
        ),
        format!(
            "The accelerometer is sampled at t = jΔt for j = 0 … {}; each sample drives the integration step that starts at its time (left end point). With point samples it reports a(t_{{j}}) + b + w(t_{{j}}), as the problem states; with interval means it reports the mean of a(t) over [t_{{j}}, t_{{j}} + Δt] + b + w(t_{{j}}), as a delta-velocity output does (field accelerometer.output). The report runs both.",
            count(tl.steps as u64 - 1)
        ),
        if c.gps.fix_at_start {
            "GPS fixes are taken at t = 0 and then every GPS period.".to_string()
        } else {
            format!(
                "The first GPS fix comes one GPS period after the start, at {} s; none is taken at t = 0.",
                fixed(tl.fix_time_s(0), 2)
            )
        },
        "The integration starts at the prior means of p(0) and v(0), so the error state has zero mean at t = 0 and the filter starts from δx̂(0) = 0, with the variances it assumes for p(0), v(0) and b on the diagonal of P(0).".to_string(),
        "Two truth models are simulated: the closed-form integral of a(t) (\"analytic\"), the physics the problem describes, and the accelerometer's deterministic input integrated with its own Euler formula (\"euler\"), the world in which the error dynamics are exact.".to_string(),
        format!(
            "The study-wide false-alarm rate α = {} is the probability that a consistent filter fails any check; each of the {} checks gets {} of it, split over its distinct members (Bonferroni at both levels).",
            percent(c.checks.false_alarm_rate),
            checks_run(study),
            share_words(c.checks.false_alarm_rate, checks_run(study))
        ),
    ];
    if !differences.is_empty() {
        choices.push(format!(
            "The filter assumes statistics that differ from the truth: {}.",
            differences.join("; ")
        ));
    }
    choices
}
