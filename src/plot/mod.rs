//! The report's figures, drawn by plotters into SVG text.
//!
//! One file per figure family; every public function takes plain data (a [`Realization`] or an
//! [`EnsembleStats`] with its [`Check`]) and returns the SVG document as a string. The shared look
//! lives here as constants: the width, the font, the font sizes and a palette derived from
//! Okabe–Ito's, which stays distinguishable under the common colour-vision deficiencies; every
//! colour a line, marker or text is drawn in reaches 3:1 against white.
//!
//! The output is deterministic: plotters runs without font crates and lays text out with its
//! naive estimate, and every number written is a pixel coordinate computed from the data alone.
//! Non-finite values are never handed to plotters; lines break where data is missing or leave the
//! axes.
//!
//! Each document is [`WIDTH_PX`] wide with a `viewBox`, so a page scales it into its column with
//! `max-width: 100%; height: auto`.
//!
//! [`Realization`]: crate::realization::Realization
//! [`EnsembleStats`]: crate::ensemble::EnsembleStats
//! [`Check`]: crate::checks::Check

use plotters::drawing::DrawingAreaErrorKind;
use plotters::style::{FontDesc, RGBColor, TextStyle};

use crate::state::ErrorState;

mod allan;
mod axis;
mod calibration;
pub mod calibration_imu;
mod cases;
mod consistency;
mod covariance;
mod diagnosis;
mod drift;
mod errors;
mod geometry;
mod ins;
mod intrinsics;
mod legend;
mod markup;
mod mean_error;
mod orthogonality;
mod panel;
mod profile;
mod residuals;
mod sensitivity;
mod trajectory;

pub use allan::{AllanMark, AllanSeries, TERM_COLOURS, TermCurve, allan_deviation};
pub use calibration::{
    calibration_bias, calibration_nis, calibration_residuals, calibration_trajectory,
};
pub use cases::{CaseSeries, accuracy_ratio, mean_error_in_sigma};
pub use consistency::consistency;
pub use covariance::covariance;
pub use diagnosis::{calibration_autocorrelation, calibration_bias_departure};
pub use drift::{DriftSeries, drift_sigma};
pub use errors::realization_errors;
pub use ins::{TraceSeries, ins_trace, ins_track};
pub use intrinsics::{intrinsics_poses, intrinsics_residuals};
pub use mean_error::mean_error;
pub use orthogonality::orthogonality;
pub use profile::{ProfileSeries, RatioSeries, estimate_ratios, likelihood_profile};
pub use residuals::residual_whiteness;
pub use sensitivity::{SensitivitySeries, sigma_ratio};
pub use trajectory::trajectory;

/// Width of every figure, px. The report shows them in a column about 900 px wide, so a figure is
/// scaled by about 0.94 and the font sizes below shrink by as much.
pub const WIDTH_PX: u32 = 960;
/// Font family of all text; the browser resolves it.
pub const FONT_FAMILY: &str = "sans-serif";
/// Panel titles, px.
pub const TITLE_PX: f64 = 17.0;
/// Axis labels ("time (s)"), px: 15 px once the figure is scaled into the report's column.
pub const AXIS_LABEL_PX: f64 = 16.0;
/// Tick labels, px: 13 px once scaled.
pub const TICK_LABEL_PX: f64 = 14.0;
/// Legend entries, px.
pub const LEGEND_PX: f64 = 14.0;

