//! The page of a calibration from logs: a short report in the study's style — the bias with its
//! σ, how the logs were processed, four figures and the NIS test — self-contained like the
//! study's page. Pure: it returns the HTML and the caller writes it.

use askama::Template;
use serde::Serialize;

use super::RenderError;
use super::rich::rich;
use super::view::{FigureView, VerdictView};
use crate::calibrate::StepMode;
use crate::calibrate::summary::{Calibration, FilterRecord, Summary};
use crate::format::{count, percent, short, sig};

/// A row of a two-column table: the quantity (HTML) and its value.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The quantity, as HTML.
    pub quantity_html: String,
    /// Its value with its unit.
    pub value: String,
}

/// Everything the calibration page shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct CalibrationView {
    /// The program's version.
    pub version: String,
    /// The bias estimate with its σ and unit.
    pub bias: String,
    /// Its 95 % interval with the digits that show its width: "[−0.6137, −0.6126] m/s²".
    pub bias_interval: String,
    /// That the interval assumes a model the data reject, and which tests reject it; empty
    /// when none does.
    pub conditional: String,
    /// The bias with an interval that does not assume white innovations, in words; empty
    /// when no test rejects.
    pub robust: String,
    /// Time stamp of the last sample, s.
    pub end_time: String,
    /// The logs and their extent.
    pub logs: Vec<Row>,
    /// How the step and the fixes were handled, as HTML.
    pub method_html: Vec<String>,
    /// The estimates at the start and the end of the log.
    pub results: Vec<Row>,
    /// The NIS test in words, as HTML.
    pub nis_html: String,
    /// Pass or fail.
    pub nis_verdict: VerdictView,
    /// The filter's assumptions.
    pub settings: Vec<Row>,
    /// The four figures.
    pub figures: Vec<FigureView>,
    /// The diagnosis: Table 3, Figures 5 and 6.
    pub diagnosis: super::calibration_diagnosis::DiagnosisView,
    /// The noise statistics estimated from the drive with their profiles (Figure 7), as HTML;
    /// empty without `--estimate-noise`.
    pub noise_html: String,
    /// The command that wrote the page.
    pub command: String,
    /// What `estimates.csv` holds, in words.
    pub estimates_words: &'static str,
}

/// The calibration page.
#[derive(Template)]
#[template(path = "calibration.html")]
pub struct CalibrationPage<'a> {
    /// The view.
    pub v: &'a CalibrationView,
    /// The stylesheet.
    pub style: &'a str,
}

fn row(quantity: &str, value: String) -> Row {
    Row {
        quantity_html: rich(quantity),
        value,
    }
}

/// `x ± s unit` with σ to two significant digits and `x` to the same decimal place.
fn with_sigma(x: f64, s: f64, unit: &str) -> String {
    let digits = if s > 0.0 && x != 0.0 {
        (x.abs().log10().floor() - s.log10().floor()).max(0.0) as usize + 2
    } else {
        3
    };
    format!("{} ± {} {unit}", sig(x, digits.min(12)), sig(s, 2))
}

/// The bias's interval at the printed line's confidence, its ends with the digits of
/// [`crate::format::interval`].
fn bias_interval(s: &Summary) -> String {
    let z = crate::stats::normal_bound(1.0 - crate::calibrate::robust::CONFIDENCE);
    let (b, h) = (s.bias_m_s2, z * s.bias_sigma_m_s2);
    let (_, lo, hi) = crate::format::interval(b, b - h, b + h, 3);
    format!("[{lo}, {hi}] m/s²")
}

fn seconds(x: f64) -> String {
    if x.abs() < 1.0 && x != 0.0 {
        format!("{} ms", short(1e3 * x))
    } else {
        format!("{} s", short(x))
    }
}

/// `text` with the HTML special characters escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The filter's bias model in words with its parameter (plain text), when the bias drifts.
fn drift_words(f: &FilterRecord) -> Option<String> {
    match (
        f.bias_random_walk_m_s2_per_sqrt_s,
        f.bias_correlation_time_s,
    ) {
        (Some(k), _) => Some(format!(
            "random walk (random_walk), K = {} m/s² per √s",
            short(k)
        )),
        (_, Some(tau_b)) => Some(format!(
            "Gauss–Markov (gauss_markov), correlation time {}, stationary σ {} m/s²",
            seconds(tau_b),
            short(f.bias_var_m2_s4.sqrt())
        )),
        _ => None,
    }
}

