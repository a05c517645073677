//! The errors of bad input: a configuration that cannot be accepted ([`ConfigError`]) and filter
//! statistics that cannot keep the covariance positive definite ([`FilterError`]). A command
//! line exits with its bad-input code for these; failures of the machine have their own types
//! beside the code that meets them ([`crate::output::OutputError`],
//! [`crate::report::RenderError`]).

use std::fmt;
use std::ops::Range;

use thiserror::Error;

/// A configuration that cannot be read, parsed or accepted.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConfigError {
    /// The configuration file could not be read.
    #[error("cannot read configuration file {path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// Why, from the operating system.
        message: String,
    },
    /// The text is not a valid configuration (syntax, type, or unknown field).
    #[error(
        "invalid configuration{}{}: {message}{}",
        place(.file, .position),
        field_words(.field),
        quoted(.position)
    )]
    Parse {
        /// The file, when the text came from one.
        file: Option<String>,
        /// Where in the text, when the parser said.
        position: Option<Box<Position>>,
        /// Dotted path of the field there, e.g. `ensemble.realizations`.
        field: Option<String>,
        /// The parser's message.
        message: String,
    },
    /// A field holds a value outside its accepted range.
    #[error(
        "invalid configuration{}: `{field}` = {value}: {expected}{}",
        place(.file, .position),
        quoted(.position)
    )]
    Invalid {
        /// Dotted path of the field, e.g. `gps.sample_rate_hz`.
        field: &'static str,
        /// The value as given.
        value: String,
        /// The accepted range, in words.
        expected: String,
        /// The file, when the configuration came from one.
        file: Option<String>,
        /// Where the file sets the field, when it does.
        position: Option<Box<Position>>,
    },
}

/// " in FILE:LINE:COLUMN", " in FILE", " at line L, column C" or nothing.
fn place(file: &Option<String>, position: &Option<Box<Position>>) -> String {
    match (file, position) {
        (Some(f), Some(p)) => format!(" in {f}:{}:{}", p.line, p.column),
        (Some(f), None) => format!(" in {f}"),
        (None, Some(p)) => format!(" at line {}, column {}", p.line, p.column),
        (None, None) => String::new(),
    }
}

fn field_words(field: &Option<String>) -> String {
    field
        .as_ref()
        .map(|f| format!(", field `{f}`"))
        .unwrap_or_default()
}

fn quoted(position: &Option<Box<Position>>) -> String {
    position.as_ref().map(|p| p.to_string()).unwrap_or_default()
}

impl ConfigError {
    /// A value outside its accepted range: `field` (a configuration path or a command-line
    /// option) holds `value`; `expected` says what is accepted.
    pub fn invalid(field: &'static str, value: impl ToString, expected: impl Into<String>) -> Self {
        ConfigError::Invalid {
            field,
            value: value.to_string(),
            expected: expected.into(),
            file: None,
            position: None,
        }
    }
}

/// A line and column in a configuration file, with the line's text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Position {
    /// Line, from 1.
    pub line: usize,
    /// Column in characters, from 1.
    pub column: usize,
    /// The line as written.
    pub text: String,
    /// Characters the span covers on the line, at least 1.
    pub width: usize,
}

impl Position {
    /// The position of byte `span.start` of `text`.
    pub fn of(text: &str, span: Range<usize>) -> Self {
        let start = floor_char_boundary(text, span.start.min(text.len()));
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line_text = text[line_start..line_end].trim_end_matches('\r');
        let column = text[line_start..start].chars().count() + 1;
        let end = floor_char_boundary(text, span.end.clamp(start, line_end));
        Self {
            line: text[..line_start].matches('\n').count() + 1,
            column,
            text: line_text.to_string(),
            width: text[start..end].chars().count().max(1),
        }
    }
}

pub(crate) fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while i > 0 && !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl fmt::Display for Position {
    /// The line quoted with a caret under the span, on lines of their own.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let gutter = self.line.to_string().len();
        write!(
            f,
            "\n {} | {}\n {} | {}{}",
            self.line,
            self.text,
            " ".repeat(gutter),
            " ".repeat(self.column - 1),
            "^".repeat(self.width)
        )
    }
}

/// The statistics the filter assumes, named in every [`FilterError`]: its covariance depends on
/// them alone.
const FILTER_FIELDS: &str = "check the [filter] statistics (accel_noise_var_m2_s4, \
     bias_var_m2_s4, gps_position_sigma_m, gps_velocity_sigma_m_s, initial_position_sigma_m, \
     initial_velocity_sigma_m_s)";

/// A covariance the filter computed stopped being symmetric positive definite. The covariance
/// recursion depends on the configured statistics alone, so this is bad input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FilterError {
    /// The innovation covariance S = H·P⁻·Hᵀ + R has no Cholesky factor.
    #[error(
        "the filter's innovation covariance at t = {time_s} s is not positive definite: {FILTER_FIELDS}"
    )]
    InnovationNotPositiveDefinite {
        /// Time of the fix, s.
        time_s: f64,
    },
    /// The state covariance P has no Cholesky factor.
    #[error(
        "the filter's {which} covariance at t = {time_s} s is not positive definite: {FILTER_FIELDS}"
    )]
    CovarianceNotPositiveDefinite {
        /// "a priori" or "a posteriori".
        which: &'static str,
        /// Time of the fix, s.
        time_s: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_lines_and_characters() {
        let text = "[gps]\nσ = 1\nrate_hz = \"x\"\n";
        let at = text.find("\"x\"").unwrap();
        let p = Position::of(text, at..at + 3);
        assert_eq!((p.line, p.column, p.width), (3, 11, 3));
        assert_eq!(p.text, "rate_hz = \"x\"");
        assert_eq!(p.to_string(), "\n 3 | rate_hz = \"x\"\n   |           ^^^");
        let end = Position::of("a = ", 4..4);
        assert_eq!((end.line, end.column, end.width), (1, 5, 1));
    }
}
