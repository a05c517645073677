//! Axes: range, title with its unit and power of ten, tick positions and labels, and the label
//! areas they need.

use std::ops::Range;

use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

use super::text_width;
use super::{AXIS_LABEL_PX, TICK_LABEL_PX};
use crate::format::{fixed, power_of_ten};

/// Length of the tick marks, px; plotters keeps labels two tick lengths from the axis.
pub(crate) const TICK_PX: i32 = 4;

/// The widest range of a linear axis: plotters searches its ticks (for our labels and for the
/// grid it draws itself) from a step of 10^⌊log₁₀ width⌋ down by factors of 10, and when the
/// width overflows (data near ±f64::MAX) that step is ∞ at every turn and the search never ends;
/// near the overflow its remainders overflow too. Far below it, the search ends.
const MAX_WIDTH: f64 = 1e300;

/// One axis: its range, its title, and how its ticks are labelled.
#[derive(Clone, Debug)]
pub(crate) struct Axis {
    name: String,
    unit: String,
    /// Range in plot coordinates: the data, or log10 of the data on a log axis.
    pub(super) range: Range<f64>,
    log10: bool,
    /// A factor axis: log2 of the data, ticks at powers of two.
    log2: bool,
    pub(super) max_ticks: usize,
    /// Linear tick labels are written in units of 10^exponent (the title says so).
    exponent: i32,
    decimals: usize,
}

impl Axis {
    /// A linear axis over `[lo, hi]` (widened when empty or degenerate) with at most `max_ticks`
    /// labelled ticks. `unit` may be empty for a dimensionless quantity.
    pub(crate) fn linear(name: &str, unit: &str, (lo, hi): (f64, f64), max_ticks: usize) -> Self {
        let range = sane_range(lo, hi);
        let mut axis = Axis {
            name: name.to_string(),
            unit: unit.to_string(),
            range,
            log10: false,
            log2: false,
            max_ticks: max_ticks.max(2),
            exponent: 0,
            decimals: 0,
        };
        axis.choose_format();
        axis
    }

    /// A log axis covering the positive values `[lo, hi]`, widened to whole decades.
    pub(crate) fn log10(name: &str, unit: &str, (lo, hi): (f64, f64)) -> Self {
        let (lo, hi) = if lo > 0.0 && hi >= lo && hi.is_finite() {
            (lo, hi)
        } else {
            (0.1, 10.0)
        };
        let a = lo.log10().floor();
        let mut b = hi.log10().ceil();
        if b <= a {
            b = a + 1.0;
        }
        let decades = (b - a) as usize;
        Axis {
            name: name.to_string(),
            unit: unit.to_string(),
            range: a..b,
            log10: true,
            log2: false,
            max_ticks: (decades + 1).min(8),
            exponent: 0,
            decimals: 0,
        }
    }

    /// A factor axis over the positive `[lo, hi]`: logarithmic, with ticks at the powers of two
    /// (labelled 0.25, 0.5, 1, 2, 4, …).
    pub(crate) fn factor(name: &str, (lo, hi): (f64, f64)) -> Self {
        let (lo, hi) = if lo > 0.0 && hi >= lo && hi.is_finite() {
            (lo, hi)
        } else {
            (0.5, 2.0)
        };
        let (a, b) = (lo.log2().floor() - 0.25, hi.log2().ceil() + 0.25);
        Axis {
            name: name.to_string(),
            unit: String::new(),
            range: a..b,
            log10: false,
            log2: true,
            max_ticks: ((b - a) as usize + 1).min(12),
            exponent: 0,
            decimals: 0,
        }
    }

    /// An axis over `[lo, hi]` without ticks, labels or title.
    pub(crate) fn bare((lo, hi): (f64, f64)) -> Self {
        Axis {
            name: String::new(),
            unit: String::new(),
            range: sane_range(lo, hi),
            log10: false,
            log2: false,
            max_ticks: 0,
            exponent: 0,
            decimals: 0,
        }
    }

    /// The axis title, e.g. "position error (10⁻³ m)".
    pub(crate) fn title(&self) -> String {
        match (self.exponent, self.unit.is_empty()) {
            (0, true) => self.name.clone(),
            (0, false) => format!("{} ({})", self.name, self.unit),
            (e, true) => format!("{} (×{})", self.name, power_of_ten(e)),
            (e, false) => format!("{} ({} {})", self.name, power_of_ten(e), self.unit),
        }
    }

    /// The value `v` in plot coordinates: NaN where it cannot be shown (≤ 0 on a log axis).
    pub(crate) fn map(&self, v: f64) -> f64 {
        if !(self.log10 || self.log2) {
            v
        } else if v <= 0.0 {
            f64::NAN
        } else if self.log2 {
            v.log2()
        } else {
            v.log10()
        }
    }

    /// Whether the value `v` is on the axis (not clipped at either end).
    pub(crate) fn shows(&self, v: f64) -> bool {
        let m = self.map(v);
        m >= self.range.start && m <= self.range.end
    }

    /// The range in plot coordinates.
    pub(crate) fn range(&self) -> Range<f64> {
        self.range.clone()
    }

    /// The ticks plotters labels, in plot coordinates.
    pub(super) fn ticks(&self) -> Vec<f64> {
        RangedCoordf64::from(self.range.clone()).key_points(self.max_ticks)
    }

    /// The label of the tick at `v` (plot coordinates).
    pub(super) fn label(&self, v: f64) -> String {
        if self.log2 {
            return crate::format::short(2f64.powf(v));
        }
        if self.log10 {
            let k = v.round();
            if (v - k).abs() < 1e-9 {
                return power_of_ten(k as i32);
            }
            return fixed(10f64.powf(v), 2);
        }
        fixed(v / 10f64.powi(self.exponent), self.decimals)
    }

