//! The section "A real drive": the shipped minute of comma2k19 calibrated as a user would, with
//! the noise statistics estimated from the drive.

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::kind::{Built, Context, SectionKind, SectionView};
use super::outline::{Figure, Label, Numbers, Table};

use super::view::FigureView;
use super::{RenderError, ReportInput, rich};
use crate::calibrate::robust;
use crate::format::{fixed, interval, sig};
use crate::likelihood::KeyEstimate;
use crate::plot;
use crate::stats::normal_bound;
use crate::study::drive::{Axis, DRIVE_DIR, DriveRun};

/// One run's row of the section's table.
#[derive(Clone, Debug, Serialize)]
pub struct DriveRow {
    /// The accelerometer log and the filter's bias model, in words.
    pub run: String,
    /// The statistics estimated, each with its interval or what the drive leaves open, as HTML.
    pub estimates: Vec<String>,
    /// The bias at the end ± σ, m/s².
    pub bias: String,
    /// Its 95 % interval, the ends with the digits that tell them apart.
    pub bias_interval: String,
    /// When a test rejects the model that interval rests on: which, and the interval from the
    /// innovations' long-run variance; empty otherwise.
    pub conditional: String,
    /// The smoothed bias at the start ± σ.
    pub bias_start: String,
    /// The NIS sum against its band.
    pub nis: String,
    /// `pass` or `fail`.
    pub verdict: String,
    /// The innovations' whiteness per measurement, in words.
    pub whiteness: Vec<String>,
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct RealDriveView {
    /// The table's number.
    pub table_number: usize,
    /// Where the files are shipped.
    pub dir: String,
    /// Samples, fixes and duration of the drive, in words.
    pub extent: String,
    /// The runs.
    pub rows: Vec<DriveRow>,
    /// The figures: the bias of the gravity-compensated run with W, and of the raw run with a
    /// random walk.
    pub figures: Vec<FigureView>,
    /// What the numbers say, as HTML paragraphs' text.
    pub findings_html: Vec<String>,
}

/// A statistic's estimate as HTML: named, with the shared words (its value and interval, or the
/// one bound a drive that does not determine it gives).
fn named_estimate(k: &KeyEstimate) -> String {
    let words = super::estimate::estimate_words(k);
    rich::rich(&if k.identifiable {
        format!("{} = {words}", super::estimate::symbol(k.key))
    } else {
        words
    })
}

fn run_words(r: &DriveRun) -> String {
    let axis = match r.axis {
        Axis::GravityCompensated => "gravity-compensated",
        Axis::Raw => "raw",
    };
    format!(
        "{axis} axis, {} bias",
        r.noise.stats.bias_model.name().replace('_', " ")
    )
}

fn row(r: &DriveRun) -> DriveRow {
    let s = &r.calibration.summary;
    let b = (s.bias_m_s2, s.bias_sigma_m_s2);
    let start = &s.start_smoothed;
    DriveRow {
        run: run_words(r),
        estimates: r.noise.keys.iter().map(named_estimate).collect(),
        bias: format!("{} ± {}", sig(b.0, 3), sig(b.1, 2)),
        bias_interval: {
            let h = normal_bound(1.0 - robust::CONFIDENCE) * b.1;
            let (_, lo, hi) = interval(b.0, b.0 - h, b.0 + h, 3);
            format!("[{lo}, {hi}]")
        },
        conditional: if s.intervals_conditional {
            let r = &s.bias_robust;
            let (_, lo, hi) = interval(r.value, r.lower, r.upper, 3);
            format!(
                "{}; without white innovations [{lo}, {hi}]",
                robust::conditional_page_words(&s.rejected_by)
            )
        } else {
            String::new()
        },
        bias_start: format!(
            "{} ± {}",
            sig(start.bias_m_s2, 3),
            sig(start.sigma_bias_m_s2, 2)
        ),
        nis: format!(
            "{} in [{}, {}]",
            fixed(s.nis.sum, 0),
            fixed(s.nis.lower, 0),
            fixed(s.nis.upper, 0)
        ),
        verdict: s.nis.verdict.to_string(),
        whiteness: s
            .diagnostics
            .measurements
            .iter()
            .map(|m| format!("{}: {}", m.measurement, m.whiteness.verdict))
            .collect(),
    }
}

/// When the bias's interval rests on a model the data reject: which tests reject it, and where
/// the interval from the innovations' long-run variance lies against zero.
fn robust_sign(s: &crate::calibrate::summary::Summary) -> String {
    if !s.intervals_conditional {
        return String::new();
    }
    let r = &s.bias_robust;
    let (_, lo, hi) = interval(r.value, r.lower, r.upper, 3);
    let place = if r.upper < 0.0 {
        "lies below zero too"
    } else if r.lower > 0.0 {
        "lies above zero too"
    } else {
        "holds zero"
    };
    format!(
        "; but that interval {}, and the one from the innovations' long-run variance, \
         [{lo}, {hi}] m/s², {place}",
        robust::conditional_page_words(&s.rejected_by)
    )
}

/// The sentences the numbers decide.
pub fn findings(runs: &[DriveRun]) -> Vec<String> {
    let mut out = Vec::new();
    let passes = |r: &DriveRun| r.calibration.summary.nis.verdict == "pass";
    let w_run = runs
        .iter()
        .find(|r| r.axis == Axis::GravityCompensated && r.noise.keys.len() == 3);
    let sigma_run = runs
        .iter()
        .find(|r| r.axis == Axis::GravityCompensated && r.noise.keys.len() == 2);
    if let (Some(w), Some(g)) = (w_run, sigma_run) {
        let wk = &w.noise.keys[2];
        let gs = &g.calibration.summary.nis;
        let sentence = match (passes(w), passes(g), wk.identifiable) {
            (true, false, true) => format!(
                "With only the GPS σ's estimated, the gravity-compensated axis fails the NIS test \
                 (sum {} {} its band [{}, {}]): the accelerometer's white noise is far above the \
                 configured 4·10⁻⁴ (m/s²)². Estimated with them, W = {} [{}, {}] (m/s²)², {}× \
                 the configured value (the engine's and the road's vibration), and the test \
                 passes.",
                fixed(gs.sum, 0),
                if gs.sum > gs.upper { "above" } else { "below" },
                fixed(gs.lower, 0),
                fixed(gs.upper, 0),
                sig(wk.value, 3),
                sig(wk.lower, 3),
                sig(wk.upper.unwrap_or(f64::NAN), 3),
                crate::format::count((wk.value / 4e-4).round() as u64)
            ),
            (true, true, _) => "The gravity-compensated axis passes the NIS test with the GPS \
                                σ's estimated alone, and with W estimated too."
                .to_string(),
            _ => format!(
                "The gravity-compensated axis does not pass the NIS test with the estimated \
                 statistics (W {}): the filter's model does not explain this drive.",
                if wk.identifiable {
                    "identified"
                } else {
                    "not identified"
                }
            ),
        };
        out.push(sentence);
        let s = &w.calibration.summary;
        let (b, sb) = (s.bias_m_s2, s.bias_sigma_m_s2);
        let sign = if b + 1.96 * sb < 0.0 {
            "negative: its 95 % interval lies below zero"
        } else if b - 1.96 * sb > 0.0 {
            "positive: its 95 % interval lies above zero"
        } else {
            "not distinguishable from zero: its 95 % interval holds zero"
        };
        out.push(format!(
            "The bias of that run is {} ± {} m/s², {sign}{}.",
            sig(b, 3),
            sig(sb, 2),
            robust_sign(s)
        ));
    }
    if let Some(rw) = runs
        .iter()
        .find(|r| r.axis == Axis::Raw && r.noise.keys.len() == 4)
    {
        out.push(raw_drift(rw));
    }
    out
}

/// The section's view of `runs`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn view(runs: &[DriveRun], numbers: &Numbers) -> Result<RealDriveView, RenderError> {
    let first = &runs[0].calibration.summary;
    let mut figures = Vec::new();
    let shown = [
        (
            Figure::RealDriveGravityCompensated,
            1usize,
            "real-drive-gravcomp",
        ),
        (Figure::RealDriveRaw, 3usize, "real-drive-raw"),
    ];
    for (fig, i, id) in shown {
        let Some(r) = runs.get(i) else { continue };
        figures.push(figure(
            id,
            numbers.figure(fig),
            &format!("Bias estimate, {}", run_words(r)),
            &format!(
                "The bias of the {} filtered and smoothed at every fix with ±1σ (top) and the two \
                 σ (bottom), with the statistics estimated from the drive.",
                run_words(r)
            ),
            plot::calibration_bias(&r.calibration.fixes),
        )?);
    }
    Ok(RealDriveView {
        table_number: numbers.table(Table::RealDrive),
        dir: DRIVE_DIR.to_string(),
        extent: format!(
            "{} accelerometer samples and {} GPS fixes over {} s",
            first.samples,
            first.fixes,
            fixed(first.duration_s, 1)
        ),
        rows: runs.iter().map(row).collect(),
        figures,
        findings_html: findings(runs).iter().map(|s| rich::rich(s)).collect(),
    })
}

