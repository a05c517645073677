//! Reading logs: a CSV reader that streams rows and names the file and line of every problem,
//! and the two sensor logs on top of it.
//!
//! A log is UTF-8 text: a header row naming the columns, then one row per sample, fields separated
//! by commas. The header must hold each required column once; other columns are ignored. Blank
//! lines are skipped, a byte-order mark and `\r\n` line ends are accepted, and every field must
//! be a finite number (`NaN` and `inf` are refused).

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use super::{ACCEL_COLUMNS, AccelSample, GPS_COLUMNS, GpsFix, LogError, LogProblem, echo};

/// A log that can be read from its start any number of times: a calibration reads the
/// accelerometer log three times rather than hold it in memory.
pub trait LogSource {
    /// The name used in messages: the path as the user gave it.
    fn name(&self) -> &str;

    /// A reader at the start of the log.
    ///
    /// # Errors
    /// [`LogProblem::Unreadable`] when it cannot be opened.
    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError>;
}

/// A log in a file.
#[derive(Clone, Debug)]
pub struct LogFile {
    path: PathBuf,
    name: String,
}

impl LogFile {
    /// The log at `path`.
    pub fn new(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            name: path.display().to_string(),
        }
    }
}

impl LogSource for LogFile {
    fn name(&self) -> &str {
        &self.name
    }

    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError> {
        if self.path.is_dir() {
            return Err(LogError::of_file(
                &self.name,
                LogProblem::Unreadable {
                    message: "it is a directory, expected a CSV file".to_string(),
                },
            ));
        }
        let file = std::fs::File::open(&self.path).map_err(|e| {
            LogError::of_file(
                &self.name,
                LogProblem::Unreadable {
                    message: e.to_string(),
                },
            )
        })?;
        Ok(Box::new(BufReader::with_capacity(1 << 16, file)))
    }
}

/// A log held in memory, named as if it were a file.
#[derive(Clone, Debug)]
pub struct LogText {
    name: String,
    text: Vec<u8>,
}

impl LogText {
    /// The log `text`, called `name` in messages.
    pub fn new(name: &str, text: impl Into<Vec<u8>>) -> Self {
        Self {
            name: name.to_string(),
            text: text.into(),
        }
    }
}

impl LogSource for LogText {
    fn name(&self) -> &str {
        &self.name
    }

    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError> {
        Ok(Box::new(self.text.as_slice()))
    }
}

/// A CSV stream whose rows hold the `N` columns asked for, as numbers.
pub struct CsvReader<'a, const N: usize> {
    file: String,
    reader: Box<dyn BufRead + 'a>,
    line: u64,
    buf: Vec<u8>,
    columns: [&'static str; N],
    /// Position of each wanted column in a row.
    positions: [usize; N],
    width: usize,
    header: String,
}