    /// The widest tick label, px.
    fn label_width(&self) -> f64 {
        self.ticks()
            .iter()
            .map(|&v| text_width(&self.label(v), TICK_LABEL_PX))
            .fold(0.0, f64::max)
    }

    /// Picks the power of ten the labels are written in and the decimals they need.
    fn choose_format(&mut self) {
        let ticks = self.ticks();
        let largest = ticks.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let magnitude = if largest > 0.0 {
            largest.log10().floor() as i32
        } else {
            0
        };
        self.exponent = if (-2..=4).contains(&magnitude) {
            0
        } else {
            magnitude
        };
        let scale = 10f64.powi(self.exponent);
        let step = ticks
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() && step > 0.0 {
            step / scale
        } else {
            (self.range.end - self.range.start).abs() / scale
        };
        self.decimals = (0..=9)
            .find(|&d| {
                let f = 10f64.powi(d);
                ticks.iter().all(|&v| {
                    let x = v / scale * f;
                    (x - x.round()).abs() <= 1e-6 * (step * f).max(1.0)
                })
            })
            .unwrap_or(9) as usize;
    }
}

/// `lo..hi` when it is a finite, non-empty interval; otherwise a small interval around it. Either
/// no wider than [`MAX_WIDTH`]: a wider one has its ends brought in to ±[`MAX_WIDTH`]/2 (data
/// beyond are clipped at the edge), so that the tick search ends.
fn sane_range(lo: f64, hi: f64) -> Range<f64> {
    let range = match (lo.is_finite(), hi.is_finite()) {
        (true, true) if hi > lo => lo..hi,
        (true, true) => {
            let c = 0.5 * (lo + hi);
            let h = if c == 0.0 { 1.0 } else { 0.1 * c.abs() };
            c - h..c + h
        }
        _ => -1.0..1.0,
    };
    if range.end - range.start <= MAX_WIDTH {
        return range;
    }
    let half = MAX_WIDTH / 2.0;
    let (lo, hi) = (range.start.clamp(-half, half), range.end.clamp(-half, half));
    if hi > lo { lo..hi } else { -half..half }
}

/// Width of the left label area that fits the tick labels and the rotated title of every axis
/// in `axes`: panels stacked in one column share it so that their plotting areas line up.
pub(crate) fn y_label_area(axes: &[&Axis]) -> u32 {
    let labels = axes.iter().map(|a| a.label_width()).fold(0.0, f64::max);
    let titled = axes.iter().any(|a| !a.title().is_empty());
    // Rotated title (one line), a gap, the labels, and the tick-to-label distance.
    let title = if titled {
        AXIS_LABEL_PX * 1.3 + 8.0
    } else {
        6.0
    };
    (title + labels + 2.0 * TICK_PX as f64 + 2.0).ceil() as u32
}

/// Height of the bottom label area: tick labels, and the axis title when it is shown.
pub(super) fn x_label_area(with_title: bool) -> u32 {
    let ticks = 2 * TICK_PX as u32 + (TICK_LABEL_PX * 1.25) as u32 + 4;
    if with_title {
        ticks + (AXIS_LABEL_PX * 1.4) as u32 + 2
    } else {
        ticks
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_scaled_and_signed() {
        let a = Axis::linear("bias error", "m/s²", (-0.0012, 0.0012), 6);
        assert_eq!(a.title(), "bias error (10⁻³ m/s²)");
        let labels: Vec<String> = a.ticks().iter().map(|&v| a.label(v)).collect();
        assert!(labels.contains(&"0.0".to_string()), "{labels:?}");
        assert!(labels.contains(&"\u{2212}1.0".to_string()), "{labels:?}");
        let b = Axis::linear("time", "s", (0.0, 30.0), 8);
        let labels: Vec<String> = b.ticks().iter().map(|&v| b.label(v)).collect();
        assert_eq!(labels, ["0", "5", "10", "15", "20", "25", "30"]);
    }

    #[test]
    fn log_axis_labels_are_powers_of_ten() {
        let a = Axis::log10("variance", "m²", (0.003, 40.0));
        assert_eq!(a.range(), -3.0..2.0);
        let labels: Vec<String> = a.ticks().iter().map(|&v| a.label(v)).collect();
        assert_eq!(labels, ["10⁻³", "10⁻²", "10⁻¹", "1", "10", "10²"]);
    }

    use crate::test_support::within_10_s;

    #[test]
    fn ticks_of_any_finite_data_are_found_and_lie_on_the_axis() {
        let max = f64::MAX;
        // (range, whether it must have a tick): plotters finds none on a range narrower than
        // the spacing of the numbers around it, which ends but labels nothing.
        let ranges = [
            ((-1e308, 1e308), true),
            ((-max, max), true),
            ((0.0, max), true),
            ((-max, 0.0), true),
            ((-8e307, 8e307), true),
            ((-1e-300, 1e-300), true),
            ((1e300, 1.000_000_1e300), false),
            ((0.0, 5e-324), false),
            ((1e308, 1e308), false),
        ];
        for ((lo, hi), ticked) in ranges {
            let axis = within_10_s(move || Axis::linear("x", "m", (lo, hi), 6));
            let r = axis.range();
            assert!(r.end - r.start <= MAX_WIDTH, "{r:?}");
            let ticks = within_10_s(move || axis.ticks());
            assert!(!ticked || !ticks.is_empty(), "no tick on [{lo:e}, {hi:e}]");
            for v in ticks {
                assert!(v.is_finite() && r.start <= v && v <= r.end, "{v} on {r:?}");
            }
        }
    }
}
