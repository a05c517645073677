//! The figures of a calibration from logs: the bias estimate, the corrected trajectory, the
//! residuals and the NIS of every fix. Each takes the per-fix series of a
//! [`Calibration`](crate::calibrate::summary::Calibration), so a log of any length draws from
//! O(fixes) points.

use plotters::style::{Color, ShapeStyle};

use super::axis::{Axis, y_label_area};
use super::geometry::{Point, extent, padded, settled_from, time_span};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns};
use super::{
    BLACK, BLUE, BLUISH_GREEN, ORANGE, PlotError, PlotResult, VERMILLION, WIDTH_PX, state_name,
    state_unit,
};
use crate::calibrate::NisTest;
use crate::calibrate::summary::FixReport;
use crate::state::{ErrorState, Variable};

/// Height of one row, px.
const ROW_PX: u32 = 260;
/// The bias's index in the state.
const B: usize = ErrorState::BIAS;
/// Measured components M.
const M: usize = ErrorState::MEAS;
/// The measurement's components.
const MEASURED: [Variable; M] = ErrorState::MEASURED;
/// Up to this many fixes are drawn as markers; more as a line through them.
const MAX_MARKERS: usize = 600;

/// Markers at `points`, or a thin line through them when there are too many to tell apart.
fn markers(panel: &Panel<'_>, points: Vec<Point>, style: ShapeStyle) -> Result<(), PlotError> {
    if points.len() <= MAX_MARKERS {
        panel.dots(points, 3, style)
    } else {
        panel.line(points, style.stroke_width(1))
    }
}

/// Heights of `n` stacked rows: the last also holds the time axis.
fn rows_px(n: usize) -> Vec<u32> {
    (0..n)
        .map(|row| ROW_PX + if row + 1 == n { 30 } else { 0 })
        .collect()
}

/// A linear axis fitted to `values`, padded.
fn fitted(name: &str, unit: &str, values: impl IntoIterator<Item = f64>, ticks: usize) -> Axis {
    let range = extent(values).map_or((-1.0, 1.0), |e| padded(e, 0.08));
    Axis::linear(name, unit, range, ticks)
}

/// Top: the bias estimate at every fix, filtered (a posteriori) and smoothed, each with ±1σ.
/// Bottom: the two σ on a log axis. The axes of the top panel are fitted after the first second
/// (or quarter of the log), where the prior's σ has collapsed.
pub fn calibration_bias(fixes: &[FixReport]) -> PlotResult {
    let (t0, t1) = time_span(fixes.iter().map(|f| f.t_s));
    let settle = settled_from(t0, t1);
    let time = Axis::linear("time", "s", (t0, t1), 8);
    let late = || fixes.iter().filter(|f| f.t_s >= settle);
    let bias_axis = fitted(
        state_name(B),
        state_unit(B),
        late().flat_map(|f| {
            let (b, s) = (f.filtered[B], f.filtered_sigma[B]);
            let (bs, ss) = (f.smoothed[B], f.smoothed_sigma[B]);
            [b - s, b + s, bs - ss, bs + ss]
        }),
        6,
    );
    let sigmas = fixes
        .iter()
        .flat_map(|f| [f.filtered_sigma[B], f.smoothed_sigma[B]]);
    let sigma_axis = Axis::log10(
        "σ of the bias",
        state_unit(B),
        extent(sigmas.filter(|s| *s > 0.0)).unwrap_or((1e-4, 1e-1)),
    );
    let y_area_px = y_label_area(&[&bias_axis, &sigma_axis]);
    let legend = [
        Entry::new(
            Swatch::Line(VERMILLION.stroke_width(2)),
            "filtered (a posteriori)",
        ),
        Entry::new(Swatch::Block(ORANGE.mix(0.3).filled()), "filtered ±1σ"),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "smoothed"),
        Entry::new(Swatch::Block(BLUE.mix(0.2).filled()), "smoothed ±1σ"),
    ];
    render_under_legend(&legend, &[ROW_PX, ROW_PX + 30], 0, |parts| {
        draw_bias(parts, fixes, &time, [bias_axis, sigma_axis], y_area_px)
    })
}

