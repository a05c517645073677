//! The four figures of a calibration's page: the bias, the corrected trajectory, the residuals
//! and the NIS of every fix.

use super::RenderError;
use super::rich::rich;
use super::view::FigureView;
use crate::calibrate::summary::Calibration;
use crate::format::{percent, sig};
use crate::plot;

/// The four figures of the page.
pub fn figures(cal: &Calibration) -> Result<Vec<FigureView>, RenderError> {
    let fig = |id: &str, svg: Result<String, plot::PlotError>| {
        svg.map_err(|source| RenderError::Figure {
            figure: id.to_string(),
            source,
        })
    };
    let n = &cal.summary.nis;
    Ok(vec![
        FigureView {
            id: "fig-bias".into(),
            number: 1,
            title: "The bias estimate".into(),
            caption_html: rich(if cal.summary.filter.bias_model == "constant" {
                "The filtered (a posteriori) bias estimate at each fix and the smoothed one, each \
             with ±1σ; below, the two σ. The smoothed estimate uses every fix, so it holds \
             its final value from the start."
            } else {
                "The filtered (a posteriori) bias estimate at each fix and the smoothed one, each \
             with ±1σ; below, the two σ. The smoothed estimate uses every fix; the bias drifts \
             in the filter's model, so it follows the bias's path, and at the last fix it \
             equals the filtered one."
            }),
            svg: fig("fig-bias", plot::calibration_bias(&cal.fixes))?,
        },
        FigureView {
            id: "fig-trajectory".into(),
            number: 2,
            title: "The corrected trajectory".into(),
            caption_html: rich(
                "Left: velocity and position from the GPS, from the integrated accelerometer \
             (p_{c}, v_{c}) and corrected by the smoothed error estimate (p_{c} + δp̂, \
             v_{c} + δv̂). Right: the integration's drift, GPS minus integration at each fix, \
             with its smoothed estimate ±1σ.",
            ),
            svg: fig("fig-trajectory", plot::calibration_trajectory(&cal.fixes))?,
        },
        FigureView {
            id: "fig-residuals".into(),
            number: 3,
            title: "Residuals".into(),
            caption_html: rich(
                "The residual r = δz − Hδx̂^{−} of each fix within the ±√S and ±2√S the filter \
             predicts for it (the diagonal of S = HP^{−}H^{T} + R).",
            ),
            svg: fig("fig-residuals", plot::calibration_residuals(&cal.fixes))?,
        },
        FigureView {
            id: "fig-nis".into(),
            number: 4,
            title: "Normalized innovations squared".into(),
            caption_html: rich(&format!(
                "The NIS r^{{T}}S^{{−1}}r of each fix, χ²(2) for a consistent filter, with its \
             expected value 2 and the per-fix band [{}, {}] that holds it with probability \
             1 − α = {}; the fixes outside it in vermillion.",
                sig(n.per_fix_lower, 3),
                sig(n.per_fix_upper, 3),
                percent(1.0 - n.false_alarm_rate)
            )),
            svg: fig("fig-nis", plot::calibration_nis(&cal.fixes, n))?,
        },
    ])
}
