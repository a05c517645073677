//! One realization's estimation errors against the filter's 1σ envelope.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{before, clipped_until, extent, max_abs, padded, settled_from, time_span};
use super::legend::{Entry, Swatch, render_state_rows};
use super::panel::{Layout, Panel, columns};
use super::{
    BLACK, BLUE, ORANGE, PlotResult, REFERENCE, capitalized, last_state, state_name, state_unit,
    states,
};
use crate::realization::Realization;

/// Height of one state's row, px.
const ROW_PX: u32 = 270;
/// Width of the full-run column, px; the zoom takes the rest.
const FULL_COLUMN_PX: u32 = 590;
/// The full-run axes show σ up to this multiple of its final value; earlier, larger σ (the
/// bias's first seconds) runs off the axis rather than flattening the rest of the run.
const SETTLED_SIGMA_RATIO: f64 = 5.0;

/// The estimation error e = δx − δx̂ of one realization at every accelerometer sample, with the
/// filter's ±1σ, and beside it a zoom on σ over two seconds, where it grows between GPS fixes and
/// drops at each update.
///
/// The full-run axes are scaled to the run after its first second (or first quarter, if shorter),
/// and after σ has fallen to five times its final value: σ starts at the prior's 10 m, 1 m/s,
/// 0.1 m/s² and collapses within the first fixes (the bias's over about ten seconds), which would
/// otherwise flatten the rest of the run. The zoom plots σ alone because its sawtooth is about 1 %
/// of σ: on an axis that also holds e, the teeth would be a pixel high. A full-run panel whose
/// error or ±1σ leaves its axis says so in its title ("clipped before 7.7 s").
pub fn realization_errors(r: &Realization) -> PlotResult {
    let t: Vec<f64> = r.samples.iter().map(|s| s.t_s).collect();
    let (t0, t1) = time_span(t.iter().copied());
    let settle = settled_from(t0, t1);
    let zoom = zoom_window(t0, t1);

    let time = Axis::linear("time", "s", (t0, t1), 8);
    let zoom_time = Axis::linear("time", "s", zoom, 5);
    let error_axes: Vec<Axis> = states().map(|k| error_axis(r, k, settle)).collect();
    let sigma_axes: Vec<Axis> = states().map(|k| sigma_axis(r, k, zoom)).collect();
    let (full_area, zoom_area) = (
        y_label_area(&error_axes.iter().collect::<Vec<_>>()),
        y_label_area(&sigma_axes.iter().collect::<Vec<_>>()),
    );
    let full_layout = |last: bool| Layout::titled(full_area, last);
    let zoom_layout = |last: bool| Layout::titled(zoom_area, last);

    let legend = [
        Entry::new(Swatch::Line(BLUE.stroke_width(1)), "error e = δx − δx̂"),
        Entry::new(Swatch::Block(ORANGE.mix(0.35).filled()), "filter ±1σ"),
        Entry::new(Swatch::Line(ORANGE.stroke_width(2)), "filter σ"),
        Entry::new(Swatch::Marker(BLACK.stroke_width(2)), "σ before GPS update"),
        Entry::new(Swatch::Marker(BLACK.filled()), "σ after update"),
    ];
    render_state_rows(ROW_PX, &legend, |area, k| {
        let last = last_state(k);
        let cols = columns(area, &[FULL_COLUMN_PX]);
        let name = state_name(k);

        let full = Panel::new(
            &cols[0],
            &full_run_title(r, k, &error_axes[k]),
            time.clone(),
            error_axes[k].clone(),
            full_layout(last),
        )?;
        let sigma: Vec<f64> = r.samples.iter().map(|s| s.sigma[k]).collect();
        let lower: Vec<f64> = sigma.iter().map(|s| -s).collect();
        full.band(&t, &lower, &sigma, ORANGE.mix(0.35))?;
        full.hline(0.0, REFERENCE.stroke_width(1))?;
        full.line(
            r.samples
                .iter()
                .map(|s| (s.t_s, s.delta_x[k] - s.estimate[k])),
            BLUE.stroke_width(1),
        )?;

        let detail = Panel::new(
            &cols[1],
            &format!(
                "{} σ between fixes, {}–{} s",
                capitalized(name),
                zoom.0,
                zoom.1
            ),
            zoom_time.clone(),
            sigma_axes[k].clone(),
            zoom_layout(last),
        )?;
        detail.line(
            r.samples
                .iter()
                .filter(|s| s.t_s >= zoom.0 && s.t_s <= zoom.1)
                .map(|s| (s.t_s, s.sigma[k])),
            ORANGE.stroke_width(2),
        )?;
        let fixes = r
            .fixes
            .iter()
            .filter(|f| f.t_s >= zoom.0 && f.t_s <= zoom.1);
        detail.dots(
            fixes.clone().map(|f| (f.t_s, f.sigma_prior[k])),
            4,
            BLACK.stroke_width(2),
        )?;
        detail.dots(fixes.map(|f| (f.t_s, f.sigma_post[k])), 4, BLACK.filled())?;
        Ok(())
    })
}

