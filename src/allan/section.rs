//! The report's section "Noise statistics from a static log": a simulated static log with known
//! N and K through the same path as `accelcal allan` (CSV text, the log reader and its step
//! checks, the analysis), its Allan plot, the recovered terms against the true ones, and the
//! coverage of the intervals over many such logs. The view is text; `templates/sections/allan.html`
//! shows it.

use rayon::prelude::*;
use serde::Serialize;

use super::figure::allan_plot;
use super::fit::term_interval;
use super::log::read_static_log;
use super::page::{TermRow, term_row};
use super::simulate::StaticLog;
use super::{AllanError, Analysis, Term, analyse};
use crate::format::{count, sig};
use crate::logs::read::LogText;
use crate::logs::write::{header, push_row};

/// How often the intervals of N and K contained the truth over `seeds` simulated logs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Coverage {
    /// Simulated logs.
    pub seeds: u64,
    /// Samples per log.
    pub samples: usize,
    /// The intervals' confidence.
    pub confidence: f64,
    /// The false-alarm rate of the band.
    pub false_alarm_rate: f64,
    /// The binomial band of covered counts, both ends accepted.
    pub band: (u64, u64),
    /// Intervals of N (sandwich covariance) that covered.
    pub n_covered: u64,
    /// Intervals of K that covered (an unresolved K covers when its bound does).
    pub k_covered: u64,
    /// Intervals of N from the fit's nominal standard errors that covered.
    pub n_nominal_covered: u64,
    /// The same for K.
    pub k_nominal_covered: u64,
    /// Logs whose K was unresolved.
    pub k_unresolved: u64,
    /// Mean of (N̂² − N²)² over the mean sandwich variance of N̂²: near 1 when the claimed
    /// scatter is the actual one (a check of both sides: too wide as well as too narrow).
    pub n_scatter_ratio: f64,
    /// The same for K².
    pub k_scatter_ratio: f64,
    /// The same for N² with the nominal variance.
    pub n_nominal_scatter_ratio: f64,
    /// The same for K² with the nominal variance.
    pub k_nominal_scatter_ratio: f64,
}

pub use crate::stats::binomial_band;

/// Whether the interval of `term` in `a` contains `truth`; `nominal` takes the fit's nominal
/// standard error instead of the sandwich one.
pub fn covers(a: &Analysis, term: Term, truth: f64, nominal: bool) -> bool {
    let Some(t) = a.fit.term(term) else {
        return false;
    };
    let (lower, upper) = if nominal {
        let (_, lo, hi) = term_interval(t.squared, t.squared_sigma_nominal.powi(2), a.confidence);
        (lo.unwrap_or(0.0), hi)
    } else {
        (t.lower.unwrap_or(0.0), t.upper)
    };
    lower <= truth && truth <= upper
}

