//! Reading logs: a CSV reader that streams rows and names the file and line of every problem,
//! and the two sensor logs on top of it.
//!
//! A log is UTF-8 text: a header row naming the columns, then one row per sample, fields separated
//! by commas. The header must hold each required column once; other columns are ignored. Blank
//! lines are skipped, a byte-order mark and `\r\n` line ends are accepted, and every field must
//! be a finite number (`NaN` and `inf` are refused).

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use super::block::{BLOCK_BYTES, Feed, Layout, MAX_LINE_BYTES, Rows, parse_block};
use super::{ACCEL_COLUMNS, AccelSample, GPS_COLUMNS, GpsFix};
use crate::input::{LogError, LogProblem, echo};

/// A log read from its start: a file can be read again, a pipe only once.
pub trait LogSource {
    /// The name used in messages: the path as the user gave it.
    fn name(&self) -> &str;

    /// A reader at the start of the log.
    ///
    /// # Errors
    /// [`LogProblem::Unreadable`] when it cannot be opened.
    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError>;

    /// Whether [`LogSource::open`] can start again after a first reading: false for a pipe or
    /// a device.
    fn rereadable(&self) -> bool {
        true
    }

    /// An accelerometer log held as arrays (time stamps in s, samples in m/s², of equal
    /// length; `input::csv::arrays::AccelArrays`): calibrate's pass then reads them in place instead
    /// of parsing text. `None` for a log of text.
    fn accel_columns(&self) -> Option<(&[f64], &[f64])> {
        None
    }
}

/// The two bytes that start a gzip member.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// `reader`, decompressed when its text starts as gzip does (whatever the file's name).
///
/// # Errors
/// The operating system's when the first bytes cannot be read.
pub(crate) fn decompressed<'a>(
    mut reader: Box<dyn BufRead + 'a>,
) -> std::io::Result<Box<dyn BufRead + 'a>> {
    if reader.fill_buf()?.starts_with(&GZIP_MAGIC) {
        let decoder = flate2::bufread::MultiGzDecoder::new(reader);
        return Ok(Box::new(BufReader::with_capacity(1 << 16, decoder)));
    }
    Ok(reader)
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
        let unreadable = |e: std::io::Error| {
            LogError::of_file(
                &self.name,
                LogProblem::Unreadable {
                    message: e.to_string(),
                },
            )
        };
        let file = std::fs::File::open(&self.path).map_err(unreadable)?;
        decompressed(Box::new(BufReader::with_capacity(1 << 16, file))).map_err(unreadable)
    }

    fn rereadable(&self) -> bool {
        // A missing file is reported when it is opened.
        std::fs::metadata(&self.path).map_or(true, |m| m.is_file())
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
        decompressed(Box::new(self.text.as_slice())).map_err(|e| {
            let message = e.to_string();
            LogError::of_file(&self.name, LogProblem::Unreadable { message })
        })
    }
}

/// Opens `source` (gzip-compressed text read transparently) and reads its header, which must
/// name each of `columns` once: where the columns lie, and the text after the header.
///
/// # Errors
/// [`LogError`] when the file cannot be read, is empty, or its header lacks a column or names
/// one twice.
pub fn open_blocks<'a, const N: usize>(
    source: &'a dyn LogSource,
    columns: [&'static str; N],
) -> Result<(Layout<N>, Feed<'a>), LogError> {
    open_blocks_choosing(source, &columns.join(","), |_, _| Ok(columns))
}

