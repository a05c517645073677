//! The page of a three-axis calibration from a recording (`calibrate --imu --gnss`): the six
//! biases and the attitude at the end with σ, 95 % interval and whether the drive determined
//! them; the alignment; the NIS and whiteness tests with their verdicts; the sentences those
//! numbers choose; every assumption; five figures. On the report's base template, stylesheet
//! and math layer, self-contained. Pure: it returns the HTML and the caller writes it.

use askama::Template;
use serde::Serialize;

use super::view::FigureView;
use super::{RenderError, stylesheet};
use crate::calibrate::imu::noise::ImuKey;
use crate::calibrate::imu::run::Calibrated;
use crate::calibrate::imu::smoother::Smoothed;
use crate::calibrate::imu::summary::Summary;
use crate::calibrate::imu::triad::{CONFIDENCE, Triad};
use crate::calibrate::robust::conditional_page_words;
use crate::format::{count, fixed, interval, percent, short, sig};

/// A row of a two-column table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The quantity.
    pub quantity: String,
    /// Its value with its unit.
    pub value: String,
}

/// An estimate at the end: value ± σ, its interval and whether the drive determined it.
#[derive(Clone, Debug, Serialize)]
pub struct EstimateRow {
    /// Element id, e.g. `gyro-bias-z`.
    pub id: String,
    /// The quantity.
    pub quantity: String,
    /// `x ± σ unit`.
    pub value: String,
    /// The interval at [`CONFIDENCE`].
    pub interval: String,
    /// Whether the drive determined it; `None` for roll and pitch, which gravity levels.
    pub determined: Option<bool>,
}

/// A test's row: what it tests, its statistic against its band, its verdict.
#[derive(Clone, Debug, Serialize)]
pub struct TestRow {
    /// The test, in words.
    pub test: String,
    /// Its statistic.
    pub statistic: String,
    /// What a consistent filter gives.
    pub band: String,
    /// pass, fail or untestable (also the badge's CSS class).
    pub verdict: String,
}

/// Everything the page shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct ImuCalibrationView {
    /// The program's version.
    pub version: String,
    /// The recording in one line.
    pub subtitle: String,
    /// That the intervals assume a model the data reject; empty when no test rejects it.
    pub conditional: String,
    /// Sentences chosen by the numbers.
    pub findings: Vec<String>,
    /// The six biases at the end.
    pub biases: Vec<EstimateRow>,
    /// Roll, pitch and yaw at the end.
    pub attitude: Vec<EstimateRow>,
    /// The logs and the alignment.
    pub alignment: Vec<Row>,
    /// The NIS test and each component's whiteness.
    pub tests: Vec<TestRow>,
    /// The NIS test in words, as HTML.
    pub nis_html: String,
    /// What the χ² innovation gate did.
    pub gate: String,
    /// Every assumption.
    pub assumptions: Vec<super::calibration_imu_assumptions::AssumptionRow>,
    /// The five figures.
    pub figures: Vec<FigureView>,
    /// The command that wrote the page.
    pub command: String,
}

/// The page.
#[derive(Template)]
#[template(path = "calibration_imu.html")]
pub struct ImuCalibrationPage<'a> {
    /// The view.
    pub v: &'a ImuCalibrationView,
    /// The stylesheet.
    pub style: &'a str,
}

/// `x ± σ unit`: σ to two significant digits, `x` to the same decimal place.
pub(super) fn with_sigma(x: f64, s: f64, unit: &str) -> String {
    if !(x.is_finite() && s.is_finite() && s > 0.0) {
        return format!("{} {unit}", sig(x, 4));
    }
    let decimals = (1.0 - s.log10().floor()).max(0.0) as usize;
    format!("{} ± {} {unit}", fixed(x, decimals), fixed(s, decimals))
}

/// `[lo, hi] unit` with the digits that tell the ends apart.
pub(super) fn interval_text(x: f64, lo: f64, hi: f64, unit: &str) -> String {
    let (_, lo, hi) = interval(x, lo, hi, 2);
    format!("[{lo}, {hi}] {unit}")
}

fn triad_rows(t: &Triad, what: &str, key: &str, unit: &str) -> Vec<EstimateRow> {
    (0..3)
        .map(|i| {
            let axis = ["x", "y", "z"][i];
            EstimateRow {
                id: format!("{key}-{axis}"),
                quantity: format!("{what}, {axis}"),
                value: with_sigma(t.value[i], t.sigma[i], unit),
                interval: interval_text(t.value[i], t.lower[i], t.upper[i], unit),
                determined: Some(t.identifiable[i]),
            }
        })
        .collect()
}

/// Roll, pitch and yaw at the end. Only the yaw is judged (the summary's flag): gravity levels
/// roll and pitch from the alignment on, so the drive is not what determines them.
fn attitude_rows(s: &Summary) -> Vec<EstimateRow> {
    let a = &s.attitude_deg;
    let z = crate::stats::normal_bound(1.0 - CONFIDENCE);
    let row = |name: &str, x: f64, sd: f64, determined: Option<bool>| EstimateRow {
        id: name.to_string(),
        quantity: name.to_string(),
        value: with_sigma(x, sd, "°"),
        interval: interval_text(x, x - z * sd, x + z * sd, "°"),
        determined,
    };
    vec![
        row("roll", a.roll, a.sigma_roll, None),
        row("pitch", a.pitch, a.sigma_pitch, None),
        row("yaw", a.yaw, a.sigma_yaw, Some(a.yaw_identifiable)),
    ]
}