impl<'a, const N: usize> CsvReader<'a, N> {
    /// Opens `source` and reads its header, which must name each of `columns` once.
    ///
    /// # Errors
    /// [`LogError`] when the file cannot be read, is empty, or its header lacks a column.
    pub fn open(source: &'a dyn LogSource, columns: [&'static str; N]) -> Result<Self, LogError> {
        let mut reader = Self {
            file: source.name().to_string(),
            reader: source.open()?,
            line: 0,
            buf: Vec::with_capacity(128),
            columns,
            positions: [0; N],
            width: 0,
            header: columns.join(","),
        };
        let expected = reader.header.clone();
        let Some(text) = reader.next_line()? else {
            return Err(LogError::of_file(
                &reader.file,
                LogProblem::Empty { header: expected },
            ));
        };
        let found: Vec<String> = text
            .trim_start_matches('\u{feff}')
            .split(',')
            .map(|f| f.trim().to_string())
            .collect();
        // One pass with a set: the first name seen before (a header of 10⁶ columns is checked
        // in a fraction of a second, where comparing each with all before it took minutes).
        let mut seen = std::collections::HashSet::with_capacity(found.len());
        if let Some(name) = found.iter().find(|name| !seen.insert(name.as_str())) {
            return Err(reader.error(LogProblem::DuplicateColumn { column: echo(name) }));
        }
        let header = echo(&found.join(","));
        for (k, column) in columns.iter().enumerate() {
            match found.iter().position(|f| f == column) {
                Some(p) => reader.positions[k] = p,
                None => {
                    return Err(reader.error(LogProblem::MissingColumn {
                        column,
                        found: header,
                        header: expected,
                    }));
                }
            }
        }
        reader.width = found.len();
        reader.header = header;
        Ok(reader)
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// An error at the current line.
    pub fn error(&self, problem: LogProblem) -> LogError {
        LogError::at(&self.file, self.line, problem)
    }

    /// The next line that is not blank, without its line end; `None` at the end of the file.
    fn next_line(&mut self) -> Result<Option<&str>, LogError> {
        loop {
            self.buf.clear();
            let n = self.reader.read_until(b'\n', &mut self.buf).map_err(|e| {
                LogError::at(
                    &self.file,
                    self.line + 1,
                    LogProblem::Unreadable {
                        message: e.to_string(),
                    },
                )
            })?;
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            let end = self
                .buf
                .iter()
                .rposition(|&b| b != b'\n' && b != b'\r')
                .map_or(0, |i| i + 1);
            if self.buf[..end].iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            let line = self.line;
            let file = &self.file;
            return std::str::from_utf8(&self.buf[..end])
                .map(Some)
                .map_err(|_| LogError::at(file, line, LogProblem::NotText));
        }
    }

    /// The next data row: its line and the wanted columns' values; `None` at the end.
    ///
    /// # Errors
    /// [`LogError`] naming the line when the row has another number of fields than the header,
    /// or a wanted field is not a finite number.
    pub fn next_row(&mut self) -> Result<Option<(u64, [f64; N])>, LogError> {
        let (width, positions, columns) = (self.width, self.positions, self.columns);
        let Some(text) = self.next_line()? else {
            return Ok(None);
        };
        let mut wanted: [&str; N] = [""; N];
        let mut found = 0;
        for (i, field) in text.split(',').enumerate() {
            for (k, &p) in positions.iter().enumerate() {
                if p == i {
                    wanted[k] = field.trim();
                }
            }
            found += 1;
        }
        if found != width {
            return Err(self.error(LogProblem::FieldCount {
                expected: width,
                found,
                header: self.header.clone(),
            }));
        }
        let mut values = [0.0; N];
        for (k, text) in wanted.iter().enumerate() {
            let column = columns[k];
            values[k] = match text.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                Ok(_) => {
                    let text = echo(text);
                    return Err(self.error(LogProblem::NotFinite { column, text }));
                }
                Err(_) => {
                    let text = echo(text);
                    return Err(self.error(LogProblem::NotANumber { column, text }));
                }
            };
        }
        Ok(Some((self.line, values)))
    }
}

/// The accelerometer log as a stream of samples with strictly increasing time stamps.
pub struct AccelReader<'a> {
    csv: CsvReader<'a, 2>,
    previous_s: Option<f64>,
}

impl<'a> AccelReader<'a> {
    /// Opens the accelerometer log `source` and checks its header.
    ///
    /// # Errors
    /// [`LogError`] when it cannot be read or its header lacks `t_s` or `accel_m_s2`.
    pub fn open(source: &'a dyn LogSource) -> Result<Self, LogError> {
        Self::with_column(source, ACCEL_COLUMNS[1])
    }

    /// Opens the accelerometer log `source` reading its samples from `column` instead of
    /// `accel_m_s2` (a log of several axes).
    ///
    /// # Errors
    /// [`LogError`] when it cannot be read or its header lacks `t_s` or `column`.
    pub fn with_column(source: &'a dyn LogSource, column: &'static str) -> Result<Self, LogError> {
        Ok(Self {
            csv: CsvReader::open(source, [ACCEL_COLUMNS[0], column])?,
            previous_s: None,
        })
    }

    /// The next sample; `None` at the end of the log.
    ///
    /// # Errors
    /// [`LogError`] naming the line of a malformed row or of a time stamp not after the previous.
    pub fn next_sample(&mut self) -> Result<Option<AccelSample>, LogError> {
        let Some((line, [t_s, accel_m_s2])) = self.csv.next_row()? else {
            return Ok(None);
        };
        increasing(&self.csv, t_s, &mut self.previous_s)?;
        Ok(Some(AccelSample {
            line,
            t_s,
            accel_m_s2,
        }))
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        self.csv.file()
    }
}

fn increasing<const N: usize>(
    csv: &CsvReader<'_, N>,
    t_s: f64,
    previous_s: &mut Option<f64>,
) -> Result<(), LogError> {
    if let Some(p) = *previous_s
        && t_s <= p
    {
        return Err(csv.error(LogProblem::NotIncreasing { t_s, previous_s: p }));
    }
    *previous_s = Some(t_s);
    Ok(())
}