/// How the smoother's bias reads: constant, or following the filter's bias model.
fn smoother_words(s: &Summary) -> String {
    match drift_words(&s.filter) {
        None => rich(
            "A fixed-interval Rauch–Tung–Striebel smoother runs backward over the fixes and gives \
             the smoothed δp, δv, b and their σ at every sample; the bias is constant, so its \
             smoothed estimate is the same at every time, and at the end of the log filtered and \
             smoothed agree.",
        ),
        Some(model) => format!(
            "The filter assumes a drifting bias, {}: Φ and Q of every step carry the bias's own \
             decay and process noise. {}",
            escape(&model),
            rich(
                "A fixed-interval Rauch–Tung–Striebel smoother runs backward over the fixes and \
                 gives the smoothed δp, δv, b and their σ at every sample; the smoothed bias \
                 follows its path through the log, and at the end of the log filtered and \
                 smoothed agree."
            )
        ),
    }
}

fn method(s: &Summary) -> Vec<String> {
    let mode = match s.dt_mode {
        StepMode::Nominal => format!(
            "Every step of the accelerometer log equals the configured Δt = {} to a relative \
             10^{{−9}}, so the filter ran with that constant Δt and the study's recursion, \
             operation for operation (Δt mode ",
            seconds(s.nominal_dt_s)
        ),
        StepMode::PerStep => format!(
            "The steps of the accelerometer log run from {} to {} (median {}), not all equal to \
             the configured Δt = {}: each step Δt_{{j}} was taken from its pair of time stamps, \
             with Φ(Δt_{{j}}) and Q(Δt_{{j}}) (Δt mode ",
            seconds(s.min_step_s),
            seconds(s.max_step_s),
            seconds(s.median_step_s),
            seconds(s.nominal_dt_s)
        ),
    };
    vec![
        rich(&format!(
            "The accelerometer output a_{{c}} is integrated by eq. (3) of the study from \
                 p_{{c}}(t_{{0}}) = {} m and v_{{c}}(t_{{0}}) = {} m/s (the configured prior \
                 means, or the first fix carried back to the first sample when the configuration \
                 gives none); the error-state filter propagates δx = (δp, δv, b) with Φ and Q, \
                 and at each GPS fix updates it with δz = z − (p_{{c}}, v_{{c}}).",
            crate::format::sig(s.filter.initial_position_mean_m, 4),
            crate::format::sig(s.filter.initial_velocity_mean_m_s, 4)
        )),
        format!("{}<code>{}</code>).", rich(&mode), s.dt_mode.name()),
        rich(&format!(
            "Steps between {} and {} (0.5 to 1.5 times the median step) are accepted; a longer \
             one is a gap and a shorter one an extra sample, and either refuses the log. Each \
             GPS fix is applied at its own time: between two samples the filter propagates over \
             the fraction of the step and updates there; a fix more than {} (half the median \
             step) outside the log's span is refused.",
            seconds(s.accepted_step_s[0]),
            seconds(s.accepted_step_s[1]),
            seconds(s.fix_tolerance_s)
        )),
        smoother_words(s),
    ]
}

/// Builds the view of `cal`; `command` wrote it, `estimates.csv` with a row per sample when
/// `every_sample`, else per fix.
///
/// # Errors
/// [`RenderError::Figure`] when a figure cannot be drawn.
pub fn build(
    cal: &Calibration,
    command: &str,
    every_sample: bool,
) -> Result<CalibrationView, RenderError> {
    let s = &cal.summary;
    Ok(CalibrationView {
        version: s.accelcal_version.to_string(),
        bias: with_sigma(s.bias_m_s2, s.bias_sigma_m_s2, "m/s²"),
        bias_interval: bias_interval(s),
        conditional: crate::calibrate::robust::conditional_page_words(&s.rejected_by),
        robust: if s.intervals_conditional {
            s.bias_robust.words(&s.rejected_by)
        } else {
            String::new()
        },
        end_time: short(s.end_s),
        logs: logs(s),
        method_html: method(s),
        results: results(s),
        nis_html: nis_words(s),
        // The NIS test's verdict is a word of summary.json; the page shows it as a verdict.
        nis_verdict: if s.nis.verdict == "pass" {
            VerdictView::Pass
        } else {
            VerdictView::Fail
        },
        settings: settings(s),
        figures: super::calibration_figures::figures(cal)?,
        diagnosis: super::calibration_diagnosis::build(cal, 3, 5)?,
        noise_html: match &s.noise_estimate {
            Some(e) => super::estimate::estimate_html(&e.0, 7)?,
            None => String::new(),
        },
        command: command.to_string(),
        estimates_words: if every_sample {
            "filtered and smoothed estimates at every sample"
        } else {
            "a priori, filtered and smoothed estimates, innovation and NIS at every GPS fix"
        },
    })
}

/// The logs and their extent.
fn logs(s: &Summary) -> Vec<Row> {
    vec![
        row("accelerometer log", s.accelerometer_log.clone()),
        row("GPS log", s.gps_log.clone()),
        row("samples", count(s.samples)),
        row("GPS fixes", count(s.fixes as u64)),
        row(
            "time span",
            format!(
                "{} s to {} s ({} s)",
                short(s.start_s),
                short(s.end_s),
                short(s.duration_s)
            ),
        ),
        row("median step", seconds(s.median_step_s)),
        row("Δt mode", s.dt_mode.name().to_string()),
    ]
}