/// The raw axis's random walk in words: whether the drive measures K, and how far the
/// smoothed bias moves.
fn raw_drift(rw: &DriveRun) -> String {
    let k = &rw.noise.keys[3];
    let s = &rw.calibration.summary;
    let moved = (s.bias_m_s2 - s.start_smoothed.bias_m_s2).abs();
    if k.identifiable {
        format!(
            "On the raw axis the bias is not constant: with a random walk the drive measures \
             K = {} [{}, {}] m/s²/√s, and the smoothed bias moves by {} m/s² over the minute \
             ({} σ of its end value): gravity's share of the axis follows the pitch.",
            sig(k.value, 3),
            sig(k.lower, 3),
            sig(k.upper.unwrap_or(f64::NAN), 3),
            sig(moved, 2),
            fixed(moved / s.bias_sigma_m_s2, 1)
        )
    } else {
        "On the raw axis the drive does not determine a random walk of the bias (K not \
         identifiable)."
            .to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sentences_follow_the_numbers() {
        let runs = crate::study::drive::run().expect("the shipped drive calibrates");
        let said = findings(&runs);
        assert!(said[0].contains("fails the NIS test") && said[0].contains("passes"));
        assert!(said[1].contains("negative"));
        assert!(said[2].contains("measures K"));
        // Flipped numbers flip the words: the GPS-only run passing, the bias's sign, K open.
        let mut flipped = runs.clone();
        flipped[0].calibration.summary.nis.verdict = "pass";
        let s = &mut flipped[1].calibration.summary;
        s.bias_m_s2 = -s.bias_m_s2;
        flipped[3].noise.keys[3].identifiable = false;
        let said = findings(&flipped);
        assert!(
            said[0].contains("with the GPS σ's estimated alone"),
            "{}",
            said[0]
        );
        assert!(said[1].contains("positive"), "{}", said[1]);
        assert!(said[2].contains("does not determine"), "{}", said[2]);
        flipped[1].calibration.summary.nis.verdict = "fail";
        assert!(findings(&flipped)[0].contains("does not pass"));
    }
}

/// The section "A real drive", when the study calibrated it.
pub struct RealDrive;

impl SectionKind for RealDrive {
    fn key(&self) -> &'static str {
        "real_drive"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.study.real_drive.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Table(Table::RealDrive),
            Label::Figure(Figure::RealDriveGravityCompensated),
            Label::Figure(Figure::RealDriveRaw),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let runs = ctx.study().real_drive.as_ref()?;
        Some(view(runs, ctx.numbers).map(|v| Box::new(v) as Box<dyn SectionView>))
    }
}

#[derive(Template)]
#[template(path = "sections/real_drive.html")]
struct RealDriveHtml<'a> {
    d: &'a RealDriveView,
}

crate::section_view!(RealDriveView, RealDriveHtml { d }, anchor: |_| "real-drive".to_string(), title: |_| "A real drive".to_string());
