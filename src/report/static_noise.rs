//! The section "Noise statistics from a static log": `accelcal allan` on a simulated static log
//! whose terms are known, and the coverage of its intervals over many such logs (the view is
//! [`AllanSection`]). Present when the report is given the coverage.

use askama::Template;
use serde::Serialize;

use super::allan::{TermRow, series, term_row};
use super::figures::inline_svg;
use super::kind::{Built, Context, SectionKind, SectionView};
use super::outline::{Figure, Label, Table};

use super::{RenderError, ReportInput};
use crate::allan::section::{Coverage, REPORT_LOG, REPORT_SAMPLES, coverage, covers};
use crate::allan::simulate::StaticLog;
use crate::allan::{AllanError, Analysis, Term, analyse};
use crate::format::{count, sig};
use crate::input::csv::read::LogText;
use crate::input::csv::static_log::read_static_log;
use crate::input::csv::text::{header, push_row};
use crate::plot::{self, PlotError};

/// The Allan figure of `a` (SVG), as `accelcal allan` draws it.
fn allan_svg(a: &Analysis) -> Result<String, RenderError> {
    plot::allan_deviation(&series(a))
        .map(inline_svg)
        .map_err(|source: PlotError| RenderError::Figure {
            figure: "allan-plot".to_string(),
            source,
        })
}

/// The section, when the report's input holds the coverage study.
pub struct StaticNoise;

impl SectionKind for StaticNoise {
    fn key(&self) -> &'static str {
        "static_noise"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.static_noise.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Figure(Figure::AllanDeviation),
            Label::Table(Table::StaticNoise),
            Label::Table(Table::StaticNoiseCoverage),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let coverage = ctx.input.static_noise?;
        let n = ctx.numbers;
        let figure = n.figure(Figure::AllanDeviation);
        let table = n.table(Table::StaticNoise);
        debug_assert_eq!(n.table(Table::StaticNoiseCoverage), table + 1);
        Some(
            section(&REPORT_LOG, REPORT_SAMPLES, 0, coverage, figure, table)
                .map(|v| Box::new(v) as Box<dyn SectionView>),
        )
    }
}

#[derive(Template)]
#[template(path = "sections/allan.html")]
struct StaticNoiseHtml<'a> {
    a: &'a AllanSection,
}

crate::section_view!(AllanSection, StaticNoiseHtml { a }, anchor: |_| "allan".to_string(), title: |_| "Noise statistics from a static log".to_string());

/// The report's section as the report shows it: [`REPORT_LOG`], one log of [`REPORT_SAMPLES`]
/// (seed 0) through the log reader and the analysis, and the coverage study over `seeds` logs
/// (100 in the test suite: about 4 s on 2 cores) with 95 % intervals and a band at a 1 %
/// false-alarm rate; the figure and the first of the two tables get the numbers given.
///
/// # Errors
/// [`RenderError`] only if the simulated logs were too short, which they are not.
pub fn report_section(
    seeds: u64,
    figure_number: usize,
    table_number: usize,
) -> Result<AllanSection, RenderError> {
    let c = coverage(&REPORT_LOG, seeds, REPORT_SAMPLES, 0.95, 0.01)?;
    section(
        &REPORT_LOG,
        REPORT_SAMPLES,
        0,
        &c,
        figure_number,
        table_number,
    )
}

/// One row of the recovered-against-true table.
#[derive(Clone, Debug, Serialize)]
pub struct RecoveredRow {
    /// The term, as HTML.
    pub name_html: String,
    /// The true value with its unit.
    pub truth: String,
    /// The estimate with its interval, SI and datasheet units.
    pub recovered: TermRow,
    /// "yes" when the interval contains the truth.
    pub covered: String,
}

/// One row of the coverage table.
#[derive(Clone, Debug, Serialize)]
pub struct CoverageRow {
    /// The term and the construction, as HTML.
    pub name_html: String,
    /// "k of n".
    pub covered: String,
    /// "inside" or "outside" the band.
    pub verdict: String,
}

/// Everything the section shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct AllanSection {
    /// The simulated log in words.
    pub log_words: String,
    /// The command that analyses such a log.
    pub command: String,
    /// The Allan plot (SVG).
    pub svg: String,
    /// Recovered against true, for N and K.
    pub recovered: Vec<RecoveredRow>,
    /// The coverage study in words.
    pub coverage_words: String,
    /// The coverage table.
    pub coverage: Vec<CoverageRow>,
    /// The confidence of the intervals, per cent.
    pub confidence: String,
    /// The figure's number in the report.
    pub figure_number: usize,
    /// The first table's number (the second is the next).
    pub table_number: usize,
}

/// The log as the CSV text an accelerometer log holds.
fn csv_text(y: &[f64], sample_period_s: f64) -> String {
    let mut text = header(&["t_s", "accel_m_s2"]);
    for (i, v) in y.iter().enumerate() {
        push_row(&mut text, &[i as f64 * sample_period_s, *v]);
    }
    text
}

