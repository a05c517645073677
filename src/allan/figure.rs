//! The log–log Allan plot as SVG text: the deviation with its interval whiskers, each resolved
//! term as a line labelled with its slope, and the fitted sum. Plain data in, SVG out; the look
//! (width, font, palette) is the report's ([`crate::plot`]).

use std::fmt::Write as _;

use plotters::style::RGBColor;

use super::{Analysis, Term};
use crate::format::power_of_ten;
use crate::plot::{
    AXIS_LABEL_PX, BLACK, BLUE, BLUISH_GREEN, FONT_FAMILY, GREY, GRID, REDDISH_PURPLE,
    TICK_LABEL_PX, VERMILLION, WIDTH_PX,
};

const HEIGHT_PX: f64 = 540.0;
const LEFT_PX: f64 = 96.0;
const RIGHT_PX: f64 = 24.0;
const TOP_PX: f64 = 20.0;
const BOTTOM_PX: f64 = 64.0;

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// Decades spanned by the data on each axis, and the mapping to pixels.
struct Frame {
    x: (f64, f64),
    y: (f64, f64),
}

impl Frame {
    fn px(&self, tau_s: f64, sigma: f64) -> (f64, f64) {
        let w = WIDTH_PX as f64 - LEFT_PX - RIGHT_PX;
        let h = HEIGHT_PX - TOP_PX - BOTTOM_PX;
        let fx = (tau_s.log10() - self.x.0) / (self.x.1 - self.x.0);
        let fy = (sigma.log10() - self.y.0) / (self.y.1 - self.y.0);
        (LEFT_PX + fx * w, TOP_PX + (1.0 - fy) * h)
    }

    fn contains(&self, sigma: f64) -> bool {
        sigma > 0.0 && (self.y.0..=self.y.1).contains(&sigma.log10())
    }
}

fn frame(a: &Analysis) -> Frame {
    let taus = a.points.iter().map(|p| p.tau_s);
    let lows = a.points.iter().map(|p| p.interval.map_or(p.adev, |i| i.0));
    let highs = a.points.iter().map(|p| p.interval.map_or(p.adev, |i| i.1));
    let decade = |v: f64| v.log10();
    let x0 = taus
        .clone()
        .map(decade)
        .fold(f64::INFINITY, f64::min)
        .floor();
    let x1 = taus.map(decade).fold(f64::NEG_INFINITY, f64::max).ceil();
    let y0 = lows
        .filter(|v| *v > 0.0)
        .map(decade)
        .fold(f64::INFINITY, f64::min)
        .floor();
    let y1 = highs.map(decade).fold(f64::NEG_INFINITY, f64::max).ceil();
    Frame {
        x: (x0, x1.max(x0 + 1.0)),
        y: (y0, y1.max(y0 + 1.0)),
    }
}

fn axes(svg: &mut String, f: &Frame) {
    let (right, bottom) = (WIDTH_PX as f64 - RIGHT_PX, HEIGHT_PX - BOTTOM_PX);
    let grid = hex(GRID);
    for k in f.x.0 as i32..=f.x.1 as i32 {
        let (x, _) = f.px(10f64.powi(k), 10f64.powf(f.y.0));
        let _ = write!(
            svg,
            r#"<line x1="{x:.1}" y1="{TOP_PX}" x2="{x:.1}" y2="{bottom}" stroke="{grid}"/><text x="{x:.1}" y="{:.1}" text-anchor="middle" font-size="{TICK_LABEL_PX}">{}</text>"#,
            bottom + 20.0,
            power_of_ten(k)
        );
    }
    for k in f.y.0 as i32..=f.y.1 as i32 {
        let (_, y) = f.px(10f64.powf(f.x.0), 10f64.powi(k));
        let _ = write!(
            svg,
            r#"<line x1="{LEFT_PX}" y1="{y:.1}" x2="{right}" y2="{y:.1}" stroke="{grid}"/><text x="{:.1}" y="{:.1}" text-anchor="end" font-size="{TICK_LABEL_PX}">{}</text>"#,
            LEFT_PX - 6.0,
            y + 5.0,
            power_of_ten(k)
        );
    }
    let _ = write!(
        svg,
        r#"<rect x="{LEFT_PX}" y="{TOP_PX}" width="{:.1}" height="{:.1}" fill="none" stroke="{}"/><text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="{AXIS_LABEL_PX}">averaging time τ (s)</text><text transform="translate(22 {:.1}) rotate(-90)" text-anchor="middle" font-size="{AXIS_LABEL_PX}">Allan deviation σ(τ) (m/s²)</text>"#,
        right - LEFT_PX,
        bottom - TOP_PX,
        hex(GREY),
        (LEFT_PX + right) / 2.0,
        HEIGHT_PX - 16.0,
        (TOP_PX + bottom) / 2.0
    );
}

