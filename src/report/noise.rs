//! The section "Noise statistics from a drive": `calibrate --estimate-noise` on simulated drives
//! whose truth is known (the coverage of its intervals, its estimates against the truth, the
//! likelihood profile of one drive), and whether the white noise is identifiable on two drives.
//! The calibration page's part, a table of the estimates and their profiles, is
//! [`estimate_html`] (in [`super::estimate`]).

use askama::Template;
use serde::Serialize;

pub use super::estimate::{estimate_html, estimate_words, profile_series};
use super::estimate::{interval_words, search_words, symbol, with_unit};
use super::figures::figure;
use super::kind::{Built, Context, Record, SectionKind, SectionView};
use super::outline::{Figure, Label, Numbers, Table};

use super::view::{FigureView, VerdictView};
use super::words::and_list;
use super::{RenderError, ReportInput, rich};
use crate::format::{count, fixed, percent};
use crate::likelihood::Key;
use crate::plot::{self, RatioSeries};
use crate::study::identify::{WhiteNoiseDrive, WhiteNoiseDrives};
use crate::study::noise::{KeyCoverage, NOISE_FALSE_ALARM_RATE, NOISE_START_FACTOR, NoiseStudy};

/// One row of the coverage table.
#[derive(Clone, Debug, Serialize)]
pub struct CoverageRow {
    /// The statistic, as HTML.
    pub statistic_html: String,
    /// Its `[filter]` key.
    pub key: String,
    /// Its true value, with unit.
    pub truth: String,
    /// Drives on which it was identifiable, "200 of 200".
    pub identifiable: String,
    /// Intervals that covered the truth.
    pub covered: String,
    /// The binomial band of the covered count.
    pub band: String,
    /// Pass when the covered count lies in the band.
    pub verdict: VerdictView,
    /// Half-width intervals that covered the truth.
    pub half_width: String,
    /// Pass when the negative control's count lies in the band (it should fail).
    pub half_width_verdict: VerdictView,
    /// The median of estimate / truth.
    pub median_ratio: String,
}

fn coverage_row(c: &KeyCoverage) -> CoverageRow {
    let verdict = |ok: bool| {
        if ok {
            VerdictView::Pass
        } else {
            VerdictView::Fail
        }
    };
    CoverageRow {
        statistic_html: rich::rich(&symbol(c.key)),
        key: c.key.name().to_string(),
        truth: with_unit(c.truth, c.key),
        identifiable: count(c.identifiable),
        covered: count(c.covered),
        band: format!("[{}, {}]", count(c.band.0), count(c.band.1)),
        verdict: verdict(c.holds()),
        half_width: count(c.half_width_covered),
        half_width_verdict: verdict(c.half_width_holds()),
        median_ratio: fixed(c.median_ratio, 3),
    }
}

/// The sentences the coverage decides: whether each statistic's intervals cover at their
/// confidence, whether the negative control fails, and on how many drives each was measured.
pub fn coverage_words(n: &NoiseStudy) -> String {
    let names = |f: &dyn Fn(&KeyCoverage) -> bool| -> Vec<String> {
        n.coverage
            .iter()
            .filter(|c| f(c))
            .map(|c| symbol(c.key))
            .collect()
    };
    let conf = percent(crate::study::noise::NOISE_CONFIDENCE);
    let mut out = Vec::new();
    let holds = names(&|c| c.holds());
    if !holds.is_empty() {
        out.push(format!(
            "The {conf} intervals of {} cover the truth as often as their confidence says: each count lies in its binomial band at {}.",
            and_list(&holds),
            percent(NOISE_FALSE_ALARM_RATE)
        ));
    }
    for c in n.coverage.iter().filter(|c| !c.holds()) {
        let how = if c.covered < c.band.0 {
            "too rarely"
        } else {
            "too often"
        };
        out.push(format!(
            "The intervals of {} cover the truth {how}: {} of {}, outside the band [{}, {}]; they are not honest {conf} intervals.",
            symbol(c.key),
            count(c.covered),
            count(c.identifiable),
            count(c.band.0),
            count(c.band.1)
        ));
    }
    let (control_fails, control_holds) = (
        names(&|c| !c.half_width_holds()),
        names(&|c| c.half_width_holds()),
    );
    if !control_fails.is_empty() {
        out.push(format!(
            "Intervals of half the width fail the same test for {}: the test sees an interval of the wrong width.",
            and_list(&control_fails)
        ));
    }
    if !control_holds.is_empty() {
        out.push(format!(
            "Intervals of half the width of {} still fall in the band: at this number of drives the test cannot tell a wrong width for them.",
            and_list(&control_holds)
        ));
    }
    for c in n.coverage.iter().filter(|c| c.identifiable < n.drives) {
        out.push(format!(
            "{} was identifiable on {} of {} drives only.",
            symbol(c.key),
            count(c.identifiable),
            count(n.drives)
        ));
    }
    out.join(" ")
}

