//! Text with notation: `_{…}` and `^{…}` in a view string become subscripts and superscripts.
//! Everything else is escaped, so the result is safe to place in the page as HTML.

/// `text` as HTML: escaped, with `x_{c}` → x<sub>c</sub> and `e^{ave}` → e<sup>ave</sup>.
///
/// # Examples
/// ```
/// use accelcal::report::rich::rich;
/// assert_eq!(rich("p_{c} < 3 & e^{ave}"), "p<sub>c</sub> &lt; 3 &amp; e<sup>ave</sup>");
/// ```
pub fn rich(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '_' | '^' if chars.peek() == Some(&'{') => {
                chars.next();
                let tag = if c == '_' { "sub" } else { "sup" };
                out.push_str(&format!("<{tag}>"));
                for d in chars.by_ref() {
                    if d == '}' {
                        break;
                    }
                    escape_into(d, &mut out);
                }
                out.push_str(&format!("</{tag}>"));
            }
            _ => escape_into(c, &mut out),
        }
    }
    out
}

fn escape_into(c: char, out: &mut String) {
    match c {
        '&' => out.push_str("&amp;"),
        '<' => out.push_str("&lt;"),
        '>' => out.push_str("&gt;"),
        '"' => out.push_str("&quot;"),
        '\'' => out.push_str("&#39;"),
        _ => out.push(c),
    }
}

/// `text` without its notation markup, for plain-text uses (the command line, JSON).
pub fn plain(text: &str) -> String {
    text.replace("_{", "").replace("^{", "").replace('}', "")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_becomes_tags_and_the_rest_is_escaped() {
        assert_eq!(rich("t_{m} < t_{i}"), "t<sub>m</sub> &lt; t<sub>i</sub>");
        assert_eq!(rich("a_b"), "a_b");
        assert_eq!(rich("<script>"), "&lt;script&gt;");
        assert_eq!(plain("v_{c}"), "vc");
    }
}