/// The two panels of [`calibration_bias`] on `parts`: the estimates with their bands over
/// `axes[0]`, their σ over `axes[1]`.
fn draw_bias(
    parts: &[Area<'_>],
    fixes: &[FixReport],
    time: &Axis,
    [bias_axis, sigma_axis]: [Axis; 2],
    y_area_px: u32,
) -> Result<(), PlotError> {
    let t: Vec<f64> = fixes.iter().map(|f| f.t_s).collect();
    let p = Panel::new(
        &parts[0],
        "Bias estimate at each fix, ±1σ",
        time.clone(),
        bias_axis,
        Layout::titled(y_area_px, false),
    )?;
    let band = |k: &dyn Fn(&FixReport) -> (f64, f64), sign: f64| -> Vec<f64> {
        fixes
            .iter()
            .map(|f| {
                let (x, s) = k(f);
                x + sign * s
            })
            .collect()
    };
    let filtered = |f: &FixReport| (f.filtered[B], f.filtered_sigma[B]);
    let smoothed = |f: &FixReport| (f.smoothed[B], f.smoothed_sigma[B]);
    p.band(
        &t,
        &band(&filtered, -1.0),
        &band(&filtered, 1.0),
        ORANGE.mix(0.3),
    )?;
    p.band(
        &t,
        &band(&smoothed, -1.0),
        &band(&smoothed, 1.0),
        BLUE.mix(0.2),
    )?;
    p.line(
        fixes.iter().map(|f| (f.t_s, f.filtered[B])),
        VERMILLION.stroke_width(2),
    )?;
    p.line(
        fixes.iter().map(|f| (f.t_s, f.smoothed[B])),
        BLUE.stroke_width(2),
    )?;
    let q = Panel::new(
        &parts[1],
        "σ of the bias: filtered and smoothed",
        time.clone(),
        sigma_axis,
        Layout::titled(y_area_px, true),
    )?;
    q.line(
        fixes.iter().map(|f| (f.t_s, f.filtered_sigma[B])),
        VERMILLION.stroke_width(2),
    )?;
    q.line(
        fixes.iter().map(|f| (f.t_s, f.smoothed_sigma[B])),
        BLUE.stroke_width(2),
    )?;
    Ok(())
}

/// Left: velocity and position at every fix — the GPS fix, the integrated accelerometer (eq. 3)
/// and the corrected (smoothed) trajectory. Right: what separates the integration from the
/// truth, δ = GPS − integration at each fix, with the smoothed estimate of the drift and ±1σ.
pub fn calibration_trajectory(fixes: &[FixReport]) -> PlotResult {
    let (t0, t1) = time_span(fixes.iter().map(|f| f.t_s));
    let time = Axis::linear("time", "s", (t0, t1), 6);
    let left: Vec<Axis> = TRAJECTORY_ROWS
        .iter()
        .map(|&r| {
            let m = r.gps;
            fitted(
                r.name(),
                r.unit(),
                fixes
                    .iter()
                    .flat_map(|f| [f.z[m], f.integrated[m], corrected(f, r)]),
                6,
            )
        })
        .collect();
    let right: Vec<Axis> = TRAJECTORY_ROWS
        .iter()
        .map(|&r| {
            let (m, k) = (r.gps, r.state);
            fitted(
                &format!("{} drift", r.name()),
                r.unit(),
                fixes.iter().flat_map(|f| {
                    let (x, s) = (f.smoothed[k], f.smoothed_sigma[k]);
                    [f.z[m] - f.integrated[m], x - s, x + s]
                }),
                6,
            )
        })
        .collect();
    let y_areas_px = [
        y_label_area(&left.iter().collect::<Vec<_>>()),
        y_label_area(&right.iter().collect::<Vec<_>>()),
    ];
    let legend = [
        Entry::new(Swatch::Marker(BLACK.filled()), "GPS fix"),
        Entry::new(
            Swatch::Line(ORANGE.stroke_width(2)),
            "integrated accelerometer",
        ),
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "corrected (smoothed)"),
        Entry::new(Swatch::Block(BLUE.mix(0.2).filled()), "smoothed ±1σ"),
    ];
    render_under_legend(&legend, &rows_px(TRAJECTORY_ROWS.len()), 0, |parts| {
        for (row, area) in parts.iter().enumerate() {
            let axes = [left[row].clone(), right[row].clone()];
            draw_trajectory_row(area, fixes, row, (&time, axes), y_areas_px)?;
        }
        Ok(())
    })
}