/// One drive of the identifiability table.
#[derive(Clone, Debug, Serialize)]
pub struct WhiteNoiseRow {
    /// The drive in words.
    pub drive: String,
    /// The true W.
    pub truth: String,
    /// GPS rate, Hz.
    pub gps_rate: String,
    /// Length, s.
    pub duration: String,
    /// What the drive says of W.
    pub estimate: String,
    /// The interval, an open end written 0 or ∞.
    pub interval: String,
    /// The search's range.
    pub search: String,
    /// Pass when identifiable, else untestable (its word is the CSS class).
    pub identifiable: VerdictView,
    /// "identifiable" or "not identifiable".
    pub identifiable_words: String,
}

fn white_noise_row(name: &str, d: &WhiteNoiseDrive) -> WhiteNoiseRow {
    let w = d.w();
    WhiteNoiseRow {
        drive: name.to_string(),
        truth: with_unit(d.truth_w_m2_s4, Key::AccelNoiseVar),
        gps_rate: fixed(d.gps_rate_hz, 0),
        duration: fixed(d.duration_s, 0),
        estimate: estimate_words(w),
        interval: interval_words(w),
        search: search_words(w),
        identifiable: if w.identifiable {
            VerdictView::Pass
        } else {
            VerdictView::Untestable
        },
        identifiable_words: if w.identifiable {
            "identifiable".to_string()
        } else {
            "not identifiable".to_string()
        },
    }
}

/// The sentence of one drive's W.
fn white_noise_sentence(name: &str, d: &WhiteNoiseDrive) -> String {
    let w = d.w();
    let drive = format!(
        "On {name} (W = {}, {} Hz GPS, {} s),",
        with_unit(d.truth_w_m2_s4, Key::AccelNoiseVar),
        fixed(d.gps_rate_hz, 0),
        fixed(d.duration_s, 0)
    );
    if w.identifiable {
        format!("{drive} W is identified: {}.", estimate_words(w))
    } else {
        format!(
            "{drive} W is {}; its profile runs to the search's bound, and the value where the search stopped, {}, is not a measurement.",
            estimate_words(w),
            with_unit(w.value, Key::AccelNoiseVar)
        )
    }
}

