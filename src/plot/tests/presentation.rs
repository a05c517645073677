//! How the figures read: contrast of every colour, real sub- and superscripts, no seams in the
//! whiteness map, labels clear of the data, titles that say what an axis clips.

use plotters::style::RGBColor;

use super::*;
use crate::state::ErrorState;

/// No figure shows ASCII sub- or superscript notation ("e_ave", "t^2") or markup left
/// unconverted ("p_{c}"): scripts are `<tspan>`s, shifted and smaller.
#[test]
fn figure_text_has_no_ascii_scripts() {
    let study = small_study();
    let mut scripts = 0;
    for case in Case::REPORT {
        for (name, svg) in figures_of(study, case) {
            for t in texts(&svg) {
                let chars: Vec<char> = t.chars().collect();
                let ascii = chars
                    .windows(2)
                    .any(|w| w[0].is_alphabetic() && (w[1] == '_' || w[1] == '^'));
                assert!(
                    !ascii && !t.contains(['{', '}', '_', '^']),
                    "{name}: {t:?} holds ASCII script notation or markup"
                );
            }
            scripts += svg.matches("<tspan dy=").count();
        }
    }
    assert!(scripts > 20, "only {scripts} script tspans");
    // The covariance figure writes P^{ave}: a raised, smaller "ave" after "P".
    let covariance = &figures(study)
        .into_iter()
        .find(|(n, _)| *n == "covariance")
        .unwrap()
        .1;
    assert!(
        covariance.contains(">P<tspan dy=\"-"),
        "no superscript after P"
    );
}