/// The estimates at the start and the end of the log.
fn results(s: &Summary) -> Vec<Row> {
    let start = &s.start_smoothed;
    let mut rows = results_end_and_start(s);
    if s.filter.bias_model != "constant" {
        // A drifting bias has a start of its own.
        rows.insert(
            1,
            row(
                "bias b̂^{s} at the start (smoothed)",
                with_sigma(start.bias_m_s2, start.sigma_bias_m_s2, "m/s²"),
            ),
        );
    }
    rows
}

/// The end's estimates and the initial position and velocity.
fn results_end_and_start(s: &Summary) -> Vec<Row> {
    let start = &s.start_smoothed;
    let end = &s.end_estimate;
    let f = &s.filter;
    vec![
        row(
            "bias b̂ at the end",
            with_sigma(end.bias_m_s2, end.sigma_bias_m_s2, "m/s²"),
        ),
        row(
            "position error δp̂ at the end",
            with_sigma(end.dp_m, end.sigma_dp_m, "m"),
        ),
        row(
            "velocity error δv̂ at the end",
            with_sigma(end.dv_m_s, end.sigma_dv_m_s, "m/s"),
        ),
        row(
            "initial position p(t_{0}) = p_{c}(t_{0}) + δp̂^{s}",
            with_sigma(
                f.initial_position_mean_m + start.dp_m,
                start.sigma_dp_m,
                "m",
            ),
        ),
        row(
            "initial velocity v(t_{0}) = v_{c}(t_{0}) + δv̂^{s}",
            with_sigma(
                f.initial_velocity_mean_m_s + start.dv_m_s,
                start.sigma_dv_m_s,
                "m/s",
            ),
        ),
    ]
}

/// The NIS test in words, as HTML.
fn nis_words(s: &Summary) -> String {
    let n = &s.nis;
    rich(&format!(
        "The NIS of the {} fixes sum to {} (mean {}). For a consistent filter the sum is \
         χ²({}) and lies in [{}, {}] with probability 1 − α = {} (α/2 in each tail, \
         α = checks.false_alarm_rate): {}. {} of the fixes fall outside the per-fix band; \
         about {} would by chance. This is the only consistency check real data allows: it \
         needs no truth.",
        count(n.fixes as u64),
        sig(n.sum, 5),
        sig(n.mean, 4),
        count(n.dof),
        sig(n.lower, 5),
        sig(n.upper, 5),
        percent(1.0 - n.false_alarm_rate),
        if n.verdict == "pass" {
            "the sum is inside, the residuals are as large as the filter predicts"
        } else if n.sum > n.upper {
            "the sum is above the band, the residuals are larger than the filter predicts \
             (its noise statistics are too small, or the model misses something)"
        } else {
            "the sum is below the band, the residuals are smaller than the filter predicts \
             (its noise statistics are too large)"
        },
        count(n.outside_per_fix as u64),
        sig(n.expected_outside_per_fix, 2)
    ))
}

/// The filter's assumptions.
fn settings(s: &Summary) -> Vec<Row> {
    let f = &s.filter;
    let mut rows = vec![
        row(
            "p_{c}(t_{0}), mean of p(0)",
            format!("{} m", short(f.initial_position_mean_m)),
        ),
        row(
            "v_{c}(t_{0}), mean of v(0)",
            format!("{} m/s", short(f.initial_velocity_mean_m_s)),
        ),
        row(
            "σ of p(0)",
            format!("{} m", short(f.initial_position_sigma_m)),
        ),
        row(
            "σ of v(0)",
            format!("{} m/s", short(f.initial_velocity_sigma_m_s)),
        ),
        row(
            "σ of the bias prior",
            format!("{} m/s²", short(f.bias_var_m2_s4.sqrt())),
        ),
        row(
            "accelerometer noise variance W",
            format!("{} (m/s²)²", short(f.accel_noise_var_m2_s4)),
        ),
        row(
            "GPS position σ",
            format!("{} m", short(f.gps_position_sigma_m)),
        ),
        row(
            "GPS velocity σ",
            format!("{} m/s", short(f.gps_velocity_sigma_m_s)),
        ),
        row("configured Δt", seconds(s.nominal_dt_s)),
    ];
    if let Some(model) = drift_words(f) {
        rows.insert(
            5,
            Row {
                quantity_html: rich("bias model"),
                value: model,
            },
        );
    }
    rows
}

/// Renders the page of `cal` as HTML; `command` wrote it, `every_sample` as in [`build`].
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the template cannot be filled.
pub fn render(cal: &Calibration, command: &str, every_sample: bool) -> Result<String, RenderError> {
    let view = build(cal, command, every_sample)?;
    let style = include_str!("../../assets/report.css");
    Ok(CalibrationPage { v: &view, style }.render()?)
}