/// The paragraph the two drives decide.
pub fn white_noise_words(d: &WhiteNoiseDrives) -> String {
    let (q, v) = (d.quiet.w().identifiable, d.vibrating.w().identifiable);
    let closing = match (q, v) {
        (false, true) => {
            "Whether W can be measured depends on the drive, and the estimator says which: the same request gives a number with its interval on one drive and a bound on the other."
        }
        (true, true) => "Both drives measure W.",
        (false, false) => "Neither drive measures W: only bounds are known.",
        (true, false) => "The configured drive measures W; the vibrating one does not.",
    };
    format!(
        "{} {} {closing}",
        white_noise_sentence("the configured drive", &d.quiet),
        white_noise_sentence("a vibrating car", &d.vibrating)
    )
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct NoiseView {
    /// Drives simulated.
    pub drives: String,
    /// Length of each, s.
    pub duration_s: String,
    /// The truth's statistics, as HTML: "σ_p = 2.5 m, …".
    pub truth_html: String,
    /// How far from the truth the search starts.
    pub start_factor: String,
    /// The intervals' confidence.
    pub confidence: String,
    /// The coverage band's false-alarm rate.
    pub false_alarm: String,
    /// The coverage table's number.
    pub coverage_table: usize,
    /// Its rows.
    pub rows: Vec<CoverageRow>,
    /// The sentences the coverage decides, as HTML.
    pub coverage_html: String,
    /// Estimates against the truth.
    pub estimates: FigureView,
    /// The likelihood profile of one drive.
    pub profile: FigureView,
    /// The identifiability table's number, when the two drives were run.
    pub white_noise_table: Option<usize>,
    /// Its rows: the configured drive, the vibrating car.
    pub white_noise_rows: Vec<WhiteNoiseRow>,
    /// The paragraph they decide, as HTML.
    pub white_noise_html: String,
}

/// The figure of each drive's estimate / truth.
fn estimates_figure(n: &NoiseStudy, number: usize) -> Result<FigureView, RenderError> {
    let series: Vec<RatioSeries> = n
        .coverage
        .iter()
        .enumerate()
        .map(|(j, c)| RatioSeries {
            title: format!("{}, {}: estimate / truth", symbol(c.key), c.key.name()),
            drives: n
                .estimates
                .iter()
                .map(|e| &e.keys[j])
                .filter(|k| k.identifiable)
                .map(|k| {
                    let u = k.upper.unwrap_or(f64::INFINITY);
                    (k.value / c.truth, k.lower / c.truth, u / c.truth)
                })
                .collect(),
        })
        .collect();
    figure(
        "fig-noise-estimates",
        number,
        "Estimates of simulated drives against the truth",
        &format!(
            "Each identifiable drive's maximum-likelihood estimate over the truth (dot) with its {} profile-likelihood interval, the drives sorted by their estimate; blue intervals hold the truth, vermillion ones miss it. {} drives of {} s.",
            percent(crate::study::noise::NOISE_CONFIDENCE),
            count(n.drives),
            fixed(n.duration_s, 0)
        ),
        plot::estimate_ratios(&series),
    )
}

/// The section's view, its figures and tables numbered from `numbers`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn.
pub fn view(
    n: &NoiseStudy,
    white: Option<&WhiteNoiseDrives>,
    numbers: &Numbers,
) -> Result<NoiseView, RenderError> {
    let truths: Vec<f64> = n.coverage.iter().map(|c| c.truth).collect();
    // The study keeps a section only when some drive was calibrated (`Study::with_noise`).
    let drive = &n.estimates[0];
    let profile = figure(
        "fig-noise-profile",
        numbers.figure(Figure::NoiseProfile),
        "The likelihood profile of one drive",
        &format!(
            "For the first drive of the study, −2Δℓ against each statistic's value, every point the maximum of ℓ over the other statistics: the points the interval's search evaluated and three more on each side, inside the interval and beyond its end (dots), joined by straight lines. The interval is where the profile lies below the χ²₁ quantile {} ({} confidence); an end that reaches the search's bound is open. Green: the truth.",
            fixed(drive.deviance_threshold, 2),
            percent(drive.confidence)
        ),
        plot::likelihood_profile(
            &profile_series(drive, Some(&truths)),
            drive.deviance_threshold,
        ),
    )?;
    let truth_html = rich::rich(
        &n.coverage
            .iter()
            .map(|c| format!("{} = {}", symbol(c.key), with_unit(c.truth, c.key)))
            .collect::<Vec<_>>()
            .join(", "),
    );
    Ok(NoiseView {
        drives: count(n.drives),
        duration_s: fixed(n.duration_s, 0),
        truth_html,
        start_factor: fixed(NOISE_START_FACTOR, 0),
        confidence: percent(crate::study::noise::NOISE_CONFIDENCE),
        false_alarm: percent(NOISE_FALSE_ALARM_RATE),
        coverage_table: numbers.table(Table::NoiseCoverage),
        rows: n.coverage.iter().map(coverage_row).collect(),
        coverage_html: rich::rich(&coverage_words(n)),
        estimates: estimates_figure(n, numbers.figure(Figure::NoiseEstimates))?,
        profile,
        white_noise_table: white.map(|_| numbers.table(Table::WhiteNoise)),
        white_noise_rows: white
            .map(|d| {
                vec![
                    white_noise_row("configured", &d.quiet),
                    white_noise_row("vibrating car", &d.vibrating),
                ]
            })
            .unwrap_or_default(),
        white_noise_html: white.map_or_else(String::new, |d| rich::rich(&white_noise_words(d))),
    })
}

/// The section "Noise statistics from a drive", when the study ran it; instance 1 also shows
/// the white noise's identifiability on two drives, instance 0 does not.
pub struct Noise;

impl SectionKind for Noise {
    fn key(&self) -> &'static str {
        "noise"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        let study = input.study;
        study
            .noise
            .iter()
            .map(|_| usize::from(study.white_noise.is_some()))
            .collect()
    }
    fn labels(&self, white_noise: usize) -> Vec<Label> {
        let mut labels = vec![
            Label::Table(Table::NoiseCoverage),
            Label::Figure(Figure::NoiseEstimates),
            Label::Figure(Figure::NoiseProfile),
        ];
        if white_noise == 1 {
            labels.push(Label::Table(Table::WhiteNoise));
        }
        labels
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let study = ctx.study();
        let n = study.noise.as_ref()?;
        Some(
            view(n, study.white_noise.as_ref(), ctx.numbers)
                .map(|v| Box::new(v) as Box<dyn SectionView>),
        )
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let study = input.study;
        let n = study.noise.as_ref()?;
        Some((
            "noise_statistics",
            Box::new(crate::export::noise::record(n, study.white_noise.as_ref())),
        ))
    }
}

#[derive(Template)]
#[template(path = "sections/noise.html")]
struct NoiseHtml<'a> {
    n: &'a NoiseView,
}

crate::section_view!(NoiseView, NoiseHtml { n }, anchor: |_| "noise-estimate".to_string(), title: |_| "Noise statistics from a drive".to_string());