/// The rows of [`calibration_trajectory`]: the GPS component (of z and of the integration) and
/// the error-state component that corrects it.
const TRAJECTORY_ROWS: [Row; 2] = [
    Row {
        gps: ErrorState::GPS_VELOCITY,
        state: ErrorState::VELOCITY,
    },
    Row {
        gps: ErrorState::GPS_POSITION,
        state: ErrorState::POSITION,
    },
];

/// A measured component and the state that corrects it.
#[derive(Clone, Copy)]
struct Row {
    gps: usize,
    state: usize,
}

impl Row {
    /// The quantity's name (`velocity`), from the state's variable.
    fn name(self) -> &'static str {
        state_name(self.state)
    }

    /// Its unit.
    fn unit(self) -> &'static str {
        state_unit(self.state)
    }
}

/// The corrected (smoothed) trajectory of row `r` at a fix: the integration plus the smoothed
/// error.
fn corrected(f: &FixReport, r: Row) -> f64 {
    f.integrated[r.gps] + f.smoothed[r.state]
}

/// Row `row` of [`calibration_trajectory`] on `area`: left, the GPS fix, the integration and the
/// corrected trajectory over `axes[0]`; right, the drift of the integration over `axes[1]`.
fn draw_trajectory_row(
    area: &Area<'_>,
    fixes: &[FixReport],
    row: usize,
    (time, [left, right]): (&Axis, [Axis; 2]),
    [left_px, right_px]: [u32; 2],
) -> Result<(), PlotError> {
    let r = TRAJECTORY_ROWS[row];
    let (m, k, name) = (r.gps, r.state, r.name());
    let last = row == TRAJECTORY_ROWS.len() - 1;
    let t: Vec<f64> = fixes.iter().map(|f| f.t_s).collect();
    let cols = columns(area, &[WIDTH_PX / 2]);
    let p = Panel::new(
        &cols[0],
        &format!("{}: GPS, integrated, corrected", super::capitalized(name)),
        time.clone(),
        left,
        Layout::titled(left_px, last),
    )?;
    p.line(
        fixes.iter().map(|f| (f.t_s, f.integrated[m])),
        ORANGE.stroke_width(2),
    )?;
    p.line(
        fixes.iter().map(|f| (f.t_s, corrected(f, r))),
        BLUE.stroke_width(2),
    )?;
    markers(
        &p,
        fixes.iter().map(|f| (f.t_s, f.z[m])).collect(),
        BLACK.filled(),
    )?;
    let q = Panel::new(
        &cols[1],
        &format!("{} drift of the integration", super::capitalized(name)),
        time.clone(),
        right,
        Layout::titled(right_px, last),
    )?;
    let lo: Vec<f64> = fixes
        .iter()
        .map(|f| f.smoothed[k] - f.smoothed_sigma[k])
        .collect();
    let hi: Vec<f64> = fixes
        .iter()
        .map(|f| f.smoothed[k] + f.smoothed_sigma[k])
        .collect();
    q.band(&t, &lo, &hi, BLUE.mix(0.2))?;
    markers(
        &q,
        fixes
            .iter()
            .map(|f| (f.t_s, f.z[m] - f.integrated[m]))
            .collect(),
        BLACK.filled(),
    )?;
    q.line(
        fixes.iter().map(|f| (f.t_s, f.smoothed[k])),
        BLUE.stroke_width(2),
    )?;
    Ok(())
}

