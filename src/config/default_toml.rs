//! The default configuration file (what `accelcal config` prints), rendered at compile time from
//! the template `default_config.toml` and the noise statistics of [`STATISTICS`].
//!
//! A template line `{section.key}` becomes the row whose truth key it names: its comment lines
//! and `key = default` (commented out for a bias model's parameter, which is optional). A line
//! `{section.*}` becomes the rows of that section that no line of their own names (a new
//! statistic lands there without touching the template). `{filter}` and `{filter.bias_model}`
//! become the commented `[filter]` keys of the other statistics and of the bias models'
//! parameters. Every other line is copied.

use super::statistics::{STATISTICS, Statistic};

/// The template.
const TEMPLATE: &[u8] = include_bytes!("default_config.toml");

/// A byte buffer of capacity `N` that counts what does not fit (with `N = 0`, a length).
struct Out<const N: usize> {
    buf: [u8; N],
    len: usize,
}

impl<const N: usize> Out<N> {
    const fn new() -> Self {
        Self {
            buf: [0; N],
            len: 0,
        }
    }

    const fn push(&mut self, bytes: &[u8]) {
        let mut i = 0;
        while i < bytes.len() {
            if self.len < N {
                self.buf[self.len] = bytes[i];
            }
            self.len += 1;
            i += 1;
        }
    }
}

/// `bytes[start..end]`.
const fn slice(bytes: &[u8], start: usize, end: usize) -> &[u8] {
    bytes.split_at(end).0.split_at(start).1
}

const fn equal(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// Whether `path` is `section` followed by a dot and a key.
const fn in_section(path: &[u8], section: &[u8]) -> bool {
    path.len() > section.len()
        && path[section.len()] == b'.'
        && equal(slice(path, 0, section.len()), section)
}

/// Whether a template line is exactly `{name}`.
const fn names(line: &[u8], name: &[u8]) -> bool {
    line.len() == name.len() + 2
        && line[0] == b'{'
        && line[line.len() - 1] == b'}'
        && equal(slice(line, 1, line.len() - 1), name)
}

/// Whether some line of the template is `{name}`.
const fn template_names(name: &[u8]) -> bool {
    let mut start = 0;
    while start < TEMPLATE.len() {
        let end = line_end(start);
        if names(slice(TEMPLATE, start, end), name) {
            return true;
        }
        start = end + 1;
    }
    false
}

/// The index of the newline ending the line that starts at `start` (or the template's end).
const fn line_end(start: usize) -> usize {
    let mut end = start;
    while end < TEMPLATE.len() && TEMPLATE[end] != b'\n' {
        end += 1;
    }
    end
}

/// The truth's key of `s` with its comment, as the default file writes it.
const fn push_truth<const N: usize>(out: &mut Out<N>, s: &Statistic) {
    out.push(s.toml_comment.as_bytes());
    if s.bias_model.is_some() {
        out.push(b"# ");
    }
    out.push(s.truth_key().as_bytes());
    out.push(b" = ");
    out.push(s.default_toml.as_bytes());
    out.push(b"\n");
}

/// The `[filter]` keys, commented out, of the statistics of a bias model (`bias`) or of the
/// others.
const fn push_filter<const N: usize>(out: &mut Out<N>, bias: bool) {
    let mut i = 0;
    while i < STATISTICS.len() {
        let s = &STATISTICS[i];
        if s.bias_model.is_some() == bias {
            out.push(b"# ");
            out.push(s.key().as_bytes());
            out.push(b" = ");
            out.push(s.default_toml.as_bytes());
            out.push(b"\n");
        }
        i += 1;
    }
}

/// The statistics of `section` that no template line names.
const fn push_section<const N: usize>(out: &mut Out<N>, section: &[u8]) {
    let mut i = 0;
    while i < STATISTICS.len() {
        let s = &STATISTICS[i];
        let path = s.truth_path.as_bytes();
        if in_section(path, section) && !template_names(path) {
            push_truth(out, s);
        }
        i += 1;
    }
}

/// Expands a placeholder line `{name}` (`name` without the braces).
const fn expand<const N: usize>(out: &mut Out<N>, name: &[u8]) {
    if equal(name, b"filter") {
        return push_filter(out, false);
    }
    if equal(name, b"filter.bias_model") {
        return push_filter(out, true);
    }
    if name.len() > 2 && name[name.len() - 2] == b'.' && name[name.len() - 1] == b'*' {
        return push_section(out, slice(name, 0, name.len() - 2));
    }
    let mut i = 0;
    while i < STATISTICS.len() {
        if equal(STATISTICS[i].truth_path.as_bytes(), name) {
            return push_truth(out, &STATISTICS[i]);
        }
        i += 1;
    }
    panic!("a placeholder of default_config.toml names no statistic");
}

/// The whole file.
const fn render<const N: usize>(out: &mut Out<N>) {
    let mut start = 0;
    while start < TEMPLATE.len() {
        let end = line_end(start);
        let line = slice(TEMPLATE, start, end);
        if line.len() > 2 && line[0] == b'{' && line[line.len() - 1] == b'}' {
            expand(out, slice(line, 1, line.len() - 1));
        } else {
            out.push(line);
            if end < TEMPLATE.len() {
                out.push(b"\n");
            }
        }
        start = end + 1;
    }
}

/// The rendered file's length.
const LEN: usize = {
    let mut out = Out::<0>::new();
    render(&mut out);
    out.len
};

/// The rendered file's bytes.
const BYTES: [u8; LEN] = {
    let mut out = Out::<LEN>::new();
    render(&mut out);
    out.buf
};

/// The default configuration as an annotated TOML file (what `accelcal config` prints).
pub const DEFAULT_TOML: &str = match std::str::from_utf8(&BYTES) {
    Ok(text) => text,
    Err(_) => panic!("the default configuration is UTF-8"),
};
