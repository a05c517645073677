//! The vehicle's motion in one realization, and the drift of the integrated accelerometer that the
//! filter estimates.

use plotters::style::Color;

use super::axis::{Axis, y_label_area};
use super::geometry::{before, clipped_until, extent, padded, settled_from, time_span};
use super::legend::{Entry, Swatch, render_under_legend};
use super::panel::{Area, Layout, Panel, columns};
use super::{
    BLUE, BLUISH_GREEN, PlotError, PlotResult, VERMILLION, WIDTH_PX, state_name, state_unit,
};
use crate::realization::{Realization, SampleRecord};
use crate::state::ErrorState;

/// Height of one row, px.
const ROW_PX: u32 = 250;

/// Left: the true acceleration a(t), and the true velocity and position with the integrated
/// accelerometer's (eq. 3) on top. Right: what separates them — the accelerometer bias and the
/// drifts δv = v − v_c, δp = p − p_c — each with the filter's estimate.
///
/// The estimates start at zero, far from a truth drawn from the prior, so the right-hand axes are
/// fitted to the truth over the run and to the estimates after the first second; a panel whose
/// estimate runs off its axis says until when in its title ("clipped before 1.6 s").
pub fn trajectory(r: &Realization) -> PlotResult {
    let s = &r.samples;
    let (t0, t1) = time_span(s.iter().map(|x| x.t_s));
    let time = Axis::linear("time", "s", (t0, t1), 7);
    let left = motion_axes(s);
    let right = drift_axes(s, settled_from(t0, t1));
    // Right-hand titles, with what the axis clips of the estimate (the truth is always in).
    let titles_right: Vec<String> = DRIFT_TITLES
        .iter()
        .zip(&right)
        .zip(DRIFT_INDEX)
        .map(|(((full, short), axis), k)| {
            match clipped_until(s.iter().map(|x| (x.t_s, x.estimate[k])), |v| axis.shows(v)) {
                Some(t) => format!("{short} (off the axis {})", before(t)),
                None => full.to_string(),
            }
        })
        .collect();
    let y_areas_px = [
        y_label_area(&left.iter().collect::<Vec<_>>()),
        y_label_area(&right.iter().collect::<Vec<_>>()),
    ];

    let legend = [
        Entry::new(Swatch::Line(BLUE.stroke_width(2)), "truth"),
        Entry::new(
            Swatch::Line(BLUISH_GREEN.stroke_width(2)),
            "integrated accelerometer",
        ),
        Entry::new(Swatch::Line(VERMILLION.stroke_width(2)), "filter estimate"),
    ];
    // The last row also holds the time axis's tick labels.
    let heights: [u32; ROWS] =
        std::array::from_fn(|row| ROW_PX + if row + 1 == ROWS { 24 } else { 0 });
    render_under_legend(&legend, &heights, 6, |parts| {
        for (row, area) in parts.iter().enumerate() {
            let axes = [left[row].clone(), right[row].clone()];
            let title = titles_right[row].as_str();
            draw_row(area, s, row, (&time, axes, title), y_areas_px)?;
        }
        Ok(())
    })
}

/// The state component of each right-hand row: bias, velocity, position.
const DRIFT_INDEX: [usize; ROWS] = [ErrorState::BIAS, ErrorState::VELOCITY, ErrorState::POSITION];
/// Rows of the figure: acceleration, velocity, position.
const ROWS: usize = 3;
// One right-hand row per state: a new state needs its row here (its DRIFT_INDEX entry, its
// DRIFT_TITLES pair and the left-hand panel of motion_axes) before the program compiles again.
const _: () = assert!(
    ErrorState::DIM == ROWS,
    "plot/trajectory.rs: the trajectory figure draws one row per state; add the new state's row"
);

/// The right-hand titles: in full, and shortened for a note on what the axis clips.
const DRIFT_TITLES: [(&str, &str); ROWS] = [
    (
        "Accelerometer bias b and its estimate",
        "Bias b and its estimate",
    ),
    (
        "Velocity drift δv = v − v_{c} and estimate",
        "Velocity drift δv = v − v_{c}",
    ),
    (
        "Position drift δp = p − p_{c} and estimate",
        "Position drift δp = p − p_{c}",
    ),
];

