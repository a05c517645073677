//! The page of `accelcal intrinsics` (its view and its template `intrinsics.html`, on the
//! report's base template and stylesheet): the poses found, where they point, each pose's
//! magnitude against gravity, the parameters with their intervals or "not determined", the
//! goodness tests and what to do next. Pure: HTML out, no IO.

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::view::FigureView;
use super::{RenderError, stylesheet};
use crate::format::{count, interval, sig};
use crate::intrinsics::Intrinsics;
use crate::intrinsics::accel::{Estimate, PARAMETER_NAMES};
use crate::intrinsics::gyro_matrix::MISALIGNMENT_NAMES;
use crate::plot;
use crate::stats::normal_bound;

/// The page.
#[derive(Template)]
#[template(path = "intrinsics.html")]
pub struct IntrinsicsPage<'a> {
    /// The view.
    pub v: &'a IntrinsicsView,
    /// The stylesheet.
    pub style: &'a str,
}

/// One row of a table: a quantity, its value ± σ and its interval, or "not determined".
#[derive(Clone, Debug, Serialize)]
pub struct EstimateRow {
    /// The quantity.
    pub name: String,
    /// Value ± σ with its unit, or "not determined".
    pub value: String,
    /// The interval, or why there is none.
    pub interval: String,
}

/// One static pose.
#[derive(Clone, Debug, Serialize)]
pub struct PoseRow {
    /// Its number.
    pub number: usize,
    /// Its start and end, s.
    pub span: String,
    /// Its mean specific force, m/s².
    pub force: String,
    /// Its normalized residual.
    pub residual: String,
}

/// A goodness test's sentence and verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// What was tested, in words.
    pub sentence: String,
    /// Whether the model was rejected.
    pub rejected: bool,
    /// Whether there was a test at all.
    pub tested: bool,
}

/// Everything the page shows, as text.
#[derive(Clone, Debug, Serialize)]
pub struct IntrinsicsView {
    /// The program's version.
    pub version: String,
    /// The log.
    pub source: String,
    /// Samples, τ₀, duration, poses, in words.
    pub extent: String,
    /// The detector, in words.
    pub detector: String,
    /// The poses.
    pub poses: Vec<PoseRow>,
    /// Where they point.
    pub poses_figure: FigureView,
    /// Their residuals.
    pub residuals_figure: FigureView,
    /// The accelerometers' parameters.
    pub accel: Vec<EstimateRow>,
    /// The gyros' parameters.
    pub gyro: Vec<EstimateRow>,
    /// The goodness tests: magnitudes, static rates, turns.
    pub verdicts: Vec<Verdict>,
    /// What to do next, one sentence each.
    pub next: Vec<String>,
    /// The confidence, %.
    pub confidence: String,
    /// The command that wrote the page.
    pub command: String,
}

/// An estimate's row, its value times `scale` in `unit`.
fn row(name: &str, e: &Estimate, scale: f64, unit: &str) -> EstimateRow {
    if !e.determined {
        return EstimateRow {
            name: name.to_string(),
            value: "not determined".to_string(),
            interval: "the poses leave it free".to_string(),
        };
    }
    let (_, lo, hi) = interval(e.value * scale, e.lower * scale, e.upper * scale, 3);
    EstimateRow {
        name: name.to_string(),
        value: format!(
            "{} ± {} {unit}",
            sig(e.value * scale, 5),
            sig(e.sigma * scale, 2)
        ),
        interval: format!("[{lo}, {hi}] {unit}"),
    }
}

/// The accelerometers' rows.
fn accel_rows(x: &Intrinsics) -> Vec<EstimateRow> {
    let a = &x.accel;
    let z = normal_bound(1.0 - x.settings.confidence);
    let mut rows: Vec<EstimateRow> = (0..3)
        .map(|i| {
            let s = a.covariance[(i, i)].sqrt();
            let e = Estimate {
                value: a.params[i],
                sigma: s,
                lower: a.params[i] - z * s,
                upper: a.params[i] + z * s,
                determined: a.determined[i],
            };
            row(&format!("bias {}", ["x", "y", "z"][i]), &e, 1.0, "m/s²")
        })
        .collect();
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        rows.push(row(
            &format!("scale factor {axis}"),
            &a.scale_ppm[i],
            1.0,
            "ppm",
        ));
    }
    for (i, pair) in ["xy", "xz", "yz"].iter().enumerate() {
        rows.push(row(
            &format!("non-orthogonality {pair}"),
            &a.misalignment_rad[i],
            1e3,
            "mrad",
        ));
    }
    rows
}