/// The coverage study: `seeds` logs of `samples` samples of `log` (seeds 0, 1, …), analysed in
/// memory on all threads, intervals at `confidence`, the band at `false_alarm_rate`.
pub fn coverage(
    log: &StaticLog,
    seeds: u64,
    samples: usize,
    confidence: f64,
    false_alarm_rate: f64,
) -> Result<Coverage, AllanError> {
    let (n, k) = (
        log.velocity_random_walk_m_s_per_sqrt_s,
        log.acceleration_random_walk_m_s2_per_sqrt_s,
    );
    let per_seed: Vec<[f64; 11]> = (0..seeds)
        .into_par_iter()
        .map(|seed| {
            let a = analyse(&log.samples(samples, seed), log.sample_period_s, confidence)?;
            let (tn, tk) = (
                a.fit.term(Term::VelocityRandomWalk),
                a.fit.term(Term::AccelerationRandomWalk),
            );
            let unresolved = tk.is_some_and(|t| t.value.is_none());
            let error = |t: Option<&super::TermEstimate>, truth: f64| {
                t.map_or([f64::NAN; 3], |t| {
                    [
                        (t.squared - truth * truth).powi(2),
                        t.squared_sigma.powi(2),
                        t.squared_sigma_nominal.powi(2),
                    ]
                })
            };
            let (en, ek) = (error(tn, n), error(tk, k));
            let flag = |b: bool| b as u64 as f64;
            Ok([
                flag(covers(&a, Term::VelocityRandomWalk, n, false)),
                flag(covers(&a, Term::AccelerationRandomWalk, k, false)),
                flag(covers(&a, Term::VelocityRandomWalk, n, true)),
                flag(covers(&a, Term::AccelerationRandomWalk, k, true)),
                flag(unresolved),
                en[0],
                en[1],
                en[2],
                ek[0],
                ek[1],
                ek[2],
            ])
        })
        .collect::<Result<_, AllanError>>()?;
    let sum = |i: usize| per_seed.iter().map(|c| c[i]).sum::<f64>();
    Ok(Coverage {
        seeds,
        samples,
        confidence,
        false_alarm_rate,
        band: binomial_band(seeds, confidence, false_alarm_rate),
        n_covered: sum(0) as u64,
        k_covered: sum(1) as u64,
        n_nominal_covered: sum(2) as u64,
        k_nominal_covered: sum(3) as u64,
        k_unresolved: sum(4) as u64,
        n_scatter_ratio: sum(5) / sum(6),
        k_scatter_ratio: sum(8) / sum(9),
        n_nominal_scatter_ratio: sum(5) / sum(7),
        k_nominal_scatter_ratio: sum(8) / sum(10),
    })
}

/// The static log the report simulates: 100 Hz, N = 2·10⁻³ m/s/√s (about 200 µg/√Hz),
/// K = 10⁻⁴ m/s²/√s, on a 1 g offset; its Allan minimum lies near τ = 40 s.
pub const REPORT_LOG: StaticLog = StaticLog {
    sample_period_s: 0.01,
    velocity_random_walk_m_s_per_sqrt_s: 2e-3,
    acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
    offset_m_s2: 9.80665,
};

/// Samples of each log of the report's section (10⁶: 2.8 h at 100 Hz).
pub const REPORT_SAMPLES: usize = 1_000_000;

/// The report's section as the report shows it: [`REPORT_LOG`], one log of [`REPORT_SAMPLES`]
/// (seed 0) through the log reader and the analysis, and the coverage study over `seeds` logs
/// (100 in the test suite: about 4 s on 2 cores) with 95 % intervals and a band at a 1 %
/// false-alarm rate; the figure and the first of the two tables get the numbers given.
///
/// # Errors
/// [`AllanError`] only if the simulated logs were too short, which they are not.
pub fn report_section(
    seeds: u64,
    figure_number: usize,
    table_number: usize,
) -> Result<AllanSection, AllanError> {
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

/// Simulated static logs of the report's validation: enough for a coverage of 95 % intervals to
/// be judged inside a binomial band at 1 % (about 4 s on 2 cores).
pub const REPORT_SEEDS: u64 = 100;

/// The coverage study the report shows: [`REPORT_SEEDS`] logs of [`REPORT_LOG`] of
/// [`REPORT_SAMPLES`] each, 95 % intervals, a band at a 1 % false-alarm rate.
///
/// # Errors
/// [`AllanError`] only if the simulated logs were too short, which they are not.
pub fn report_coverage() -> Result<Coverage, AllanError> {
    coverage(&REPORT_LOG, REPORT_SEEDS, REPORT_SAMPLES, 0.95, 0.01)
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
        let t = a.fit.term(term)?;
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
/// [`AllanError`] when the simulated log is too short for the analysis.
pub fn section(
    log: &StaticLog,
    samples: usize,
    seed: u64,
    coverage: &Coverage,
    figure_number: usize,
    table_number: usize,
) -> Result<AllanSection, AllanError> {
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
        svg: allan_plot(&a),
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
    use askama::Template;

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