/// The title of state `k`'s full-run panel, saying what `axis` clips: the error, ±1σ or both,
/// which leave it early in the run.
fn full_run_title(r: &Realization, k: usize, axis: &Axis) -> String {
    let name = capitalized(state_name(k));
    let error = clipped_until(
        r.samples
            .iter()
            .map(|s| (s.t_s, s.delta_x[k] - s.estimate[k])),
        |v| axis.shows(v),
    );
    let sigma = clipped_until(r.samples.iter().map(|s| (s.t_s, s.sigma[k])), |v| {
        axis.shows(v)
    });
    match (error, sigma) {
        (None, None) => format!("{name}: error and ±1σ over the run"),
        (Some(t), None) => format!("{name}: error and ±1σ (error off the axis {})", before(t)),
        (None, Some(t)) => format!("{name}: error and ±1σ (±1σ off the axis {})", before(t)),
        (Some(a), Some(b)) => format!(
            "{name}: error and ±1σ (both off the axis {})",
            before(a.max(b))
        ),
    }
}

/// The two-second window the zoom shows: from two thirds into the run (20–22 s of 30 s).
fn zoom_window(t0: f64, t1: f64) -> (f64, f64) {
    crate::realization::detail_window(t0, t1)
}

/// The symmetric error axis of state `k`, scaled to e and σ after `settle` or, if later, after σ
/// has come within [`SETTLED_SIGMA_RATIO`] of its final value (at most halfway through the run).
fn error_axis(r: &Realization, k: usize, settle: f64) -> Axis {
    let (t0, t1) = time_span(r.samples.iter().map(|s| s.t_s));
    let last = r.samples.last().map_or(f64::NAN, |s| s.sigma[k]);
    let converged = r
        .samples
        .iter()
        .rposition(|s| s.sigma[k] > SETTLED_SIGMA_RATIO * last || s.sigma[k].is_nan())
        .and_then(|i| r.samples.get(i + 1))
        .map_or(t0, |s| s.t_s);
    let from = settle.max(converged.min(0.5 * (t0 + t1)));
    let late = r.samples.iter().filter(|s| s.t_s >= from);
    let m = max_abs(late.flat_map(|s| [s.sigma[k], s.delta_x[k] - s.estimate[k]]));
    let m = if m > 0.0 { 1.3 * m } else { 1.0 };
    Axis::linear(
        &format!("{} error", state_name(k)),
        state_unit(k),
        (-m, m),
        7,
    )
}

/// The σ axis of state `k` over the zoom window, fitted to σ there (prior σ at fixes included).
fn sigma_axis(r: &Realization, k: usize, (a, b): (f64, f64)) -> Axis {
    let inside = |t: f64| t >= a && t <= b;
    let values = r
        .samples
        .iter()
        .filter(|s| inside(s.t_s))
        .map(|s| s.sigma[k])
        .chain(
            r.fixes
                .iter()
                .filter(|f| inside(f.t_s))
                .flat_map(|f| [f.sigma_prior[k], f.sigma_post[k]]),
        );
    let range = extent(values).map_or((0.0, 1.0), |e| padded(e, 0.12));
    Axis::linear(&format!("{} σ", state_name(k)), state_unit(k), range, 5)
}