/// A polyline of σ(τ) over the frame's τ, broken where it leaves the axes.
fn curve(svg: &mut String, f: &Frame, sigma: impl Fn(f64) -> f64, style: &str) {
    let mut path = String::new();
    let mut pen_down = false;
    for i in 0..=200 {
        let tau = 10f64.powf(f.x.0 + (f.x.1 - f.x.0) * i as f64 / 200.0);
        let s = sigma(tau);
        if !f.contains(s) {
            pen_down = false;
            continue;
        }
        let (x, y) = f.px(tau, s);
        let _ = write!(path, "{}{x:.1},{y:.1} ", if pen_down { "L" } else { "M" });
        pen_down = true;
    }
    let _ = write!(svg, r#"<path d="{path}" fill="none" {style}/>"#);
}

/// The label of a term's line.
fn term_label(term: Term) -> &'static str {
    match term {
        Term::Quantization => "Q: slope −1",
        Term::VelocityRandomWalk => "N: slope −½",
        Term::BiasInstability => "B: slope 0",
        Term::AccelerationRandomWalk => "K: slope +½",
    }
}

fn term_lines(svg: &mut String, f: &Frame, a: &Analysis) {
    for t in &a.fit.terms {
        if t.value.is_none() {
            continue;
        }
        let c = hex(term_colour(t.term));
        let theta = t.squared;
        let sigma = |tau: f64| (theta * t.term.coefficient(tau)).sqrt();
        curve(
            svg,
            f,
            sigma,
            &format!(r#"stroke="{c}" stroke-width="2" stroke-dasharray="7 4""#),
        );
        // The label sits where the term's line crosses the middle third of the τ axis.
        let tau = 10f64.powf(f.x.0 + (f.x.1 - f.x.0) * label_position(t.term));
        if f.contains(sigma(tau)) {
            let (x, y) = f.px(tau, sigma(tau));
            // Above a falling line, below a rising one: clear of the data either way.
            let dy = if t.term.slope() > 0.0 { 26.0 } else { -10.0 };
            let _ = write!(
                svg,
                r#"<text x="{x:.1}" y="{:.1}" fill="{c}" font-size="{TICK_LABEL_PX}">{}</text>"#,
                y + dy,
                term_label(t.term)
            );
        }
    }
}

fn term_colour(term: Term) -> RGBColor {
    match term {
        Term::Quantization => VERMILLION,
        Term::VelocityRandomWalk => REDDISH_PURPLE,
        Term::BiasInstability => BLUE,
        Term::AccelerationRandomWalk => BLUISH_GREEN,
    }
}

fn label_position(term: Term) -> f64 {
    match term {
        Term::Quantization => 0.05,
        Term::VelocityRandomWalk => 0.2,
        Term::BiasInstability => 0.5,
        Term::AccelerationRandomWalk => 0.75,
    }
}

fn data(svg: &mut String, f: &Frame, a: &Analysis) {
    let ink = hex(BLACK);
    for p in &a.points {
        if let Some((lo, hi)) = p.interval
            && f.contains(lo)
            && f.contains(hi)
        {
            let (x, y0) = f.px(p.tau_s, lo);
            let (_, y1) = f.px(p.tau_s, hi);
            let _ = write!(
                svg,
                r#"<path d="M{x:.1},{y0:.1}L{x:.1},{y1:.1}M{:.1},{y0:.1}h8M{:.1},{y1:.1}h8" stroke="{ink}"/>"#,
                x - 4.0,
                x - 4.0
            );
        }
        if f.contains(p.adev) {
            let (x, y) = f.px(p.tau_s, p.adev);
            let _ = write!(
                svg,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{ink}"/>"#
            );
        }
    }
}

/// The Allan plot of an analysis.
pub fn allan_plot(a: &Analysis) -> String {
    let f = frame(a);
    let mut svg = format!(
        r#"<svg viewBox="0 0 {WIDTH_PX} {HEIGHT_PX}" width="{WIDTH_PX}" height="{HEIGHT_PX}" font-family="{FONT_FAMILY}" role="img" aria-label="Allan deviation against averaging time, log–log">"#
    );
    axes(&mut svg, &f);
    term_lines(&mut svg, &f, a);
    curve(
        &mut svg,
        &f,
        |tau| a.fit.avar_at(tau).max(0.0).sqrt(),
        &format!(r#"stroke="{}" stroke-width="1.5""#, hex(GREY)),
    );
    data(&mut svg, &f, a);
    svg.push_str("</svg>");
    svg
}
