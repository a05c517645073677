//! The section "A real drive in three axes": the shipped comma2k19 minute as six raw IMU
//! channels and geodetic fixes, calibrated with no configuration and with noise statistics
//! estimated from the drive: its six biases (Android's own gyro estimate beside them), the
//! attitude against comma's pose, the NIS test and the whiteness with their diagnosis, and the
//! estimated statistics, in sentences chosen by the numbers (`real_drive_3d_words`).

use askama::Template;
use serde::Serialize;

use super::calibration_imu::{TestRow, interval_text, test_rows, with_sigma};
use super::calibration_imu_figures::{biases, nis};
use super::figures::figure;
use super::kind::{Built, Context, Record, SectionKind, SectionView};
use super::outline::{Figure, Label, Numbers, Table};
use super::real_drive_3d_words::{
    self as words, ANGLES, filtered_pairs, key_words, signed, within,
};
use super::view::FigureView;
use super::{RenderError, ReportInput, rich};
use crate::calibrate::imu::CONSUMER;
use crate::calibrate::imu::noise::ImuKey;
use crate::calibrate::imu::summary::Summary;
use crate::calibrate::imu::triad::{CONFIDENCE, Triad};
use crate::format::{count, fixed, percent, sig};
use crate::plot::calibration_imu::{EstimateSeries, imu_estimates};
use crate::study::drive3d::{DRIVE_DIR, RealDrive3d};

const BIASES: Table = Table::Named("real-drive-3d-biases");
const ATTITUDE: Table = Table::Named("real-drive-3d-attitude");
const TESTS: Table = Table::Named("real-drive-3d-tests");
const NOISE: Table = Table::Named("real-drive-3d-noise");
const ATTITUDE_FIGURE: Figure = Figure::Named("real-drive-3d-attitude");
const BIASES_FIGURE: Figure = Figure::Named("real-drive-3d-biases");
const NIS_FIGURE: Figure = Figure::Named("real-drive-3d-nis");

/// One bias in both runs: the estimate ± σ where the drive determines it, its interval always.
#[derive(Clone, Debug, Serialize)]
pub struct BiasRow {
    /// The bias, e.g. "gyro, x (rad/s)".
    pub quantity: String,
    /// With no configuration: `x ± σ`, or "not determined".
    pub plain: String,
    /// Its interval.
    pub plain_interval: String,
    /// Whether the drive determined it.
    pub plain_determined: bool,
    /// With the statistics estimated.
    pub estimated: String,
    /// Its interval.
    pub estimated_interval: String,
    /// Whether the drive determined it.
    pub estimated_determined: bool,
    /// Android's own estimate (gyros), empty for the accelerometers.
    pub android: String,
}

/// One angle at the end against comma's pose.
#[derive(Clone, Debug, Serialize)]
pub struct AngleRow {
    /// roll, pitch or yaw.
    pub angle: String,
    /// The filter's value ± σ, °.
    pub filter: String,
    /// comma's value, °.
    pub reference: String,
    /// Their difference, ° and in σ.
    pub difference: String,
    /// The fixes within ±1σ and ±2σ over the minute.
    pub within: String,
    /// Whether the drive determined it; `None` for roll and pitch, which gravity levels.
    pub determined: Option<bool>,
}

/// A test in both runs.
#[derive(Clone, Debug, Serialize)]
pub struct TestPair {
    /// The test, short: "NIS", "whiteness, position north".
    pub test: String,
    /// The test with no configuration.
    pub plain: TestRow,
    /// The test with the statistics estimated.
    pub estimated: TestRow,
}