/// Every fix of the GPS log, in time order: a GPS log is small (one row per fix), so it is held.
///
/// # Errors
/// [`LogError`] naming the line of a malformed row or of a time stamp not after the previous,
/// or the file when it holds no fix.
pub fn read_gps(source: &dyn LogSource) -> Result<Vec<GpsFix>, LogError> {
    let mut csv = CsvReader::open(source, GPS_COLUMNS)?;
    let mut fixes = Vec::new();
    let mut previous_s = None;
    while let Some((line, [t_s, position_m, velocity_m_s])) = csv.next_row()? {
        increasing(&csv, t_s, &mut previous_s)?;
        fixes.push(GpsFix {
            line,
            t_s,
            position_m,
            velocity_m_s,
        });
    }
    if fixes.is_empty() {
        return Err(LogError::of_file(
            csv.file(),
            LogProblem::TooFewRows {
                found: 0,
                needed: 1,
            },
        ));
    }
    Ok(fixes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem_of(text: impl Into<Vec<u8>>) -> (Option<u64>, LogProblem) {
        let src = LogText::new("a.csv", text);
        let mut r = match AccelReader::open(&src) {
            Ok(r) => r,
            Err(e) => return (e.line, e.problem),
        };
        loop {
            match r.next_sample() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("accepted a bad log"),
                Err(e) => return (e.line, e.problem),
            }
        }
    }

    #[test]
    fn reads_rows_in_any_column_order_with_extra_columns() {
        let src = LogText::new(
            "a.csv",
            "\u{feff}temp_c, accel_m_s2 ,t_s\r\n20,1.5,0\n\n21,-2,0.005\n",
        );
        let mut r = AccelReader::open(&src).unwrap();
        let s = r.next_sample().unwrap().unwrap();
        assert_eq!((s.line, s.t_s, s.accel_m_s2), (2, 0.0, 1.5));
        let s = r.next_sample().unwrap().unwrap();
        assert_eq!((s.line, s.t_s, s.accel_m_s2), (4, 0.005, -2.0));
        assert!(r.next_sample().unwrap().is_none());
    }

    #[test]
    fn reads_a_named_axis_column() {
        let src = LogText::new("a.csv", "t_s,ax_m_s2,ay_m_s2\n0,1,2\n0.01,3,4\n");
        let mut r = AccelReader::with_column(&src, "ay_m_s2").unwrap();
        assert_eq!(r.next_sample().unwrap().unwrap().accel_m_s2, 2.0);
        assert_eq!(r.next_sample().unwrap().unwrap().accel_m_s2, 4.0);
        let e = AccelReader::with_column(&src, "az_m_s2").err().unwrap();
        assert!(matches!(
            e.problem,
            LogProblem::MissingColumn {
                column: "az_m_s2",
                ..
            }
        ));
    }

    #[test]
    fn every_problem_names_its_line() {
        assert!(matches!(problem_of(""), (None, LogProblem::Empty { .. })));
        assert!(matches!(
            problem_of("t_s,accel\n0,1\n"),
            (
                Some(1),
                LogProblem::MissingColumn {
                    column: "accel_m_s2",
                    ..
                }
            )
        ));
        assert!(matches!(
            problem_of("t_s,t_s,accel_m_s2\n"),
            (Some(1), LogProblem::DuplicateColumn { .. })
        ));
        assert!(matches!(
            problem_of("t_s,accel_m_s2\n0,1\n0.1,1,3\n"),
            (
                Some(3),
                LogProblem::FieldCount {
                    expected: 2,
                    found: 3,
                    ..
                }
            )
        ));
        assert!(matches!(
            problem_of("t_s,accel_m_s2\n0,x1\n"),
            (
                Some(2),
                LogProblem::NotANumber {
                    column: "accel_m_s2",
                    ..
                }
            )
        ));
        for bad in ["NaN", "inf", "-infinity"] {
            assert!(matches!(
                problem_of(format!("t_s,accel_m_s2\n0,1\n{bad},1\n")),
                (Some(3), LogProblem::NotFinite { column: "t_s", .. })
            ));
        }
        assert!(matches!(
            problem_of("t_s,accel_m_s2\n0,1\n0.01,1\n0.01,1\n"),
            (Some(4), LogProblem::NotIncreasing { .. })
        ));
        assert!(matches!(
            problem_of(&b"t_s,accel_m_s2\n0,1\n\xff,1\n"[..]),
            (Some(3), LogProblem::NotText)
        ));
    }
}