fn recovered(a: &Analysis, log: &StaticLog) -> Vec<RecoveredRow> {
    [
        (
            Term::VelocityRandomWalk,
            log.velocity_random_walk_m_s_per_sqrt_s,
            "m/s/√s",
        ),
        (
            Term::AccelerationRandomWalk,
            log.acceleration_random_walk_m_s2_per_sqrt_s,
            "m/s²/√s",
        ),
    ]
    .into_iter()
    .filter_map(|(term, truth, unit)| {
        let t = a.term(term)?;
        let row = term_row(t);
        Some(RecoveredRow {
            name_html: row.name_html.clone(),
            truth: format!("{} {unit}", sig(truth, 3)),
            recovered: row,
            covered: if covers(a, term, truth, false) {
                "yes"
            } else {
                "no"
            }
            .to_string(),
        })
    })
    .collect()
}

fn coverage_rows(c: &Coverage) -> Vec<CoverageRow> {
    let row = |name: &str, k: u64| CoverageRow {
        name_html: name.to_string(),
        covered: format!("{k} of {}", c.seeds),
        verdict: if (c.band.0..=c.band.1).contains(&k) {
            "inside"
        } else {
            "outside"
        }
        .to_string(),
    };
    vec![
        row(
            "<i>N</i>, intervals from the covariance across τ",
            c.n_covered,
        ),
        row(
            "<i>K</i>, intervals from the covariance across τ",
            c.k_covered,
        ),
        row(
            "<i>N</i>, nominal standard errors (negative control)",
            c.n_nominal_covered,
        ),
        row(
            "<i>K</i>, nominal standard errors (negative control)",
            c.k_nominal_covered,
        ),
    ]
}

/// The section: `samples` samples of `log` from `seed` through the log reader and the analysis
/// at the coverage study's confidence, with the study `coverage` (from [`coverage`]); the figure
/// and first table get the numbers given.
///
/// # Errors
/// [`RenderError`] when the simulated log is too short for the analysis or the figure cannot be
/// drawn.
pub fn section(
    log: &StaticLog,
    samples: usize,
    seed: u64,
    coverage: &Coverage,
    figure_number: usize,
    table_number: usize,
) -> Result<AllanSection, RenderError> {
    let source = LogText::new(
        "static.csv",
        csv_text(&log.samples(samples, seed), log.sample_period_s),
    );
    let read = read_static_log(&source, "accel_m_s2")
        .map_err(|e| AllanError::SimulatedLog(e.to_string()))?;
    let a = analyse(&read.values, read.sample_period_s, coverage.confidence)?;
    Ok(AllanSection {
        log_words: format!(
            "{} samples at {} Hz ({} s) of white noise with N = {} m/s/√s and a random walk of \
             the bias with K = {} m/s²/√s, on a 1 g offset (seed {seed})",
            count(samples as u64),
            sig(1.0 / log.sample_period_s, 4),
            sig(samples as f64 * log.sample_period_s, 4),
            sig(log.velocity_random_walk_m_s_per_sqrt_s, 3),
            sig(log.acceleration_random_walk_m_s2_per_sqrt_s, 3)
        ),
        command: format!(
            "accelcal allan --accel static.csv --confidence {}",
            coverage.confidence
        ),
        svg: allan_svg(&a)?,
        recovered: recovered(&a, log),
        coverage_words: format!(
            "{} such logs of {} samples (seeds 0 to {}), {} % intervals; a construction that \
             covers as claimed lands inside the binomial band [{}, {}] with probability at least \
             {} % (false-alarm rate {} %); K was unresolved in {} of them. The actual mean \
             squared error of N̂² is {} times the variance the fit claims and that of K̂² {} \
             times (nominal variances: {} and {})",
            count(coverage.seeds),
            count(coverage.samples as u64),
            coverage.seeds.saturating_sub(1),
            sig(100.0 * coverage.confidence, 3),
            coverage.band.0,
            coverage.band.1,
            sig(100.0 * (1.0 - coverage.false_alarm_rate), 3),
            sig(100.0 * coverage.false_alarm_rate, 2),
            coverage.k_unresolved,
            sig(coverage.n_scatter_ratio, 3),
            sig(coverage.k_scatter_ratio, 3),
            sig(coverage.n_nominal_scatter_ratio, 3),
            sig(coverage.k_nominal_scatter_ratio, 3)
        ),
        coverage: coverage_rows(coverage),
        confidence: sig(100.0 * coverage.confidence, 3),
        figure_number,
        table_number,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The section's template on its own, as the report includes it.
    #[derive(Template)]
    #[template(path = "sections/allan.html")]
    struct Page<'a> {
        a: &'a AllanSection,
    }

    #[test]
    fn the_section_renders_its_view() {
        let log = StaticLog {
            sample_period_s: 0.01,
            velocity_random_walk_m_s_per_sqrt_s: 2e-3,
            acceleration_random_walk_m_s2_per_sqrt_s: 1e-3,
            offset_m_s2: 9.80665,
        };
        let c = coverage(&log, 4, 20_000, 0.95, 0.01).unwrap();
        let s = section(&log, 20_000, 0, &c, 7, 3).unwrap();
        let html = Page { a: &s }.render().unwrap();
        assert!(html.contains("Noise statistics from a static log"));
        assert!(html.contains("Figure 7.") && html.contains("Table 4."));
        assert!(html.contains("<svg") && html.contains("of 4"));
    }
}