/// A statistic searched by maximum likelihood.
#[derive(Clone, Debug, Serialize)]
pub struct KeyRow {
    /// Its name in `summary.json` and on the command line.
    pub key: String,
    /// What it is, with its unit.
    pub words: String,
    /// The consumer default it started from.
    pub start: String,
    /// Its estimate and interval, or what the drive leaves open.
    pub estimate: String,
    /// Whether the drive determined it.
    pub determined: bool,
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct RealDrive3dView {
    /// Where the files are shipped.
    pub dir: String,
    /// Rows, rate, fixes and span of the recording, in words.
    pub extent: String,
    /// The statistics searched, in words.
    pub keys_searched: String,
    /// The intervals' confidence, "95 %".
    pub confidence: String,
    /// Table numbers: biases, attitude, tests, noise.
    pub tables: [usize; 4],
    /// The six biases.
    pub biases: Vec<BiasRow>,
    /// Roll, pitch, yaw at the end.
    pub attitude: Vec<AngleRow>,
    /// The NIS test and each component's whiteness, both runs.
    pub tests: Vec<TestPair>,
    /// The statistics estimated.
    pub keys: Vec<KeyRow>,
    /// The six biases over the minute.
    pub biases_figure: FigureView,
    /// The attitude against comma's pose.
    pub attitude_figure: FigureView,
    /// The NIS per fix.
    pub nis_figure: FigureView,
    /// The sentences on the biases, as HTML.
    pub bias_html: Vec<String>,
    /// On the attitude.
    pub attitude_html: Vec<String>,
    /// On the tests (already HTML).
    pub tests_html: Vec<String>,
    /// On the estimated statistics.
    pub noise_html: Vec<String>,
}

/// `x ± σ unit` where the drive determined it, "not determined" otherwise; and the interval.
fn estimate_cells(t: &Triad, i: usize, unit: &str) -> (String, String) {
    let interval = interval_text(t.value[i], t.lower[i], t.upper[i], unit);
    if t.identifiable[i] {
        (with_sigma(t.value[i], t.sigma[i], unit), interval)
    } else {
        ("not determined".to_string(), interval)
    }
}

fn bias_rows(d: &RealDrive3d) -> Vec<BiasRow> {
    let (p, e) = (&d.plain.summary, &d.estimated.summary);
    let mut out = Vec::new();
    for (what, unit, tp, te) in [
        ("gyro", "rad/s", &p.gyro_bias_rad_s, &e.gyro_bias_rad_s),
        (
            "accelerometer",
            "m/s²",
            &p.accel_bias_m_s2,
            &e.accel_bias_m_s2,
        ),
    ] {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let (plain, plain_interval) = estimate_cells(tp, i, unit);
            let (estimated, estimated_interval) = estimate_cells(te, i, unit);
            out.push(BiasRow {
                quantity: format!("{what}, {axis}"),
                plain,
                plain_interval,
                plain_determined: tp.identifiable[i],
                estimated,
                estimated_interval,
                estimated_determined: te.identifiable[i],
                android: if what == "gyro" {
                    format!("{} {unit}", sig(d.android_gyro_bias_rad_s[i], 4))
                } else {
                    String::new()
                },
            });
        }
    }
    out
}

fn attitude_rows(d: &RealDrive3d) -> Vec<AngleRow> {
    let a = &d.plain.attitude;
    let s = &d.plain.summary.attitude_deg;
    let end = a.filtered.last().copied().unwrap_or([f64::NAN; 3]);
    let end_sigma = a.filtered_sigma.last().copied().unwrap_or([f64::NAN; 3]);
    let value = [s.roll, s.pitch, s.yaw];
    let sigma = [s.sigma_roll, s.sigma_pitch, s.sigma_yaw];
    (0..3)
        .map(|k| AngleRow {
            angle: ANGLES[k].to_string(),
            filter: with_sigma(value[k], sigma[k], "°"),
            reference: format!("{}°", fixed(a.reference_end_deg[k], 2)),
            difference: format!(
                "{}° ({} σ)",
                signed(end[k], 2),
                fixed(end[k].abs() / end_sigma[k], 1)
            ),
            within: format!(
                "{} / {}",
                percent(within(filtered_pairs(a, k), 1.0)),
                percent(within(filtered_pairs(a, k), 2.0))
            ),
            determined: (k == 2).then_some(s.yaw_identifiable),
        })
        .collect()
}

