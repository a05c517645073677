//! The cases side by side: the accuracy each achieves against the accuracy its filter claims,
//! and how far each mean error strays, in filter σ.

use plotters::style::{Color, RGBColor};

use super::axis::{Axis, y_label_area};
use super::geometry::{extent, time_span};
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel, columns};
use super::{
    BLACK, BLUE, PlotResult, REDDISH_PURPLE, REFERENCE, VERMILLION, capitalized, last_state,
    state_name, states,
};
use crate::ensemble::EnsembleStats;
use crate::state::ErrorState;

/// Height of one state's panel, px.
const ROW_PX: u32 = 230;

/// Colours of the cases, in order.
const CASE_COLORS: [RGBColor; 3] = [BLUE, VERMILLION, REDDISH_PURPLE];

/// One case to draw: its legend label, its ensemble statistics, and its achieved RMS a
/// posteriori error at every fix.
pub struct CaseSeries<'a> {
    /// Legend label.
    pub label: String,
    /// The ensemble statistics.
    pub stats: &'a EnsembleStats,
    /// Achieved RMS error at every fix, per state.
    pub achieved_rms: &'a [[f64; ErrorState::DIM]],
}

fn color(i: usize) -> RGBColor {
    CASE_COLORS[i % CASE_COLORS.len()]
}

fn legend(cases: &[CaseSeries<'_>]) -> Vec<Entry> {
    cases
        .iter()
        .enumerate()
        .map(|(i, c)| Entry::new(Swatch::Line(color(i).stroke_width(2)), c.label.clone()))
        .collect()
}

/// Stacked panels, one per state, sharing a time axis; `draw(panel, k)` fills each.
fn per_state(
    cases: &[CaseSeries<'_>],
    extra_legend: Vec<Entry>,
    title: &dyn Fn(usize) -> String,
    axes: Vec<Axis>,
    draw: &dyn Fn(&Panel<'_>, usize) -> Result<(), super::PlotError>,
) -> PlotResult {
    let (t0, t1) = time_span(
        cases
            .iter()
            .flat_map(|c| c.stats.fixes.iter().map(|f| f.time_s)),
    );
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 8);
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let mut entries = legend(cases);
    entries.extend(extra_legend);
    render_state_rows(ROW_PX, &entries, |area, k| {
        let p = Panel::new(
            area,
            &title(k),
            time.clone(),
            axes[k].clone(),
            Layout::titled(y_area_px, last_state(k)),
        )?;
        draw(&p, k)?;
        Ok(())
    })
}

/// Width of the full-range column, px; the enlarged band around 1 takes the rest.
const FULL_COLUMN_PX: u32 = 590;

/// Per state, the achieved RMS a posteriori error divided by the filter's σ at every fix, one
/// line per case, against 1 (the filter's claim) and ±5 %: over the whole range on the left,
/// and enlarged to 1 ± 10 % on the right, where a consistent case lives.
pub fn accuracy_ratio(cases: &[CaseSeries<'_>]) -> PlotResult {
    let ratio = |c: &CaseSeries<'_>, i: usize, k: usize| {
        c.achieved_rms[i][k] / c.stats.fixes[i].post.filter_cov[k][k].sqrt()
    };
    let full_axes: Vec<Axis> = states()
        .map(|k| {
            let (lo, hi) = extent(
                cases
                    .iter()
                    .flat_map(|c| (0..c.stats.fixes.len()).map(move |i| ratio(c, i, k))),
            )
            .unwrap_or((1.0, 1.0));
            let (lo, hi) = (lo.min(0.9), hi.max(1.1));
            let pad = 0.08 * (hi - lo);
            Axis::linear("RMS error / σ", "", (lo - pad, hi + pad), 6)
        })
        .collect();
    let near_axes: Vec<Axis> = states()
        .map(|_| Axis::linear("RMS error / σ", "", (0.9, 1.1), 5))
        .collect();
    let (t0, t1) = time_span(
        cases
            .iter()
            .flat_map(|c| c.stats.fixes.iter().map(|f| f.time_s)),
    );
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 8);
    let full_area = y_label_area(&full_axes.iter().collect::<Vec<_>>());
    let near_area = y_label_area(&near_axes.iter().collect::<Vec<_>>());
    let mut entries = legend(cases);
    entries.push(Entry::new(
        Swatch::Line(BLACK.stroke_width(1)),
        "1: the filter's claim",
    ));
    entries.push(Entry::new(Swatch::Line(REFERENCE.stroke_width(1)), "±5 %"));
    render_state_rows(ROW_PX, &entries, |area, k| {
        let cols = columns(area, &[FULL_COLUMN_PX]);
        let name = capitalized(state_name(k));
        for (col, axis, area, title) in [
            (
                &cols[0],
                &full_axes[k],
                full_area,
                format!("{name}: achieved RMS error over the filter's σ"),
            ),
            (
                &cols[1],
                &near_axes[k],
                near_area,
                format!("{name}: around 1, enlarged"),
            ),
        ] {
            let p = Panel::new(
                col,
                &title,
                time.clone(),
                axis.clone(),
                Layout::titled(area, last_state(k)),
            )?;
            p.hline(1.0, BLACK.stroke_width(1))?;
            p.hline(1.05, REFERENCE.stroke_width(1))?;
            p.hline(0.95, REFERENCE.stroke_width(1))?;
            for (j, c) in cases.iter().enumerate() {
                p.line(
                    (0..c.stats.fixes.len()).map(|i| (c.stats.fixes[i].time_s, ratio(c, i, k))),
                    color(j).stroke_width(2),
                )?;
            }
        }
        Ok(())
    })
}

/// Per state, the a posteriori |mean error| in units of the filter's σ at every fix on a log
/// axis, one line per case, against the mean-error check's bound b/√N in the same units: a
/// systematic error stands decades above sampling noise.
pub fn mean_error_in_sigma(cases: &[CaseSeries<'_>], bound: f64) -> PlotResult {
    let z = |c: &CaseSeries<'_>, i: usize, k: usize| {
        let f = &c.stats.fixes[i].post;
        (f.mean_error[k] / f.filter_cov[k][k].sqrt()).abs()
    };
    let limit = |c: &CaseSeries<'_>| bound / (c.stats.realizations as f64).sqrt();
    let axes: Vec<Axis> = states()
        .map(|k| {
            let values = cases.iter().flat_map(|c| {
                (0..c.stats.fixes.len())
                    .map(move |i| z(c, i, k))
                    .chain([limit(c)])
            });
            let (lo, hi) = extent(values.filter(|v| *v > 0.0)).unwrap_or((1e-3, 1.0));
            Axis::log10("|mean error| / σ", "", (lo.max(1e-6 * hi), hi))
        })
        .collect();
    let extra = vec![Entry::new(
        Swatch::Line(BLACK.stroke_width(1)),
        format!("check bound {bound:.2}/√N"),
    )];
    per_state(
        cases,
        extra,
        &|k| {
            format!(
                "{}: a posteriori |mean error| in units of the filter's σ",
                capitalized(state_name(k))
            )
        },
        axes,
        &|p, k| {
            for (j, c) in cases.iter().enumerate() {
                p.hline(limit(c), BLACK.stroke_width(1))?;
                p.line(
                    (0..c.stats.fixes.len()).map(|i| (c.stats.fixes[i].time_s, z(c, i, k))),
                    color(j).stroke_width(2),
                )?;
            }
            Ok(())
        },
    )
}