/// The logs and the alignment.
fn alignment_rows(s: &Summary) -> Vec<Row> {
    let a = &s.alignment;
    let layout = serde_json::to_value(s.imu_layout)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    let row = |q: &str, v: String| Row {
        quantity: q.to_string(),
        value: v,
    };
    vec![
        row("IMU log", s.imu_file.clone()),
        row(
            "IMU rows",
            format!(
                "{} at {} Hz (median step), {layout}",
                count(s.imu_rows),
                short(s.imu_rate_hz)
            ),
        ),
        row("GNSS log", s.gnss_file.clone()),
        row(
            "GNSS fixes",
            format!(
                "{} read, {} used by the filter (those after the alignment's)",
                count(s.fixes as u64),
                count(s.fixes_used as u64)
            ),
        ),
        row(
            "alignment window",
            format!(
                "{} s to {} s (the mean specific force over it gives roll and pitch)",
                short(a.window_start_s),
                short(a.t_s)
            ),
        ),
        row(
            "filter's start",
            format!(
                "t = {} s, the first fix at {} m/s or faster: {} m/s (its course gives the yaw)",
                short(a.t_s),
                short(s.assumptions.heading_speed_m_s),
                sig(a.speed_m_s, 3)
            ),
        ),
        row(
            "roll at the start",
            with_sigma(a.roll_deg, a.sigma_roll_deg, "°"),
        ),
        row(
            "pitch at the start",
            with_sigma(a.pitch_deg, a.sigma_pitch_deg, "°"),
        ),
        row(
            "yaw at the start",
            with_sigma(a.yaw_deg, a.sigma_yaw_deg, "°"),
        ),
    ]
}

/// The NIS test and each component's whiteness.
pub(super) fn test_rows(s: &Summary) -> Vec<TestRow> {
    let n = &s.nis;
    let mut rows = vec![TestRow {
        test: format!("NIS over the {} fixes", count(n.fixes as u64)),
        statistic: format!("Σ = {} (mean {})", sig(n.sum, 5), sig(n.mean, 3)),
        band: format!(
            "χ²({}): [{}, {}]",
            count(n.dof),
            sig(n.lower, 5),
            sig(n.upper, 5)
        ),
        verdict: n.verdict.to_string(),
    }];
    for w in &s.whiteness {
        let t = &w.test;
        rows.push(TestRow {
            test: format!(
                "whiteness of the {} innovations ({} fixes)",
                w.component.replace('_', " "),
                count(w.fixes as u64)
            ),
            statistic: format!(
                "ρ̂(1) = {}; {} of {} lags outside",
                t.autocorrelation.first().map_or("—".into(), |r| sig(*r, 3)),
                t.lags_outside.len(),
                t.max_lag
            ),
            band: format!(
                "|ρ̂(1)| ≤ {}",
                t.band.first().map_or("—".into(), |h| sig(*h, 2))
            ),
            verdict: t.verdict.to_string(),
        });
    }
    rows
}

/// The view of the calibration `c` with its summary `s` and the smoothed solution `smoothed`;
/// `command` wrote it.
///
/// # Errors
/// [`RenderError::Figure`] when a figure cannot be drawn.
pub fn view<const N: usize>(
    c: &Calibrated<N>,
    s: &Summary,
    smoothed: &[Smoothed<N>],
    command: &str,
) -> Result<ImuCalibrationView, RenderError> {
    let end = c.records.last().map_or(c.start_s, |r| r.t_s);
    let elapsed = (end - c.start_s).max(0.0);
    let mut biases = triad_rows(&s.gyro_bias_rad_s, "gyro bias", "gyro-bias", "rad/s");
    biases.extend(triad_rows(
        &s.accel_bias_m_s2,
        "accelerometer bias",
        "accel-bias",
        "m/s²",
    ));
    if let (Some(g), Some(a)) = (&s.gyro_scale_factor_ppm, &s.accel_scale_factor_ppm) {
        biases.extend(triad_rows(g, "gyro scale factor", "gyro-scale", "ppm"));
        biases.extend(triad_rows(
            a,
            "accelerometer scale factor",
            "accel-scale",
            "ppm",
        ));
    }
    Ok(ImuCalibrationView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        subtitle: format!(
            "{} and {}: {} s of the drive from the alignment at {} s to the last fix, {} intervals",
            s.imu_file,
            s.gnss_file,
            sig(elapsed, 4),
            short(c.start_s),
            percent(CONFIDENCE)
        ),
        // The components as words: "the position north innovations' whiteness".
        conditional: conditional_page_words(&s.rejected_by).replace('_', " "),
        findings: super::calibration_imu_words::findings(s),
        biases,
        attitude: attitude_rows(s),
        alignment: alignment_rows(s),
        tests: test_rows(s),
        nis_html: super::calibration_imu_words::nis_words(s),
        gate: super::calibration_imu_words::gate_words(s),
        assumptions: super::calibration_imu_assumptions::rows(&s.assumptions, &estimated_fields(s)),
        figures: super::calibration_imu_figures::figures(c, s, smoothed)?,
        command: command.to_string(),
    })
}

/// The page of the calibration `c` (its summary `s`, its smoothed solution `smoothed`) as HTML;
/// `command` wrote it.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the template cannot be filled.
pub fn render<const N: usize>(
    c: &Calibrated<N>,
    s: &Summary,
    smoothed: &[Smoothed<N>],
    command: &str,
) -> Result<String, RenderError> {
    let v = view(c, s, smoothed, command)?;
    let style = stylesheet();
    Ok(ImuCalibrationPage {
        v: &v,
        style: &style,
    }
    .render()?)
}

/// The fields of the assumptions that `--estimate-noise` set.
fn estimated_fields(s: &Summary) -> Vec<&'static str> {
    s.noise_estimate.as_ref().map_or_else(Vec::new, |e| {
        e.keys
            .iter()
            .filter_map(|k| ImuKey::parse(k.key).map(ImuKey::field))
            .collect()
    })
}
