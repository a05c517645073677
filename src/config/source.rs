//! Where in a configuration file something is: the line and column of a span, the line itself,
//! and the dotted path of the field there (or the span of a field's value).
//!
//! The TOML parser's errors carry a byte span; the document parsed again with spans
//! ([`toml::de::DeTable::parse_recoverable`], which keeps what it can of a broken document) tells
//! which key holds it. [`ConfigText`] keeps a file's text to point at the line of an error found
//! after parsing.

use std::io::Read;
use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};

use super::Config;
use crate::error::{ConfigError, Position, floor_char_boundary};

fn contains(span: &Range<usize>, offset: usize) -> bool {
    span.start <= offset && offset < span.end.max(span.start + 1)
}

/// The most bytes a configuration file may hold: the annotated default is under 10 KB, and a
/// bound keeps a wrong path (a device, a log) from being read without end.
pub const MAX_CONFIG_BYTES: usize = 1 << 20;

/// A configuration file's text, kept so that an error found after parsing (a value out of
/// range) can point at the line that sets it.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigText {
    /// The file as the user named it.
    pub file: String,
    /// Its text.
    pub text: String,
}

impl ConfigText {
    /// Reads the file at `path`, at most [`MAX_CONFIG_BYTES`]: a longer file, or a device that
    /// never ends (`/dev/zero`), is refused once that much is read. A pipe (`--config <(…)`)
    /// is read like a file.
    ///
    /// # Errors
    /// [`ConfigError::Read`] when it cannot be read, is longer than the limit or is not UTF-8.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let file = path.display().to_string();
        let fail = |message: String| ConfigError::Read {
            path: file.clone(),
            message,
        };
        let opened = std::fs::File::open(path).map_err(|e| fail(e.to_string()))?;
        let mut bytes = Vec::new();
        opened
            .take(MAX_CONFIG_BYTES as u64 + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| fail(e.to_string()))?;
        if bytes.len() > MAX_CONFIG_BYTES {
            return Err(fail(format!(
                "longer than {} bytes (1 MiB), the most a configuration may hold: is it the \
                 right file?",
                MAX_CONFIG_BYTES
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            fail(format!("not UTF-8 text (byte {at} is not valid UTF-8)"))
        })?;
        Ok(Self { file, text })
    }

    /// Parses the text.
    ///
    /// # Errors
    /// [`ConfigError::Parse`] naming the file, line, column and field.
    pub fn parse(&self) -> Result<Config, ConfigError> {
        Config::from_toml_str(&self.text).map_err(|e| self.locate(e))
    }

    /// `err` with this file named, and for [`ConfigError::Invalid`] the position of the line
    /// that sets the field, when the file sets it.
    pub fn locate(&self, err: ConfigError) -> ConfigError {
        match err {
            ConfigError::Parse {
                position,
                field,
                message,
                ..
            } => ConfigError::Parse {
                file: Some(self.file.clone()),
                position,
                field,
                message,
            },
            ConfigError::Invalid {
                field,
                value,
                expected,
                ..
            } => ConfigError::Invalid {
                position: span_of(&self.text, field).map(|s| Box::new(Position::of(&self.text, s))),
                file: Some(self.file.clone()),
                field,
                value,
                expected,
            },
            read @ ConfigError::Read { .. } => read,
        }
    }
}

/// The dotted path of the innermost key whose key or value holds byte `offset`.
fn path_in(table: &DeTable<'_>, offset: usize, path: &mut Vec<String>) -> bool {
    for (key, value) in table.iter() {
        path.push(key.get_ref().to_string());
        let inner = match value.get_ref() {
            DeValue::Table(t) => path_in(t, offset, path),
            DeValue::Array(a) => a.into_iter().enumerate().any(|(i, v)| {
                let DeValue::Table(t) = v.get_ref() else {
                    return false;
                };
                path.push(i.to_string());
                let found = path_in(t, offset, path);
                if !found {
                    path.pop();
                }
                found
            }),
            _ => false,
        };
        if inner || contains(&key.span(), offset) || contains(&value.span(), offset) {
            return true;
        }
        path.pop();
    }
    false
}

/// The dotted path of the field at byte `offset` of `text`, e.g. `ensemble.realizations`.
///
/// When the document is too broken for its keys to be found, the nearest table header above the
/// line and the key before `=` on it give the path.
pub fn field_at(text: &str, offset: usize) -> Option<String> {
    let (doc, _) = DeTable::parse_recoverable(text);
    let mut path = Vec::new();
    if path_in(doc.get_ref(), offset, &mut path) {
        return Some(path.join("."));
    }
    let start = floor_char_boundary(text, offset.min(text.len()));
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("");
    let header = text[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    if let Some(h) = line.trim_start().strip_prefix('[') {
        // The header of this very line is broken: the table it declares.
        let name = h.trim_matches(|c: char| c == '[' || c == ']' || c.is_whitespace());
        return (!name.is_empty()).then(|| name.to_string());
    }
    // A comment's words are not a key, even when they hold an `=`.
    let code = line.split('#').next().unwrap_or("");
    let key = code
        .split_once('=')
        .map(|(k, _)| k.trim().to_string())
        .filter(|k| !k.is_empty() && !k.starts_with('['));
    match (header, key) {
        (Some(h), Some(k)) => Some(format!("{h}.{k}")),
        (None, Some(k)) => Some(k),
        (Some(h), None) => Some(h),
        (None, None) => None,
    }
}

/// The error of a carriage return that no line feed follows, when `text` holds one: TOML ends a
/// line with LF or CR LF only, and a file saved with CR alone (old Mac line ends) would otherwise
/// be read as one long line whose comments the parser's error quotes as keys.
pub fn lone_carriage_return(text: &str) -> Option<ConfigError> {
    let bytes = text.as_bytes();
    let at = (0..bytes.len()).find(|&i| bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n'))?;
    // Lines as the user's editor shows them: ended by LF, CR LF or CR alone.
    let before = &text[..at];
    let line_start = before.rfind(['\n', '\r']).map_or(0, |i| i + 1);
    let line = before.matches('\n').count() + before.matches('\r').count()
        - before.matches("\r\n").count()
        + 1;
    let line_text = &text[line_start..at];
    Some(ConfigError::Parse {
        file: None,
        position: Some(Box::new(Position {
            line,
            column: line_text.chars().count() + 1,
            text: line_text.to_string(),
            width: 1,
        })),
        field: None,
        message: "a carriage return (CR) that no line feed (LF) follows ends this line: TOML \
                  lines end with LF or CR LF (the file seems to use old Mac line ends; convert \
                  them, e.g. with `tr '\\r' '\\n'`)"
            .to_string(),
    })
}

/// Invisible characters that make a value look right and read wrong, with their names.
const INVISIBLE: [(char, &str); 7] = [
    ('\u{feff}', "a byte order mark"),
    ('\u{200b}', "a zero-width space"),
    ('\u{200c}', "a zero-width non-joiner"),
    ('\u{200d}', "a zero-width joiner"),
    ('\u{2060}', "a word joiner"),
    ('\u{00a0}', "a no-break space"),
    ('\u{00ad}', "a soft hyphen"),
];

/// The parser's `message` for an error at `span` of `text`, made true where its words mislead:
/// a date-time value is named as one (serde calls it a "map"), and an invisible character on the
/// line is named with its code point and column.
pub fn explain(text: &str, span: Option<Range<usize>>, message: &str) -> String {
    let Some(span) = span else {
        return message.to_string();
    };
    let start = floor_char_boundary(text, span.start.min(text.len()));
    let end = floor_char_boundary(text, span.end.clamp(start, text.len()));
    let mut out = message.to_string();
    if text[start..end]
        .trim()
        .parse::<toml::value::Datetime>()
        .is_ok()
    {
        out = out.replace("invalid type: map", "invalid type: a date-time");
    }
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let line = &text[line_start..line_end];
    let invisible = line.chars().enumerate().find_map(|(column, c)| {
        // A byte order mark that starts the file is allowed and skipped by the parser.
        if line_start == 0 && column == 0 && c == '\u{feff}' {
            return None;
        }
        INVISIBLE
            .iter()
            .find(|(i, _)| *i == c)
            .map(|(_, name)| (column + 1, c, *name))
    });
    if let Some((column, c, name)) = invisible {
        out.push_str(&format!(
            " (column {column} holds U+{:04X}, {name}: an invisible character; delete it)",
            u32::from(c)
        ));
    }
    out
}

/// The span of the value of the field at dotted `path` in `text`, when the file sets it.
pub fn span_of(text: &str, path: &str) -> Option<Range<usize>> {
    let (doc, _) = DeTable::parse_recoverable(text);
    let mut keys = path.split('.');
    let first = keys.next()?;
    let mut value = doc.get_ref().get(first)?;
    for key in keys {
        let DeValue::Table(t) = value.get_ref() else {
            return None;
        };
        value = t.get(key)?;
    }
    Some(value.span())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_found_by_offset_and_by_path() {
        let text = "[profile]\nduration_s = 6.0\n\n[ensemble]\nrealizations = 10\n";
        let at = text.find("10").unwrap();
        assert_eq!(field_at(text, at).as_deref(), Some("ensemble.realizations"));
        let span = span_of(text, "profile.duration_s").unwrap();
        assert_eq!(&text[span], "6.0");
        assert_eq!(span_of(text, "gps.sample_rate_hz"), None);
        // Broken beyond parsing: the header and the key on the line.
        let text = "[gps]\nposition_sigma_m = = 1\n";
        assert_eq!(field_at(text, 19).as_deref(), Some("gps.position_sigma_m"));
        assert_eq!(field_at("[gps\nx = 1\n", 4).as_deref(), Some("gps"));
    }
}