/// The residual r = δz − H·δx̂⁻ of every fix, position and velocity, within the ±√S the filter
/// predicts for it (±1σ and ±2σ). Axes are fitted after the first second, as the prior's σ
/// makes the first residuals large.
pub fn calibration_residuals(fixes: &[FixReport]) -> PlotResult {
    let (t0, t1) = time_span(fixes.iter().map(|f| f.t_s));
    let settle = settled_from(t0, t1);
    let time = Axis::linear("time", "s", (t0, t1), 8);
    let names: [String; M] = std::array::from_fn(|k| format!("{} residual", MEASURED[k].key));
    let axes: Vec<Axis> = (0..M)
        .map(|k| {
            fitted(
                &names[k],
                MEASURED[k].unit,
                fixes.iter().filter(|f| f.t_s >= settle).flat_map(|f| {
                    let s = f.residual_sigma[k];
                    [f.residual[k], -2.0 * s, 2.0 * s]
                }),
                6,
            )
        })
        .collect();
    let y_area_px = y_label_area(&axes.iter().collect::<Vec<_>>());
    let legend = [
        Entry::new(Swatch::Marker(BLUE.filled()), "residual r"),
        Entry::new(Swatch::Block(ORANGE.mix(0.35).filled()), "±√S (1σ)"),
        Entry::new(Swatch::Block(ORANGE.mix(0.15).filled()), "±2√S"),
    ];
    render_under_legend(&legend, &rows_px(M), 0, |parts| {
        let t: Vec<f64> = fixes.iter().map(|f| f.t_s).collect();
        for k in 0..M {
            let p = Panel::new(
                &parts[k],
                &format!("{} at each fix", super::capitalized(&names[k])),
                time.clone(),
                axes[k].clone(),
                Layout::titled(y_area_px, k + 1 == M),
            )?;
            let s: Vec<f64> = fixes.iter().map(|f| f.residual_sigma[k]).collect();
            let scaled = |c: f64| s.iter().map(|v| c * v).collect::<Vec<_>>();
            p.band(&t, &scaled(-2.0), &scaled(2.0), ORANGE.mix(0.15))?;
            p.band(&t, &scaled(-1.0), &scaled(1.0), ORANGE.mix(0.35))?;
            p.hline(0.0, BLACK.mix(0.5).stroke_width(1))?;
            markers(
                &p,
                fixes.iter().map(|f| (f.t_s, f.residual[k])).collect(),
                BLUE.filled(),
            )?;
        }
        Ok(())
    })
}

/// The NIS rᵀS⁻¹r of every fix on a log axis, against its expected value M and the per-fix χ²(M)
/// band of `test`, the fixes outside it in vermillion; the title gives the test of the whole
/// sequence.
pub fn calibration_nis(fixes: &[FixReport], test: &NisTest) -> PlotResult {
    let (t0, t1) = time_span(fixes.iter().map(|f| f.t_s));
    let time = Axis::linear("time", "s", (t0, t1), 8);
    let values = fixes
        .iter()
        .map(|f| f.nis)
        .chain([test.per_fix_lower, test.per_fix_upper])
        .filter(|v| *v > 0.0);
    let axis = Axis::log10("NIS", "", extent(values).unwrap_or((1e-3, 10.0)));
    let y_area_px = y_label_area(&[&axis]);
    let legend = [
        Entry::new(Swatch::Marker(BLUISH_GREEN.filled()), "NIS of a fix"),
        Entry::new(Swatch::Marker(VERMILLION.filled()), "outside the band"),
        Entry::new(
            Swatch::Line(BLACK.mix(0.4).stroke_width(1)),
            format!("expected value {M}"),
        ),
        Entry::new(
            Swatch::Line(BLACK.stroke_width(1)),
            format!("per-fix χ²({M}) band"),
        ),
    ];
    render_under_legend(&legend, &[ROW_PX + 30], 0, |parts| {
        let p = Panel::new(
            &parts[0],
            &format!(
                "NIS per fix; mean {:.3} over {} fixes, sequence test: {}",
                test.mean, test.fixes, test.verdict
            ),
            time,
            axis,
            Layout::titled(y_area_px, true),
        )?;
        p.hline(M as f64, BLACK.mix(0.4).stroke_width(1))?;
        p.hline(test.per_fix_lower, BLACK.stroke_width(1))?;
        p.hline(test.per_fix_upper, BLACK.stroke_width(1))?;
        let inside = |f: &&FixReport| (test.per_fix_lower..=test.per_fix_upper).contains(&f.nis);
        let (within, outside): (Vec<&FixReport>, Vec<&FixReport>) = fixes.iter().partition(inside);
        let at = |f: Vec<&FixReport>| f.iter().map(|f| (f.t_s, f.nis)).collect();
        markers(&p, at(within), BLUISH_GREEN.filled())?;
        // Drawn last and always as markers: the few fixes the diagnosis names by time.
        p.dots(at(outside), 3, VERMILLION.filled())
    })
}
