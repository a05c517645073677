//! Sub- and superscripts in figure text.
//!
//! Labels are written with `_{…}` and `^{…}` (`p_{c}`, `e^{ave}`, `r_{p}(t_{i})`); plotters would
//! show that markup literally, and Unicode has no subscript for most letters (c, for one). Once a
//! figure is drawn, [`scripts_to_tspans`] rewrites the content of every `<text>` that holds
//! markup into `<tspan>`s: each script is set at [`SCRIPT_SCALE`] of the text's size and shifted
//! with `dy` in pixels, and the text after it shifts back to the baseline. `dy` on `<tspan>`
//! renders alike in Chromium, Firefox and Safari, unlike `baseline-shift` or `<sub>`.
//!
//! The markup has no nesting and no escape: `_` or `^` not followed by `{`, and a `{` without its
//! `}`, are left as they are (a test then finds them in the figure).

/// Size of a script relative to its text.
pub(crate) const SCRIPT_SCALE: f64 = 0.75;
/// How far a subscript's baseline drops, as a fraction of the text's size.
const SUB_DROP: f64 = 0.25;
/// How far a superscript's baseline rises, as a fraction of the text's size.
const SUP_RISE: f64 = 0.4;

/// Where a run of text sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Place {
    Baseline,
    Sub,
    Sup,
}

/// `text` split into runs by its markup, the markup removed; empty runs are dropped.
pub(crate) fn runs(text: &str) -> Vec<(Place, &str)> {
    let mut out = Vec::new();
    let mut rest = text;
    let mut plain_from = 0;
    let mut i = 0;
    while i < rest.len() {
        let tail = &rest[i..];
        let place = if tail.starts_with("_{") {
            Some(Place::Sub)
        } else if tail.starts_with("^{") {
            Some(Place::Sup)
        } else {
            None
        };
        if let Some(place) = place
            && let Some(close) = tail[2..].find('}')
        {
            if i > plain_from {
                out.push((Place::Baseline, &rest[plain_from..i]));
            }
            let script = &tail[2..2 + close];
            if !script.is_empty() {
                out.push((place, script));
            }
            rest = &tail[3 + close..];
            i = 0;
            plain_from = 0;
            continue;
        }
        i += tail.chars().next().map_or(1, char::len_utf8);
    }
    if rest.len() > plain_from {
        out.push((Place::Baseline, &rest[plain_from..]));
    }
    out
}

/// Width of `text` in characters as drawn: a script character counts [`SCRIPT_SCALE`].
pub(crate) fn drawn_chars(text: &str) -> f64 {
    runs(text)
        .iter()
        .map(|(place, s)| {
            let n = s.chars().count() as f64;
            if *place == Place::Baseline {
                n
            } else {
                n * SCRIPT_SCALE
            }
        })
        .sum()
}

/// `text` without its markup, as a reader sees it on one line.
#[cfg(test)]
pub(crate) fn plain(text: &str) -> String {
    runs(text).iter().map(|(_, s)| *s).collect()
}

/// Rewrites the markup in the content of every `<text>` element of `svg` (as plotters writes
/// it: one element per label, content escaped, `font-size` in pixels) into `<tspan>`s.
pub(crate) fn scripts_to_tspans(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len() + svg.len() / 16);
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        let Some(open_end) = rest[start..].find('>').map(|k| start + k + 1) else {
            break;
        };
        let Some(close) = rest[open_end..].find("</text>").map(|k| open_end + k) else {
            break;
        };
        out.push_str(&rest[..open_end]);
        let content = &rest[open_end..close];
        if content.contains("_{") || content.contains("^{") {
            let size = font_size(&rest[start..open_end]).unwrap_or(16.0);
            out.push_str(&tspans(content.trim(), size));
        } else {
            out.push_str(content);
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}

/// The `font-size` attribute of an opening tag, in pixels.
fn font_size(tag: &str) -> Option<f64> {
    let from = tag.find(" font-size=\"")? + " font-size=\"".len();
    let len = tag[from..].find('"')?;
    tag[from..from + len].trim_end_matches("px").parse().ok()
}

/// The content `text` (font size `size` px) with its scripts as shifted `<tspan>`s.
fn tspans(text: &str, size: f64) -> String {
    let px = |v: f64| {
        let v = (v * 10.0).round() / 10.0;
        if v == 0.0 {
            "0".to_string()
        } else {
            v.to_string()
        }
    };
    let mut out = String::new();
    let mut shift = 0.0;
    for (place, s) in runs(text) {
        let target = match place {
            Place::Baseline => 0.0,
            Place::Sub => SUB_DROP * size,
            Place::Sup => -SUP_RISE * size,
        };
        match place {
            Place::Baseline if shift == 0.0 => out.push_str(s),
            Place::Baseline => {
                out.push_str(&format!("<tspan dy=\"{}\">{s}</tspan>", px(-shift)));
            }
            _ => out.push_str(&format!(
                "<tspan dy=\"{}\" font-size=\"{}\">{s}</tspan>",
                px(target - shift),
                px(SCRIPT_SCALE * size)
            )),
        }
        shift = target;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_splits_into_runs() {
        assert_eq!(
            runs("δp = p − p_{c}"),
            [(Place::Baseline, "δp = p − p"), (Place::Sub, "c")]
        );
        assert_eq!(
            runs("e^{ave} (m)"),
            [
                (Place::Baseline, "e"),
                (Place::Sup, "ave"),
                (Place::Baseline, " (m)")
            ]
        );
        assert_eq!(
            runs("r_{p}(t_{i})"),
            [
                (Place::Baseline, "r"),
                (Place::Sub, "p"),
                (Place::Baseline, "(t"),
                (Place::Sub, "i"),
                (Place::Baseline, ")"),
            ]
        );
        // No markup, or markup that does not close, stays as it is.
        assert_eq!(runs("a_b x^{y"), [(Place::Baseline, "a_b x^{y")]);
        assert_eq!(plain("t_{m} < t_{i}"), "tm < ti");
        assert_eq!(drawn_chars("P^{ave}"), 1.0 + 3.0 * SCRIPT_SCALE);
    }

    #[test]
    fn text_elements_get_shifted_tspans() {
        let svg = "<svg><text x=\"1\" y=\"2\" font-size=\"20\" fill=\"#000000\">\nv_{c}(t) + e^{ave}\n</text><text font-size=\"20\">\nplain_text\n</text></svg>";
        assert_eq!(
            scripts_to_tspans(svg),
            "<svg><text x=\"1\" y=\"2\" font-size=\"20\" fill=\"#000000\">v<tspan dy=\"5\" font-size=\"15\">c</tspan><tspan dy=\"-5\">(t) + e</tspan><tspan dy=\"-8\" font-size=\"15\">ave</tspan></text><text font-size=\"20\">\nplain_text\n</text></svg>"
        );
    }
}