/// The gyros' rows.
fn gyro_rows(x: &Intrinsics) -> Vec<EstimateRow> {
    let Some(m) = &x.gyro_matrix else {
        return x
            .gyro
            .bias
            .iter()
            .zip(["x", "y", "z"])
            .map(|(e, a)| row(&format!("bias {a} (static poses)"), e, 1.0, "rad/s"))
            .collect();
    };
    let mut rows: Vec<EstimateRow> = m
        .bias
        .iter()
        .zip(["x", "y", "z"])
        .map(|(e, a)| row(&format!("bias {a}"), e, 1.0, "rad/s"))
        .collect();
    for (e, a) in m.scale_ppm.iter().zip(["x", "y", "z"]) {
        rows.push(row(&format!("scale factor {a}"), e, 1.0, "ppm"));
    }
    for (e, n) in m.misalignment_rad.iter().zip(MISALIGNMENT_NAMES) {
        let (from, to) = n.split_once('_').unwrap_or((n, ""));
        rows.push(row(&format!("lean of {from} towards {to}"), e, 1e3, "mrad"));
    }
    rows
}

/// A goodness test's verdict.
fn verdict(what: &str, chi: f64, dof: f64, p: Option<f64>, alpha: f64) -> Verdict {
    match p {
        Some(p) => Verdict {
            sentence: format!(
                "{what}: χ² = {} on {} degrees of freedom, p = {}, {} at α = {}",
                sig(chi, 4),
                sig(dof, 3),
                sig(p, 3),
                if p < alpha {
                    "rejected"
                } else {
                    "not rejected"
                },
                sig(alpha, 2)
            ),
            rejected: p < alpha,
            tested: true,
        },
        None => Verdict {
            sentence: format!("{what}: not testable, no degree of freedom left"),
            rejected: false,
            tested: false,
        },
    }
}

/// The two figures.
fn figures(x: &Intrinsics) -> Result<(FigureView, FigureView), RenderError> {
    let a = &x.accel;
    let ups: Vec<[f64; 3]> = x
        .detection
        .intervals
        .iter()
        .map(|i| {
            let u = a.correct(&i.mean_specific_force).normalize();
            [u.x, u.y, u.z]
        })
        .collect();
    let poses_figure = figure(
        "intrinsics-poses",
        1,
        "Where the poses point",
        "Each static pose's up direction in the sensor's axes (its corrected mean specific force, normalized) on the two hemispheres, by Lambert's equal-area projection; the outer circle is the equator. Poses spread over both discs determine every parameter; the ringed point is the pose that would best fix those the poses leave free.",
        plot::intrinsics_poses(&ups, a.suggested_up.map(|u| [u.x, u.y, u.z])),
    )?;
    let residuals_figure = figure(
        "intrinsics-residuals",
        2,
        "Each pose's magnitude against gravity",
        "The fitted model's |M(f̄ − b)| − g of each pose divided by its σ (the white noise measured in the log over the pose's samples), against the two-sided 95 % normal bounds. A pose far outside moved, or the sensor drifted while it was held.",
        plot::intrinsics_residuals(&a.residuals, normal_bound(0.05)),
    )?;
    Ok((poses_figure, residuals_figure))
}

/// The poses' rows.
fn pose_rows(x: &Intrinsics) -> Vec<PoseRow> {
    let tau = x.detection.sample_period_s;
    x.detection
        .intervals
        .iter()
        .zip(&x.accel.residuals)
        .enumerate()
        .map(|(k, (i, r))| {
            let f = i.mean_specific_force;
            PoseRow {
                number: k + 1,
                span: format!(
                    "{} – {}",
                    sig(i.first as f64 * tau, 5),
                    sig(i.last as f64 * tau, 5)
                ),
                force: format!("({}, {}, {})", sig(f.x, 5), sig(f.y, 5), sig(f.z, 5)),
                residual: sig(*r, 3),
            }
        })
        .collect()
}

