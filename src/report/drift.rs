//! The section "A drifting bias": the same random-walk truth seen by a filter that believes the
//! bias constant and by one that models the walk.

use askama::Template;
use serde::Serialize;

use super::equations::Equations;
use super::figures::figure;
use super::kind::{Built, Context, Record, SectionKind, SectionView};
use super::outline::{Figure, Label, Numbers, Table};

use super::view::FigureView;
use super::{RenderError, ReportInput, rich};
use crate::checks::{CheckId, Verdict};
use crate::format::{count, fixed, short, sig};
use crate::plot::{self, DriftSeries};
use crate::state::ErrorState;
use crate::study::drift::{DriftFilter, DriftStudy};

/// The time at which the section quotes both filters' claim and error, s (the run's end when it
/// is shorter).
pub const QUOTE_AT_S: f64 = 120.0;
/// Achieved RMS over claimed σ beyond which a filter is said to claim far less error than it
/// makes.
const OVERCONFIDENT_RATIO: f64 = 1.5;

/// One filter's row of the section's table.
#[derive(Clone, Debug, Serialize)]
pub struct DriftRow {
    /// The filter, in words.
    pub filter: String,
    /// Its bias σ claimed and its RMS bias error achieved at [`QUOTE_AT_S`] and at the end.
    pub claimed_at_quote: String,
    /// Achieved RMS bias error at [`QUOTE_AT_S`].
    pub achieved_at_quote: String,
    /// Claimed bias σ at the end of the run.
    pub claimed_final: String,
    /// Achieved RMS bias error at the end.
    pub achieved_final: String,
    /// Achieved over claimed at the end.
    pub ratio_final: String,
    /// Each check's verdict, in [`CheckId::ALL`] order.
    pub verdicts: Vec<String>,
}

/// The section's view.
#[derive(Clone, Debug, Serialize)]
pub struct DriftView {
    /// The figure: claimed σ against achieved RMS over time.
    pub figure: FigureView,
    /// The table's number.
    pub table_number: usize,
    /// K of the truth, m/s²/√s, formatted.
    pub k: String,
    /// How far the bias walks over the run (K·√T), m/s², formatted.
    pub drift: String,
    /// The run's length, s.
    pub duration_s: String,
    /// The quoted time, s.
    pub quote_s: String,
    /// Realizations of each ensemble.
    pub realizations: String,
    /// The checks' titles, as the table's columns.
    pub checks: Vec<String>,
    /// The constant-bias filter, then the random-walk filter.
    pub rows: Vec<DriftRow>,
    /// The conclusion the numbers decide, as HTML.
    pub conclusion_html: String,
}

const BIAS: usize = ErrorState::BIAS;

/// (claimed, achieved) bias σ of `f` at the kept fix nearest `t_s`.
fn bias_at(f: &DriftFilter, t_s: f64) -> (f64, f64) {
    let i = f.nearest(t_s);
    (f.claimed_sigma[i][BIAS], f.achieved_rms[i][BIAS])
}

fn mm(x: f64) -> String {
    format!("{} mm/s²", sig(1e3 * x, 2))
}

fn row(name: &str, f: &DriftFilter, quote_s: f64, end_s: f64) -> DriftRow {
    let (cq, aq) = bias_at(f, quote_s);
    let (ce, ae) = bias_at(f, end_s);
    DriftRow {
        filter: name.to_string(),
        claimed_at_quote: mm(cq),
        achieved_at_quote: mm(aq),
        claimed_final: mm(ce),
        achieved_final: mm(ae),
        ratio_final: fixed(ae / ce, 2),
        verdicts: CheckId::ALL
            .iter()
            .map(|&id| f.verdicts.get(id).verdict.name().to_string())
            .collect(),
    }
}

/// The sentence the numbers decide: how each filter's claim compares with its error, and what the
/// checks said.
fn conclusion(d: &DriftStudy, quote_s: f64) -> String {
    let (cc, ca) = bias_at(&d.constant, quote_s);
    let (rc, ra) = bias_at(&d.random_walk, quote_s);
    let claim = |claimed: f64, achieved: f64| {
        if achieved > OVERCONFIDENT_RATIO * claimed {
            format!(
                "claims {} at {} s and achieves {}, {} times worse than it claims",
                mm(claimed),
                fixed(quote_s, 0),
                mm(achieved),
                fixed(achieved / claimed, 1)
            )
        } else {
            format!(
                "claims {} at {} s and achieves {}: its claim holds",
                mm(claimed),
                fixed(quote_s, 0),
                mm(achieved)
            )
        }
    };
    let checks = |f: &DriftFilter| {
        let failed: Vec<&str> = f
            .verdicts
            .checks
            .iter()
            .filter(|c| c.verdict == Verdict::Fail)
            .map(|c| c.id.name())
            .collect();
        if failed.is_empty() {
            if f.verdicts.all_passed() {
                "every check passes".to_string()
            } else {
                "no check fails".to_string()
            }
        } else {
            format!("{} fail", failed.join(", "))
        }
    };
    format!(
        "The constant-bias filter {} ({}); the random-walk filter {} ({}).",
        claim(cc, ca),
        checks(&d.constant),
        claim(rc, ra),
        checks(&d.random_walk)
    )
}