/// Black: text, axes, band edges.
pub const BLACK: RGBColor = RGBColor(0x00, 0x00, 0x00);
/// Dark amber (Okabe–Ito orange #E69F00 darkened to 3.6:1 on white; the original reaches 2.25:1),
/// kept yellower than vermillion so the two stay apart.
pub const ORANGE: RGBColor = RGBColor(0xB0, 0x7D, 0x00);
/// Dark sky blue (Okabe–Ito sky blue #56B4E9 darkened to 3.7:1; the original reaches 2.3:1).
pub const SKY_BLUE: RGBColor = RGBColor(0x3A, 0x8A, 0xCB);
/// Okabe–Ito bluish green (3.4:1).
pub const BLUISH_GREEN: RGBColor = RGBColor(0x00, 0x9E, 0x73);
/// Okabe–Ito blue (5.2:1).
pub const BLUE: RGBColor = RGBColor(0x00, 0x72, 0xB2);
/// Okabe–Ito vermillion (3.9:1): bounds and warnings.
pub const VERMILLION: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
/// Dark reddish purple (Okabe–Ito reddish purple #CC79A7 darkened to 4.5:1; the original
/// reaches 3.06:1, too close to the limit once a thin line is anti-aliased).
pub const REDDISH_PURPLE: RGBColor = RGBColor(0xB4, 0x56, 0x8E);
/// Dark grey: axis frames and secondary text (7.5:1).
pub const GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);
/// Mid grey: reference lines such as zero and an expected value (4.5:1), lighter than the black
/// of band edges.
pub const REFERENCE: RGBColor = RGBColor(0x76, 0x76, 0x76);
/// Light grey: grid lines. The one stroke colour below 3:1, on purpose: the grid is decoration
/// behind the data (the ticks on the frame carry the scale) and must not compete with it.
pub const GRID: RGBColor = RGBColor(0xE3, 0xE3, 0xE3);

/// Every colour figures stroke lines, markers or text with, by name. Each reaches 3:1 against
/// white (WCAG 2 relative luminance); [`GRID`] is left out on purpose (see there).
#[cfg(test)]
pub(crate) const STROKE_COLORS: [(&str, RGBColor); 9] = [
    ("BLACK", BLACK),
    ("ORANGE", ORANGE),
    ("SKY_BLUE", SKY_BLUE),
    ("BLUISH_GREEN", BLUISH_GREEN),
    ("BLUE", BLUE),
    ("VERMILLION", VERMILLION),
    ("REDDISH_PURPLE", REDDISH_PURPLE),
    ("GREY", GREY),
    ("REFERENCE", REFERENCE),
];

/// Why a figure could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// plotters failed to lay out or draw an element.
    #[error("drawing the figure failed: {0}")]
    Drawing(String),
}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PlotError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        PlotError::Drawing(e.to_string())
    }
}

/// The indices of the error state's components, in state order: one panel row each.
pub(crate) fn states() -> std::ops::Range<usize> {
    0..ErrorState::DIM
}

/// Whether state `k` is the last, whose panel carries the time axis.
pub(crate) fn last_state(k: usize) -> bool {
    k + 1 == ErrorState::DIM
}

/// Unit of state component `k` of the error state.
pub(crate) fn state_unit(k: usize) -> &'static str {
    ErrorState::VARIABLES[k].unit
}

/// Name of state component `k` of the error state.
pub(crate) fn state_name(k: usize) -> &'static str {
    ErrorState::VARIABLES[k].key
}

/// `s` with its first letter in upper case, for panel titles.
pub(crate) fn capitalized(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

/// Average advance of a character as a fraction of the font size; generous for the common
/// sans-serif faces (DejaVu Sans digits are 0.64 em, Arial's 0.56 em).
const CHAR_EM: f64 = 0.6;
/// A text style whose glyphs are `px` pixels high in the SVG. plotters' SVG backend writes
/// `font-size = size / 1.24`, so it is handed `px · 1.24`.
pub(crate) fn font(px: f64) -> TextStyle<'static> {
    FontDesc::from((FONT_FAMILY, px * 1.24)).color(&BLACK)
}

/// Estimated width of `text` at `px` pixels, its sub- and superscript markup (`p_{c}`, see
/// [`markup`]) drawn as scripts.
pub(crate) fn text_width(text: &str, px: f64) -> f64 {
    markup::drawn_chars(text) * CHAR_EM * px
}

/// A figure's SVG document, or why it could not be drawn.
pub type PlotResult = Result<String, PlotError>;

#[cfg(test)]
mod tests;