/// [`open_blocks`] with the columns chosen from the header: `choose` gets the header's names
/// and its line and returns the columns to read (or the problem with the header), so that a
/// log of one of several layouts is read in one opening (a pipe can be opened only once).
/// `expected` describes the header in the message about an empty file.
///
/// # Errors
/// As [`open_blocks`], and `choose`'s.
pub fn open_blocks_choosing<'a, const N: usize>(
    source: &'a dyn LogSource,
    expected: &str,
    choose: impl FnOnce(&[&str], u64) -> Result<[&'static str; N], LogError>,
) -> Result<(Layout<N>, Feed<'a>), LogError> {
    let reader: Box<dyn Read + 'a> = source.open()?;
    let mut feed = Feed::new(source.name(), reader);
    let Some((text, line)) = feed.header()? else {
        return Err(LogError::of_file(
            source.name(),
            LogProblem::Empty {
                header: expected.to_string(),
            },
        ));
    };
    let at = |problem| LogError::at(source.name(), line, problem);
    let found: Vec<&str> = text
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    // One pass with a set: the first name seen before (a header of 10⁶ columns is checked
    // in a fraction of a second, where comparing each with all before it took minutes).
    let mut seen = std::collections::HashSet::with_capacity(found.len());
    if let Some(name) = found.iter().find(|name| !seen.insert(**name)) {
        return Err(at(LogProblem::DuplicateColumn { column: echo(name) }));
    }
    let columns = choose(&found, line)?;
    let expected = columns.join(",");
    let header = echo(&found.join(","));
    let mut positions = [0; N];
    for (k, column) in columns.iter().enumerate() {
        match found.iter().position(|f| f == column) {
            Some(p) => positions[k] = p,
            None => {
                return Err(at(LogProblem::MissingColumn {
                    column,
                    found: header,
                    header: expected,
                }));
            }
        }
    }
    let layout = Layout {
        file: source.name().to_string(),
        columns,
        positions,
        width: found.len(),
        header,
    };
    Ok((layout, feed))
}

/// A CSV stream whose rows hold the `N` columns asked for, as numbers.
pub struct CsvReader<'a, const N: usize> {
    layout: Layout<N>,
    feed: Feed<'a>,
    rows: Rows<N>,
    next: usize,
    /// The problem that ended the current block, reported after its good rows.
    pending: Option<LogError>,
    /// Line of the last row handed out (the header's before any).
    line: u64,
}

impl<'a, const N: usize> CsvReader<'a, N> {
    /// Opens `source` and reads its header, which must name each of `columns` once.
    ///
    /// # Errors
    /// [`LogError`] when the file cannot be read, is empty, or its header lacks a column.
    pub fn open(source: &'a dyn LogSource, columns: [&'static str; N]) -> Result<Self, LogError> {
        Self::open_choosing(source, &columns.join(","), |_, _| Ok(columns))
    }

    /// Opens `source` reading the columns `choose` picks from its header
    /// ([`open_blocks_choosing`]).
    ///
    /// # Errors
    /// As [`CsvReader::open`], and `choose`'s.
    pub fn open_choosing(
        source: &'a dyn LogSource,
        expected: &str,
        choose: impl FnOnce(&[&str], u64) -> Result<[&'static str; N], LogError>,
    ) -> Result<Self, LogError> {
        let (layout, feed) = open_blocks_choosing(source, expected, choose)?;
        Ok(Self {
            layout,
            line: 1,
            feed,
            rows: Rows::default(),
            next: 0,
            pending: None,
        })
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        &self.layout.file
    }

    /// The columns read, in the order of each row's values.
    pub fn columns(&self) -> [&'static str; N] {
        self.layout.columns
    }

    /// An error at the current line.
    pub fn error(&self, problem: LogProblem) -> LogError {
        LogError::at(&self.layout.file, self.line, problem)
    }

    /// The next data row: its line and the wanted columns' values; `None` at the end.
    ///
    /// # Errors
    /// [`LogError`] naming the line when the row has another number of fields than the header,
    /// or a wanted field is not a finite number.
    pub fn next_row(&mut self) -> Result<Option<(u64, [f64; N])>, LogError> {
        while self.next == self.rows.values.len() {
            if let Some(e) = self.pending.take() {
                return Err(e);
            }
            let Some(block) = self.feed.next_block(BLOCK_BYTES, MAX_LINE_BYTES)? else {
                return Ok(None);
            };
            self.rows.clear();
            self.next = 0;
            self.pending = parse_block(&self.layout, &block, &mut self.rows).err();
        }
        let k = self.next;
        self.next += 1;
        self.line = self.rows.lines[k];
        Ok(Some((self.line, self.rows.values[k])))
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
mod tests;