fn key_rows(e: &Summary) -> Vec<KeyRow> {
    let Some(est) = &e.noise_estimate else {
        return Vec::new();
    };
    est.keys
        .iter()
        .map(|k| {
            let key = ImuKey::parse(k.key);
            KeyRow {
                key: k.key.to_string(),
                words: key.map_or(String::new(), |key| key.words().to_string()),
                start: key.map_or(String::new(), |key| sig(key.get(&CONSUMER), 3)),
                estimate: key_words(k),
                determined: k.identifiable,
            }
        })
        .collect()
}

/// The filtered and smoothed attitude minus comma's pose, ±σ.
fn attitude_figure(d: &RealDrive3d, number: usize) -> Result<FigureView, RenderError> {
    let a = &d.plain.attitude;
    let col = |v: &[[f64; 3]], k: usize| v.iter().map(|x| x[k]).collect::<Vec<_>>();
    let names = ["Roll", "Pitch", "Yaw"];
    let series: Vec<EstimateSeries> = (0..3)
        .map(|k| EstimateSeries {
            title: format!("{} − comma's {}", names[k], ANGLES[k]),
            name: ["Δroll", "Δpitch", "Δyaw"][k],
            unit: "°",
            t_s: &a.t_s,
            filtered: col(&a.filtered, k),
            filtered_sigma: col(&a.filtered_sigma, k),
            smoothed: col(&a.smoothed, k),
            smoothed_sigma: col(&a.smoothed_sigma, k),
        })
        .collect();
    figure(
        "fig-real-drive-3d-attitude",
        number,
        "The attitude against comma's pose",
        &format!(
            "Roll, pitch and yaw of the IMU's body axes with no configuration minus comma's pose (linear between its samples) at each of the {} fixes the pose spans, filtered and smoothed, each with the filter's ±1σ. A consistent filter with an independent reference would hold about {} of the differences within ±1σ.",
            count(a.t_s.len() as u64),
            percent(words::normal_within(1.0))
        ),
        imu_estimates(&series),
    )
}

/// The section's view of `d`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn view(d: &RealDrive3d, numbers: &Numbers) -> Result<RealDrive3dView, RenderError> {
    let (p, e) = (&d.plain.summary, &d.estimated.summary);
    let c = &d.plain.calibrated;
    let t: Vec<f64> = c.records.iter().map(|f| f.t_s).collect();
    // test_rows' order: the NIS test, then each component's whiteness.
    let names = std::iter::once("NIS".to_string()).chain(
        p.whiteness
            .iter()
            .map(|w| format!("whiteness, {}", w.component.replace('_', " "))),
    );
    let tests = names
        .zip(test_rows(p).into_iter().zip(test_rows(e)))
        .map(|(test, (plain, estimated))| TestPair {
            test,
            plain,
            estimated,
        })
        .collect();
    let html = |v: Vec<String>| v.iter().map(|s| rich::rich(s)).collect();
    Ok(RealDrive3dView {
        dir: DRIVE_DIR.to_string(),
        extent: format!(
            "{} IMU rows at {} Hz and {} fixes; the filter starts at the alignment's fix, {} s \
             in, and uses the {} after it",
            count(p.imu_rows),
            sig(p.imu_rate_hz, 6),
            count(p.fixes as u64),
            sig(p.alignment.t_s, 3),
            count(p.fixes_used as u64)
        ),
        keys_searched: e
            .noise_estimate
            .as_ref()
            .map_or(String::new(), |n| words::keys_searched(&n.keys)),
        confidence: percent(CONFIDENCE),
        tables: [BIASES, ATTITUDE, TESTS, NOISE].map(|t| numbers.table(t)),
        biases: bias_rows(d),
        attitude: attitude_rows(d),
        tests,
        keys: key_rows(e),
        biases_figure: biases(
            c,
            &d.plain.smoothed,
            &t,
            ("fig-real-drive-3d-biases", numbers.figure(BIASES_FIGURE)),
        )?,
        attitude_figure: attitude_figure(d, numbers.figure(ATTITUDE_FIGURE))?,
        nis_figure: nis(
            c,
            p,
            &t,
            ("fig-real-drive-3d-nis", numbers.figure(NIS_FIGURE)),
        )?,
        bias_html: html(words::bias_findings(d)),
        attitude_html: html(words::attitude_findings(&d.plain)),
        tests_html: words::test_findings(p),
        noise_html: html(words::noise_findings(d)),
    })
}