/// A linear axis fitted to `values`, padded by 6 %.
fn fitted(name: &str, unit: &str, values: Vec<f64>) -> Axis {
    let range = extent(values).map_or((-1.0, 1.0), |e| padded(e, 0.06));
    Axis::linear(name, unit, range, 6)
}

/// The left-hand axes: acceleration, velocity and position, fitted to the truth and the
/// integration.
fn motion_axes(s: &[SampleRecord]) -> [Axis; ROWS] {
    [
        // The bias is an acceleration, and δv, δp have the units of v, p.
        fitted(
            "acceleration",
            state_unit(ErrorState::BIAS),
            s.iter().map(|x| x.accel_m_s2).collect(),
        ),
        fitted(
            state_name(ErrorState::VELOCITY),
            state_unit(ErrorState::VELOCITY),
            s.iter()
                .flat_map(|x| [x.truth_v_m_s, x.computed_v_m_s])
                .collect(),
        ),
        fitted(
            state_name(ErrorState::POSITION),
            state_unit(ErrorState::POSITION),
            s.iter()
                .flat_map(|x| [x.truth_p_m, x.computed_p_m])
                .collect(),
        ),
    ]
}

/// The right-hand axes: bias, velocity drift and position drift, fitted to the truth over the
/// run and to the estimate from `settle` on.
fn drift_axes(s: &[SampleRecord], settle: f64) -> [Axis; ROWS] {
    let drift = |k: usize| format!("{} drift", state_name(k));
    let drift_axis = |k: usize, name: String| {
        let values = s
            .iter()
            .map(|x| x.delta_x[k])
            .chain(s.iter().filter(|x| x.t_s >= settle).map(|x| x.estimate[k]))
            .collect::<Vec<_>>();
        let range = extent(values).map_or((-1.0, 1.0), |e| padded(e, 0.12));
        Axis::linear(&name, state_unit(k), range, 6)
    };
    [
        drift_axis(ErrorState::BIAS, state_name(ErrorState::BIAS).to_string()),
        drift_axis(ErrorState::VELOCITY, drift(ErrorState::VELOCITY)),
        drift_axis(ErrorState::POSITION, drift(ErrorState::POSITION)),
    ]
}

/// Row `row` of [`trajectory`] on `area`: left, the truth and the integration over `axes[0]`;
/// right, the drift (or bias) and its estimate over `axes[1]`, titled `title_right`.
fn draw_row(
    area: &Area<'_>,
    s: &[SampleRecord],
    row: usize,
    (time, [left, right], title_right): (&Axis, [Axis; 2], &str),
    [left_px, right_px]: [u32; 2],
) -> Result<(), PlotError> {
    let titles_left = [
        "True acceleration a(t)",
        "Velocity: truth v and integrated v_{c}",
        "Position: truth p and integrated p_{c}",
    ];
    type Series = fn(&SampleRecord) -> f64;
    let truth: [Series; ROWS] = [|x| x.accel_m_s2, |x| x.truth_v_m_s, |x| x.truth_p_m];
    let computed: [Option<Series>; ROWS] =
        [None, Some(|x| x.computed_v_m_s), Some(|x| x.computed_p_m)];
    let cols = columns(area, &[WIDTH_PX / 2]);
    let layout = |y_area_px| Layout::titled(y_area_px, row + 1 == ROWS);
    let p = Panel::new(
        &cols[0],
        titles_left[row],
        time.clone(),
        left,
        layout(left_px),
    )?;
    if let Some(c) = computed[row] {
        p.line(
            s.iter().map(|x| (x.t_s, c(x))),
            BLUISH_GREEN.stroke_width(2),
        )?;
    }
    p.line(
        s.iter().map(|x| (x.t_s, truth[row](x))),
        BLUE.stroke_width(2),
    )?;

    let k = DRIFT_INDEX[row];
    let q = Panel::new(&cols[1], title_right, time.clone(), right, layout(right_px))?;
    q.line(
        s.iter().map(|x| (x.t_s, x.delta_x[k])),
        BLUE.stroke_width(2),
    )?;
    q.line(
        s.iter().map(|x| (x.t_s, x.estimate[k])),
        VERMILLION.stroke_width(1),
    )?;
    Ok(())
}
