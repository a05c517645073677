//! The ensemble's error variance against the filter's.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{extent, padded, time_span};
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel, columns};
use super::{
    BLACK, BLUE, ORANGE, PlotError, PlotResult, REFERENCE, SKY_BLUE, VERMILLION, WIDTH_PX,
    capitalized, last_state, state_name, state_unit, states,
};
use crate::checks::Check;
use crate::ensemble::{EnsembleStats, FixStats, StageStats};

/// Height of one state's row, px.
const ROW_PX: u32 = 250;

/// Per state (rows): left, the ensemble variance P_ave and the filter's P at every fix, a priori
/// and a posteriori, on a log axis; right, their ratio P_ave/P against the check's χ² band.
pub fn covariance(stats: &EnsembleStats, check: &Check) -> PlotResult {
    let fixes = &stats.fixes;
    let (t0, t1) = time_span(fixes.iter().map(|f| f.time_s));
    let time = Axis::linear("time", "s", (t0.min(0.0), t1), 7);
    let var_axes: Vec<Axis> = states()
        .map(|k| {
            let values = fixes.iter().flat_map(|f| {
                let (a, b) = var(&f.prior, k);
                let (c, d) = var(&f.post, k);
                [a, b, c, d]
            });
            let (lo, hi) = extent(values.filter(|v| *v > 0.0)).unwrap_or((0.1, 10.0));
            // A compound unit is squared in parentheses: m², (m/s)².
            let unit = match state_unit(k) {
                u if u.contains('/') => format!("({u})²"),
                u => format!("{u}²"),
            };
            Axis::log10("variance", &unit, (lo, hi))
        })
        .collect();
    let ratio_axes: Vec<Axis> = states()
        .map(|k| {
            let values = fixes
                .iter()
                .flat_map(|f| [ratio(&f.prior, k), ratio(&f.post, k)])
                .chain([check.lower, check.upper, 1.0]);
            let range = extent(values).map_or((0.5, 1.5), |e| padded(e, 0.1));
            Axis::linear("P^{ave} / P", "", range, 6)
        })
        .collect();
    let var_area = y_label_area(&var_axes.iter().collect::<Vec<_>>());
    let ratio_area = y_label_area(&ratio_axes.iter().collect::<Vec<_>>());
    render_state_rows(ROW_PX, &legend(check), |area, k| {
        let cols = columns(area, &[WIDTH_PX / 2]);
        let layout = |y_area_px| Layout::titled(y_area_px, last_state(k));
        let name = state_name(k);
        let p = Panel::new(
            &cols[0],
            &format!("{}: ensemble and filter variance", capitalized(name)),
            time.clone(),
            var_axes[k].clone(),
            layout(var_area),
        )?;
        draw_variances(&p, fixes, k)?;
        let q = Panel::new(
            &cols[1],
            &format!("{}: variance ratio P^{{ave}} / P", capitalized(name)),
            time.clone(),
            ratio_axes[k].clone(),
            layout(ratio_area),
        )?;
        draw_ratios(&q, fixes, k, check)
    })
}

/// The ensemble's and the filter's variance of state `k` in a stage.
fn var(s: &StageStats, k: usize) -> (f64, f64) {
    (s.ensemble_cov[k][k], s.filter_cov[k][k])
}

/// The ratio P_ave/P of state `k` in a stage.
fn ratio(s: &StageStats, k: usize) -> f64 {
    let (ens, filt) = var(s, k);
    ens / filt
}

/// The legend of [`covariance`], with the band of `check`.
fn legend(check: &Check) -> [Entry; 5] {
    [
        Entry::new(
            Swatch::Line(ORANGE.mix(0.5).stroke_width(5)),
            "filter P, a priori",
        ),
        Entry::new(
            Swatch::Line(VERMILLION.stroke_width(2)),
            "ensemble P^{ave}, a priori",
        ),
        Entry::new(
            Swatch::Line(SKY_BLUE.mix(0.6).stroke_width(5)),
            "filter P, a posteriori",
        ),
        Entry::new(
            Swatch::Line(BLUE.stroke_width(2)),
            "ensemble P^{ave}, a posteriori",
        ),
        Entry::new(
            Swatch::Line(BLACK.stroke_width(1)),
            format!(
                "χ² band [{}, {}]",
                crate::format::sig(check.lower, 4),
                crate::format::sig(check.upper, 4)
            ),
        ),
    ]
}

/// The filter's variance of state `k` (wide) and the ensemble's (thin) on `p`, a priori then a
/// posteriori.
fn draw_variances(p: &Panel<'_>, fixes: &[FixStats], k: usize) -> Result<(), PlotError> {
    for (stage, wide, thin) in [
        (false, ORANGE.mix(0.5), VERMILLION.mix(1.0)),
        (true, SKY_BLUE.mix(0.6), BLUE.mix(1.0)),
    ] {
        let pick = |f: &FixStats| {
            if stage {
                var(&f.post, k)
            } else {
                var(&f.prior, k)
            }
        };
        p.line(
            fixes.iter().map(|f| (f.time_s, pick(f).1)),
            wide.stroke_width(5),
        )?;
        p.line(
            fixes.iter().map(|f| (f.time_s, pick(f).0)),
            thin.stroke_width(1),
        )?;
    }
    Ok(())
}

/// The ratio P_ave/P of state `k` on `q`, a priori and a posteriori, against 1 and the band of
/// `check`.
fn draw_ratios(
    q: &Panel<'_>,
    fixes: &[FixStats],
    k: usize,
    check: &Check,
) -> Result<(), PlotError> {
    q.hline(1.0, REFERENCE.stroke_width(1))?;
    q.hline(check.lower, BLACK.stroke_width(1))?;
    q.hline(check.upper, BLACK.stroke_width(1))?;
    q.line(
        fixes.iter().map(|f| (f.time_s, ratio(&f.prior, k))),
        VERMILLION.stroke_width(2),
    )?;
    q.line(
        fixes.iter().map(|f| (f.time_s, ratio(&f.post, k))),
        BLUE.stroke_width(2),
    )?;
    Ok(())
}