/// The section's view, its figure and table numbered from `numbers`.
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn.
pub fn view(d: &DriftStudy, numbers: &Numbers) -> Result<DriftView, RenderError> {
    let end_s = *d.constant.time_s.last().expect("at least one fix");
    let quote_s = QUOTE_AT_S.min(end_s);
    let series = |label: &str, f: &DriftFilter| DriftSeries {
        label: label.to_string(),
        time_s: f.time_s.clone(),
        claimed: f.claimed_sigma.clone(),
        achieved: f.achieved_rms.clone(),
    };
    let figure = figure(
        "fig-drift",
        numbers.figure(Figure::Drift),
        "A drifting bias: claimed against achieved accuracy",
        "The σ each filter claims after every fix (thin) and the RMS error it achieves (thick), for each state, when the bias walks at random: exact, from the covariance recursion of the filter with its own gains and the truth's noise, no random numbers. The random-walk filter's lines lie on one another; the constant-bias filter's part as its σ shrinks while the bias keeps moving.",
        plot::drift_sigma(&[
            series("constant-bias filter", &d.constant),
            series("random-walk filter", &d.random_walk),
        ]),
    )?;
    Ok(DriftView {
        figure,
        table_number: numbers.table(Table::Drift),
        k: short(d.k_m_s2_per_sqrt_s),
        drift: sig(d.k_m_s2_per_sqrt_s * d.duration_s.sqrt(), 2),
        duration_s: fixed(d.duration_s, 0),
        quote_s: fixed(quote_s, 0),
        realizations: count(d.realizations),
        checks: CheckId::ALL.iter().map(|c| c.name().to_string()).collect(),
        rows: vec![
            row("constant bias", &d.constant, quote_s, end_s),
            row("random walk", &d.random_walk, quote_s, end_s),
        ],
        conclusion_html: rich::rich(&conclusion(d, quote_s)),
    })
}

/// One filter of the drifting-bias study in data.json.
#[derive(Serialize)]
pub struct DriftFilterRecord<'a> {
    /// The bias model the filter assumes.
    pub bias_model: &'static str,
    /// Fix times of the series, s.
    pub time_s: &'a [f64],
    /// The filter's a posteriori σ at those fixes: [position m, velocity m/s, bias m/s²].
    pub claimed_sigma: &'a [[f64; ErrorState::DIM]],
    /// The actual RMS error there (exact), same order and units.
    pub achieved_rms: &'a [[f64; ErrorState::DIM]],
    /// Each check's verdict on the filter's ensemble.
    pub verdicts: std::collections::BTreeMap<&'static str, &'static str>,
}

/// data.json's `drifting_bias`: a constant-bias and a random-walk filter on one random-walk truth.
#[derive(Serialize)]
pub struct DriftRecord<'a> {
    /// K of the truth's random walk, m/s²/√s.
    bias_random_walk_m_s2_per_sqrt_s: f64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// Realizations of each ensemble.
    pub realizations: u64,
    /// The constant-bias filter, then the random-walk filter.
    pub filters: [DriftFilterRecord<'a>; 2],
}

/// The study's record in data.json.
pub fn record(d: &DriftStudy) -> DriftRecord<'_> {
    fn filter(f: &DriftFilter) -> DriftFilterRecord<'_> {
        DriftFilterRecord {
            bias_model: f.bias_model.name(),
            time_s: &f.time_s,
            claimed_sigma: &f.claimed_sigma,
            achieved_rms: &f.achieved_rms,
            verdicts: f
                .verdicts
                .checks
                .iter()
                .map(|c| (c.id.name(), c.verdict.name()))
                .collect(),
        }
    }
    DriftRecord {
        bias_random_walk_m_s2_per_sqrt_s: d.k_m_s2_per_sqrt_s,
        duration_s: d.duration_s,
        realizations: d.realizations,
        filters: [filter(&d.constant), filter(&d.random_walk)],
    }
}

/// The section "A drifting bias", when the study ran it.
pub struct Drift;

impl SectionKind for Drift {
    fn key(&self) -> &'static str {
        "drift"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.study.drift.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![Label::Figure(Figure::Drift), Label::Table(Table::Drift)]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let d = ctx.study().drift.as_ref()?;
        Some(view(d, ctx.numbers).map(|v| Box::new(v) as Box<dyn SectionView>))
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let d = input.study.drift.as_ref()?;
        Some(("drifting_bias", Box::new(record(d))))
    }
}

#[derive(Template)]
#[template(path = "sections/drift.html")]
struct DriftHtml<'a> {
    d: &'a DriftView,
    eq: &'a Equations,
}

crate::section_view!(DriftView, DriftHtml { d, eq }, anchor: |_| "drifting-bias".to_string(), title: |_| "A drifting bias".to_string());