/// The goodness tests' verdicts.
fn verdicts(x: &Intrinsics) -> Vec<Verdict> {
    let a = &x.accel;
    let alpha = x.settings.alpha;
    let mut verdicts = vec![
        verdict(
            "The poses' magnitudes",
            a.chi_squared,
            a.dof,
            a.p_value,
            alpha,
        ),
        verdict(
            "The gyros' rates at rest",
            x.gyro.chi_squared,
            x.gyro.dof as f64,
            x.gyro.p_value,
            alpha,
        ),
    ];
    if let Some(m) = &x.gyro_matrix {
        verdicts.push(verdict(
            &format!(
                "The {} turns between poses and the poses' magnitudes, together",
                m.turns
            ),
            m.chi_squared,
            m.dof,
            m.p_value,
            alpha,
        ));
    }
    verdicts
}

/// What to do next.
fn next_steps(x: &Intrinsics, verdicts: &[Verdict]) -> Vec<String> {
    let a = &x.accel;
    let mut next = Vec::new();
    let free: Vec<&str> = PARAMETER_NAMES
        .iter()
        .zip(a.determined)
        .filter(|(_, d)| !d)
        .map(|(n, _)| *n)
        .collect();
    if let Some(u) = a.suggested_up {
        next.push(format!(
            "The poses leave the accelerometers' {} free: add a pose with the sensor's ({}, {}, {}) pointing up, held still for a few seconds.",
            free.join(", "),
            sig(u.x, 2),
            sig(u.y, 2),
            sig(u.z, 2)
        ));
    }
    if verdicts.iter().any(|v| v.rejected) {
        next.push("A goodness test rejects the model: the intervals hold only if it does. Let the sensor warm up before the session, keep each pose still on a firm table, and record it again.".to_string());
    }
    if next.is_empty() {
        next.push("Every parameter is determined and every test passes: intrinsics.json can correct this sensor's logs.".to_string());
    }
    next
}

/// The view of `x`.
fn view(x: &Intrinsics, source: &str, command: &str) -> Result<IntrinsicsView, RenderError> {
    let d = &x.detection;
    let tau = d.sample_period_s;
    let (poses_figure, residuals_figure) = figures(x)?;
    let verdicts = verdicts(x);
    let next = next_steps(x, &verdicts);
    let confidence = sig(100.0 * x.settings.confidence, 3);
    Ok(IntrinsicsView {
        version: env!("CARGO_PKG_VERSION").to_string(),
        source: source.to_string(),
        extent: format!(
            "{} samples, τ₀ = {} s ({} Hz), {} s; {} static poses",
            count(d.samples as u64),
            sig(tau, 4),
            sig(1.0 / tau, 4),
            sig(d.samples as f64 * tau, 4),
            d.intervals.len()
        ),
        detector: format!(
            "a window of {} s ({} samples), still when its six channels' scatter against the white noise measured in the poses (σ per sample: accelerometers {}, {}, {} m/s²; gyros {}, {}, {} rad/s) stays under the χ² quantile that calls a still window moving at the rate {}; poses at least {} s long",
            sig(d.settings.window_s, 3),
            d.window,
            sig(d.noise_var[0].sqrt(), 3),
            sig(d.noise_var[1].sqrt(), 3),
            sig(d.noise_var[2].sqrt(), 3),
            sig(d.noise_var[3].sqrt(), 3),
            sig(d.noise_var[4].sqrt(), 3),
            sig(d.noise_var[5].sqrt(), 3),
            sig(d.settings.false_alarm, 2),
            sig(d.settings.min_static_s, 3)
        ),
        poses: pose_rows(x),
        poses_figure,
        residuals_figure,
        accel: accel_rows(x),
        gyro: gyro_rows(x),
        verdicts,
        next,
        confidence,
        command: command.to_string(),
    })
}

/// The page of the calibration `x` of the log `source`, written by `command`.
///
/// # Errors
/// [`RenderError`] when a figure cannot be drawn or the template cannot be filled.
pub fn render(x: &Intrinsics, source: &str, command: &str) -> Result<String, RenderError> {
    let v = view(x, source, command)?;
    let style = stylesheet();
    Ok(IntrinsicsPage {
        v: &v,
        style: &style,
    }
    .render()?)
}
