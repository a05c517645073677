//! The report's figures, drawn by plotters into SVG text.
//!
//! One file per figure family; every public function takes plain data (a [`Realization`] or an
//! [`EnsembleStats`] with its [`Check`]) and returns the SVG document as a string. The shared look
//! lives here as constants: the width, the font, the font sizes and an Okabe–Ito palette, which
//! stays distinguishable under the common colour-vision deficiencies.
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
use plotters::style::RGBColor;

mod consistency;
mod covariance;
mod errors;
mod mean_error;
mod orthogonality;
mod panel;
mod residuals;
mod trajectory;
mod truth_models;

pub use consistency::consistency;
pub use covariance::covariance;
pub use errors::realization_errors;
pub use mean_error::mean_error;
pub use orthogonality::orthogonality;
pub use residuals::residual_whiteness;
pub use trajectory::trajectory;
pub use truth_models::truth_models;

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

/// Okabe–Ito black: text, axes, reference lines.
pub const BLACK: RGBColor = RGBColor(0x00, 0x00, 0x00);
/// Okabe–Ito orange.
pub const ORANGE: RGBColor = RGBColor(0xE6, 0x9F, 0x00);
/// Okabe–Ito sky blue.
pub const SKY_BLUE: RGBColor = RGBColor(0x56, 0xB4, 0xE9);
/// Okabe–Ito bluish green.
pub const BLUISH_GREEN: RGBColor = RGBColor(0x00, 0x9E, 0x73);
/// Okabe–Ito yellow.
pub const YELLOW: RGBColor = RGBColor(0xF0, 0xE4, 0x42);
/// Okabe–Ito blue.
pub const BLUE: RGBColor = RGBColor(0x00, 0x72, 0xB2);
/// Okabe–Ito vermillion: bounds and warnings.
pub const VERMILLION: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
/// Okabe–Ito reddish purple.
pub const REDDISH_PURPLE: RGBColor = RGBColor(0xCC, 0x79, 0xA7);
/// Dark grey: axis frames and secondary text.
pub const GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);
/// Light grey: grid lines.
pub const GRID: RGBColor = RGBColor(0xE3, 0xE3, 0xE3);

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

/// Units of the error-state components δp, δv, b, in state order.
pub(crate) const STATE_UNITS: [&str; 3] = ["m", "m/s", "m/s²"];

/// `s` with its first letter in upper case, for panel titles.
pub(crate) fn capitalized(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

/// A figure's SVG document, or why it could not be drawn.
pub type PlotResult = Result<String, PlotError>;

#[cfg(test)]
mod tests;