/// One run's numbers in data.json: the summary, and the attitude's difference from comma's
/// pose at the end with the fractions of fixes within ±1σ and ±2σ.
#[derive(Serialize)]
pub struct RunRecord<'a> {
    /// `summary.json` of the run.
    pub summary: &'a Summary,
    /// Roll, pitch, yaw minus comma's at the end, °.
    pub attitude_difference_end_deg: [f64; 3],
    /// Their σ's, °.
    pub attitude_sigma_end_deg: [f64; 3],
    /// Fixes whose filtered difference is within ±1σ, per angle.
    pub within_1_sigma: [f64; 3],
    /// Within ±2σ.
    pub within_2_sigma: [f64; 3],
}

/// data.json's `real_drive_3d`.
#[derive(Serialize)]
pub struct RealDrive3dRecord<'a> {
    /// Android's own gyro bias estimate, rad/s.
    pub android_gyro_bias_rad_s: [f64; 3],
    /// The intervals' confidence.
    pub confidence: f64,
    /// With no configuration.
    pub no_configuration: RunRecord<'a>,
    /// With the statistics estimated.
    pub noise_estimated: RunRecord<'a>,
}

fn run_record(r: &crate::study::drive3d::Run3d) -> RunRecord<'_> {
    let a = &r.attitude;
    RunRecord {
        summary: &r.summary,
        attitude_difference_end_deg: a.filtered.last().copied().unwrap_or([f64::NAN; 3]),
        attitude_sigma_end_deg: a.filtered_sigma.last().copied().unwrap_or([f64::NAN; 3]),
        within_1_sigma: [0, 1, 2].map(|k| within(filtered_pairs(a, k), 1.0)),
        within_2_sigma: [0, 1, 2].map(|k| within(filtered_pairs(a, k), 2.0)),
    }
}

/// The section, when the study calibrated the minute in three axes.
pub struct RealDrive3dSection;

impl SectionKind for RealDrive3dSection {
    fn key(&self) -> &'static str {
        "real_drive_3d"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.study.real_drive_3d.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Table(BIASES),
            Label::Figure(BIASES_FIGURE),
            Label::Table(ATTITUDE),
            Label::Figure(ATTITUDE_FIGURE),
            Label::Table(TESTS),
            Label::Figure(NIS_FIGURE),
            Label::Table(NOISE),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let d = ctx.study().real_drive_3d.as_ref()?;
        Some(view(d, ctx.numbers).map(|v| Box::new(v) as Box<dyn SectionView>))
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let d = input.study.real_drive_3d.as_ref()?;
        Some((
            "real_drive_3d",
            Box::new(RealDrive3dRecord {
                android_gyro_bias_rad_s: d.android_gyro_bias_rad_s,
                confidence: CONFIDENCE,
                no_configuration: run_record(&d.plain),
                noise_estimated: run_record(&d.estimated),
            }),
        ))
    }
}

#[derive(Template)]
#[template(path = "sections/real_drive_3d.html")]
struct RealDrive3dHtml<'a> {
    d: &'a RealDrive3dView,
}

crate::section_view!(RealDrive3dView, RealDrive3dHtml { d }, anchor: |_| "real-drive-3d".to_string(), title: |_| "A real drive in three axes".to_string());