/// WCAG 2 relative luminance of an sRGB colour.
fn luminance(c: RGBColor) -> f64 {
    let lin = |v: u8| {
        let v = f64::from(v) / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * lin(c.0) + 0.7152 * lin(c.1) + 0.0722 * lin(c.2)
}

/// WCAG 2 contrast ratio of `c` against white.
fn contrast_on_white(c: RGBColor) -> f64 {
    1.05 / (luminance(c) + 0.05)
}

/// `c` painted with `opacity` over white.
fn over_white(c: RGBColor, opacity: f64) -> RGBColor {
    let mix = |v: u8| (opacity * f64::from(v) + (1.0 - opacity) * 255.0).round() as u8;
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}

/// `#RRGGBB`, or None ("none", or anything else).
fn hex(s: &str) -> Option<RGBColor> {
    let s = s.strip_prefix('#').filter(|s| s.len() == 6)?;
    let v = |i: usize| u8::from_str_radix(s.get(i..i + 2)?, 16).ok();
    Some(RGBColor(v(0)?, v(2)?, v(4)?))
}

#[test]
fn stroke_colours_reach_three_to_one_on_white() {
    for (name, c) in STROKE_COLORS {
        let r = contrast_on_white(c);
        assert!(r >= 3.0, "{name} reaches only {r:.2}:1 against white");
    }
    // The test would see the Okabe–Ito orange and sky blue these replace.
    assert!(contrast_on_white(RGBColor(0xE6, 0x9F, 0x00)) < 3.0);
    assert!(contrast_on_white(RGBColor(0x56, 0xB4, 0xE9)) < 3.0);
}

/// Every line, marker and text of every figure, as painted over white (opacity included),
/// reaches 3:1. Exempt: grid lines, and areas — filled bands and cells, and wide translucent
/// strokes (a band drawn as a line) — which must still show (1.2:1).
#[test]
fn every_line_marker_and_text_reaches_three_to_one() {
    let study = small_study();
    let mut problems = Vec::new();
    let mut checked = 0;
    for case in Case::REPORT {
        for (name, svg) in figures_of(study, case) {
            let doc = roxmltree::Document::parse(&svg).unwrap();
            for n in doc.descendants().filter(|n| n.is_element()) {
                let tag = n.tag_name().name();
                let opacity: f64 = n.attribute("opacity").map_or(1.0, |o| o.parse().unwrap());
                let paint = |attr: &str| n.attribute(attr).and_then(hex);
                let mut judge = |what: &str, c: RGBColor, area: bool| {
                    let seen = over_white(c, opacity);
                    let (min, r) = (if area { 1.2 } else { 3.0 }, contrast_on_white(seen));
                    checked += 1;
                    if r < min {
                        problems.push(format!(
                            "{name}: {what} of <{tag}> {c:?} at opacity {opacity}: {r:.2}:1"
                        ));
                    }
                };
                if let Some(c) = paint("stroke") {
                    let width: f64 = n
                        .attribute("stroke-width")
                        .map_or(1.0, |w| w.parse().unwrap());
                    if c != GRID {
                        judge("stroke", c, opacity < 1.0 && width >= 4.0);
                    }
                }
                match (tag, paint("fill")) {
                    ("text" | "circle", Some(c)) => judge("fill", c, false),
                    ("rect" | "polygon", Some(c)) if opacity < 1.0 => judge("fill", c, true),
                    _ => {}
                }
            }
        }
    }
    assert!(checked > 1000, "only {checked} paints checked");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The cells of the whiteness map (and its colour scale) overlap their neighbours instead of
/// meeting edge to edge: edges that meet exactly show a white anti-aliased seam once the figure
/// is scaled.
#[test]
fn map_cells_leave_no_seams() {
    let figs = figures(small_study());
    let svg = &figs
        .iter()
        .find(|(n, _)| *n == "residual_whiteness")
        .unwrap()
        .1;
    let doc = roxmltree::Document::parse(svg).unwrap();
    let num = |n: &roxmltree::Node, a: &str| n.attribute(a).unwrap().parse::<i32>().unwrap();
    let cells: Vec<[i32; 4]> = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect"))
        .filter(|n| {
            n.attribute("fill")
                .is_some_and(|f| f != "none" && f != "#FFFFFF")
        })
        .map(|n| {
            let (x, y) = (num(&n, "x"), num(&n, "y"));
            [x, y, x + num(&n, "width"), y + num(&n, "height")]
        })
        .collect();
    assert!(cells.len() > 20, "only {} cells", cells.len());
    // A seam: a stretch of an edge where two cells meet exactly, with no cell across it.
    let crossed_x = |x: i32, y: i32| {
        cells
            .iter()
            .any(|c| c[0] < x && x < c[2] && c[1] <= y && y < c[3])
    };
    let crossed_y = |y: i32, x: i32| {
        cells
            .iter()
            .any(|c| c[1] < y && y < c[3] && c[0] <= x && x < c[2])
    };
    for a in &cells {
        for b in &cells {
            if a[0] == b[2] {
                let seam = (a[1].max(b[1])..a[3].min(b[3])).find(|&y| !crossed_x(a[0], y));
                assert!(seam.is_none(), "cells {a:?} and {b:?} meet edge to edge");
            }
            if a[1] == b[3] {
                let seam = (a[0].max(b[0])..a[2].min(b[2])).find(|&x| !crossed_y(a[1], x));
                assert!(seam.is_none(), "cells {a:?} and {b:?} meet edge to edge");
            }
        }
    }
}

/// The labels of the whiteness figure's residual pair ("r_p(t_i)·r_v(t_m)", "z = 0.77") stand
/// left of its plot, where no line or dot runs: they end before its frame.
#[test]
fn residual_pair_labels_stay_clear_of_the_plot() {
    let figs = figures(small_study());
    let svg = &figs
        .iter()
        .find(|(n, _)| *n == "residual_whiteness")
        .unwrap()
        .1;
    let doc = roxmltree::Document::parse(svg).unwrap();
    let num = |n: &roxmltree::Node, a: &str| n.attribute(a).unwrap().parse::<f64>().unwrap();
    // The pair's plot is the rightmost frame.
    let frame_left = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some("none"))
        .map(|n| num(&n, "x"))
        .fold(f64::NEG_INFINITY, f64::max);
    let mut labels = 0;
    for n in doc.descendants().filter(|n| n.has_tag_name("text")) {
        let text: String = n
            .descendants()
            .filter_map(|d| d.text().filter(|_| d.is_text()))
            .collect();
        let text = text.trim();
        if text.contains(")·r")
            || (text.starts_with("z = ") && !text.contains('√'))
            || text == "undefined"
        {
            labels += 1;
            assert_eq!(n.attribute("text-anchor"), Some("end"), "{text}");
            assert!(num(&n, "x") < frame_left, "{text} reaches into the plot");
        }
    }
    assert_eq!(labels, 8, "four component pairs, each named with its z");
}

/// A trace that an axis cuts early in the run is named in its panel's title, with the time from
/// which all of it is shown; a trace the axis holds is not.
#[test]
fn titles_say_what_the_axes_clip() {
    let study = small_study();
    let title_with = |svg: &str, start: &str| {
        texts(svg)
            .into_iter()
            .find(|t| t.starts_with(start))
            .unwrap_or_else(|| panic!("no title starting {start:?}"))
    };
    // Every estimate on its truth, every error zero, σ constant: nothing leaves its axis.
    let mut calm = study.realization.clone();
    for s in &mut calm.samples {
        s.estimate = s.delta_x;
        s.sigma = [1.0; ErrorState::DIM];
    }
    let svg = trajectory(&calm).unwrap();
    assert_eq!(
        title_with(&svg, "Accelerometer bias"),
        "Accelerometer bias b and its estimate"
    );
    assert_eq!(
        title_with(&realization_errors(&calm).unwrap(), "Bias:"),
        "Bias: error and ±1σ over the run"
    );
    // The bias estimate far off at the second sample: clipped until the third, at 0.01 s.
    let mut wild = calm.clone();
    wild.samples[1].estimate[ErrorState::BIAS] = 1e3;
    assert!(wild.samples[2].t_s <= 0.1);
    assert_eq!(
        title_with(&trajectory(&wild).unwrap(), "Bias b"),
        "Bias b and its estimate (off the axis before 0.1 s)"
    );
    assert_eq!(
        title_with(&realization_errors(&wild).unwrap(), "Bias:"),
        "Bias: error and ±1σ (error off the axis before 0.1 s)"
    );
    // A σ too large early on, as the prior's is.
    wild.samples[3].sigma[ErrorState::BIAS] = 1e3;
    assert!(wild.samples[4].t_s <= 0.1);
    assert_eq!(
        title_with(&realization_errors(&wild).unwrap(), "Bias:"),
        "Bias: error and ±1σ (both off the axis before 0.1 s)"
    );
}

/// An average NEES or NIS far from its χ² band (which a linear axis would flatten to a line)
/// gets a log axis over the run and, beside it, the band enlarged; one near its band keeps its
/// linear axis.
#[test]
fn consistency_far_from_its_band_gets_a_log_axis_and_the_band_enlarged() {
    let study = small_study();
    let (nees, nis) = (check(study, CheckId::NEES), check(study, CheckId::NIS));
    let mut near = study.case(CASE).run.stats.clone();
    for f in &mut near.fixes {
        // Each at its expected value: the number of states, of measured components.
        let (states, measured) = (ErrorState::DIM as f64, ErrorState::MEAS as f64);
        (f.prior.nees_avg, f.post.nees_avg, f.nis_avg) = (states, states, measured);
    }
    let titles = |stats| {
        texts(&consistency(stats, nees, nis).unwrap())
            .into_iter()
            .filter(|t| t.starts_with("Average") || t.starts_with("Enlarged"))
            .collect::<Vec<_>>()
    };
    let linear = titles(&near);
    assert_eq!(linear.len(), 2, "{linear:?}");
    assert!(
        linear.iter().all(|t| t.contains(": expected")),
        "{linear:?}"
    );

    let mut far = near.clone();
    far.fixes[3].post.nees_avg = 11.0 * nees.upper;
    let split = titles(&far);
    assert_eq!(split.len(), 3, "{split:?}");
    assert!(split[0].starts_with("Average NEES") && split[0].ends_with(", log axis"));
    assert!(split[1].starts_with("Enlarged: band ["), "{split:?}");
    assert!(split[2].starts_with("Average NIS: expected 2"), "{split:?}");
    // The log axis reaches the decade above 11 × 3.1.
    assert!(texts(&consistency(&far, nees, nis).unwrap()).contains(&"10²".to_string()));
}
