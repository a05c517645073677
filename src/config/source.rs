//! Where in a configuration file something is: the line and column of a span, the line itself,
//! and the dotted path of the field there (or the span of a field's value).
//!
//! The TOML parser's errors carry a byte span; the document parsed again with spans
//! ([`toml::de::DeTable::parse_recoverable`], which keeps what it can of a broken document) tells
//! which key holds it. [`ConfigText`] keeps a file's text to point at the line of an error found
//! after parsing.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};

use super::Config;
use crate::error::{ConfigError, Position, floor_char_boundary};

fn contains(span: &Range<usize>, offset: usize) -> bool {
    span.start <= offset && offset < span.end.max(span.start + 1)
}

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
    /// Reads the file at `path`.
    ///
    /// # Errors
    /// [`ConfigError::Read`] when it cannot be read.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Read {
            path: file.clone(),
            message: e.to_string(),
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
    let key = line
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
