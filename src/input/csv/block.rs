//! The log reader's fast core: the text arrives in blocks of whole lines read with large reads
//! (bounded: no line may exceed [`MAX_LINE_BYTES`]), and a block's rows are parsed from byte
//! slices, numbers by a correctly rounded parser, without an allocation per row.
//!
//! Blocks are cut at line ends wherever the bytes fall, so their parsing can run on several
//! threads and the results, stitched in order, do not depend on how many.

use std::io::Read;

use crate::input::{LogError, LogProblem, echo};

/// The longest data row accepted, bytes: a row is a few numbers, and the limit stops a file
/// without line ends (a device such as `/dev/zero`) from being read without bound.
pub const MAX_LINE_BYTES: usize = 64 << 10;

/// The longest header accepted, bytes: room for a million columns.
pub const MAX_HEADER_BYTES: usize = 16 << 20;

/// Bytes a block is read up to before it is cut at its last line end.
pub const BLOCK_BYTES: usize = 1 << 20;

/// Where the wanted columns of a log lie in its rows.
#[derive(Clone, Debug)]
pub struct Layout<const N: usize> {
    /// The file as the user named it.
    pub file: String,
    /// The wanted columns.
    pub columns: [&'static str; N],
    /// Position of each wanted column in a row.
    pub positions: [usize; N],
    /// Fields of a row.
    pub width: usize,
    /// The header as found, as messages quote it.
    pub header: String,
}

/// Parsed rows: the wanted columns' values and each row's line.
#[derive(Clone, Debug, Default)]
pub struct Rows<const N: usize> {
    /// Values of the wanted columns, in the order asked for.
    pub values: Vec<[f64; N]>,
    /// Line of each row in the file (the header is line 1).
    pub lines: Vec<u64>,
}

impl<const N: usize> Rows<N> {
    /// No rows.
    pub fn clear(&mut self) {
        self.values.clear();
        self.lines.clear();
    }
}

/// A block of whole lines and the number of lines before it.
#[derive(Debug, Default)]
pub struct Block {
    /// The text.
    pub bytes: Vec<u8>,
    /// Lines of the file before the block's first.
    pub lines_before: u64,
}

/// Whether `b` is a character `str::trim` removes (Unicode White_Space in ASCII).
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r')
}

fn trim(mut s: &[u8]) -> &[u8] {
    while let [first, rest @ ..] = s
        && is_space(*first)
    {
        s = rest;
    }
    while let [rest @ .., last] = s
        && is_space(*last)
    {
        s = rest;
    }
    s
}

/// The value of `field` (valid UTF-8), exactly as `str::trim` then `str::parse::<f64>` give
/// it: the fast parser on the ASCII-trimmed bytes, and the standard one whenever it refuses (a
/// field with other white space, or not a number), so that every message is today's.
fn number(field: &[u8], column: &'static str) -> Result<f64, LogProblem> {
    let value = match fast_float2::parse::<f64, _>(trim(field)) {
        Ok(x) => x,
        Err(_) => {
            let text = std::str::from_utf8(field).unwrap_or_default().trim();
            match text.parse::<f64>() {
                Ok(x) => x,
                Err(_) => {
                    let text = echo(text);
                    return Err(LogProblem::NotANumber { column, text });
                }
            }
        }
    };
    if value.is_finite() {
        Ok(value)
    } else {
        let text = echo(std::str::from_utf8(field).unwrap_or_default().trim());
        Err(LogProblem::NotFinite { column, text })
    }
}

impl<const N: usize> Layout<N> {
    /// The wanted values of a non-blank line of `found` fields, the wanted ones `wanted`.
    fn values(&self, wanted: &[&[u8]; N], found: usize) -> Result<[f64; N], LogProblem> {
        // The field count first, then the numbers in the order of the columns asked for.
        if found != self.width {
            return Err(LogProblem::FieldCount {
                expected: self.width,
                found,
                header: self.header.clone(),
            });
        }
        let mut values = [0.0; N];
        for (k, field) in wanted.iter().enumerate() {
            values[k] = number(field, self.columns[k])?;
        }
        Ok(values)
    }
}

/// The line ends of `bytes`.
pub fn count_lines(bytes: &[u8]) -> u64 {
    memchr::memchr_iter(b'\n', bytes).count() as u64
}

/// Parses every row of `block` into `rows` (appending), up to the first problem, which it
/// returns: blank lines are skipped, `\r` before a line end is dropped, a line that is not
/// UTF-8 or longer than [`MAX_LINE_BYTES`] is refused.
///
/// The commas and line ends are found in one vectorized scan of the block; each field is
/// looked at once.
///
/// # Errors
/// [`LogError`] naming the line of the first bad row; the rows before it are in `rows`.
pub fn parse_block<const N: usize>(
    layout: &Layout<N>,
    block: &Block,
    rows: &mut Rows<N>,
) -> Result<(), LogError> {
    let bytes = block.bytes.as_slice();
    // The first byte that is not UTF-8: the lines before it parse, its own is refused.
    let valid = match std::str::from_utf8(bytes) {
        Ok(_) => bytes.len(),
        Err(e) => e.valid_up_to(),
    };
    let mut line = block.lines_before;
    let (mut line_start, mut field_start, mut found) = (0, 0, 0);
    let mut wanted: [&[u8]; N] = [&[]; N];
    let mut separators = memchr::memchr2_iter(b',', b'\n', bytes);
    loop {
        let separator = separators.next();
        let end = separator.unwrap_or(bytes.len());
        for (k, &p) in layout.positions.iter().enumerate() {
            if p == found {
                wanted[k] = &bytes[field_start..end];
            }
        }
        found += 1;
        field_start = end + 1;
        if separator.is_some_and(|i| bytes[i] == b',') {
            continue;
        }
        if separator.is_none() && line_start == bytes.len() {
            return Ok(());
        }
        line += 1;
        let at = |problem| LogError::at(&layout.file, line, problem);
        if end > valid {
            return Err(at(LogProblem::NotText));
        }
        if end - line_start > MAX_LINE_BYTES {
            let limit_bytes = MAX_LINE_BYTES;
            return Err(at(LogProblem::LineTooLong { limit_bytes }));
        }
        let mut text = &bytes[line_start..end];
        while let [rest @ .., b'\r'] = text {
            text = rest;
        }
        if !text.iter().all(u8::is_ascii_whitespace) {
            rows.values.push(layout.values(&wanted, found).map_err(at)?);
            rows.lines.push(line);
        }
        if separator.is_none() {
            return Ok(());
        }
        (line_start, found) = (end + 1, 0);
    }
}

/// A log's text read in blocks of whole lines.
pub struct Feed<'a> {
    file: String,
    reader: Box<dyn Read + 'a>,
    /// The start of a line read with the previous block.
    carry: Vec<u8>,
    /// Lines of the file before `carry`.
    lines_before: u64,
    eof: bool,
}

impl<'a> Feed<'a> {
    /// The text of `reader`, called `file` in messages.
    pub fn new(file: &str, reader: Box<dyn Read + 'a>) -> Self {
        Self {
            file: file.to_string(),
            reader,
            carry: Vec::new(),
            lines_before: 0,
            eof: false,
        }
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// Reads into `bytes` until it holds `target` bytes or the text ends.
    fn fill(&mut self, bytes: &mut Vec<u8>, target: usize) -> Result<(), LogError> {
        if bytes.len() >= target || self.eof {
            return Ok(());
        }
        let len = bytes.len();
        // `read_to_end` of a `Take` reads into the spare capacity without zeroing it first, and
        // stops at `target` bytes or the end of the text.
        let wanted = (target - len) as u64;
        let read = (&mut self.reader).take(wanted).read_to_end(bytes);
        let n = read.map_err(|e| {
            bytes.truncate(len);
            let line = self.lines_before + count_lines(bytes) + 1;
            let message = e.to_string();
            LogError::at(&self.file, line, LogProblem::Unreadable { message })
        })?;
        self.eof = (n as u64) < wanted;
        Ok(())
    }

    /// The next block of whole lines, about `target` bytes (at least one line); `None` at the
    /// end of the text.
    ///
    /// # Errors
    /// [`LogProblem::Unreadable`] when a read fails; [`LogProblem::LineTooLong`] when a line
    /// exceeds `limit` bytes.
    pub fn next_block(&mut self, target: usize, limit: usize) -> Result<Option<Block>, LogError> {
        self.next_block_in(Vec::new(), target, limit)
    }

    /// As [`Feed::next_block`], the block's text in `bytes` (a buffer used before: its
    /// allocation is kept, its content dropped).
    ///
    /// # Errors
    /// As [`Feed::next_block`].
    pub fn next_block_in(
        &mut self,
        mut bytes: Vec<u8>,
        target: usize,
        limit: usize,
    ) -> Result<Option<Block>, LogError> {
        bytes.clear();
        bytes.reserve(target.max(self.carry.len() + 1));
        bytes.extend_from_slice(&self.carry);
        self.carry.clear();
        let mut want = target.max(bytes.len() + 1);
        // Bytes already searched for a line end.
        let mut searched = 0;
        loop {
            self.fill(&mut bytes, want)?;
            if self.eof {
                break;
            }
            if let Some(i) = memchr::memrchr(b'\n', &bytes[searched..]) {
                let end = searched + i + 1;
                self.carry.extend_from_slice(&bytes[end..]);
                bytes.truncate(end);
                break;
            }
            if bytes.len() > limit {
                let problem = LogProblem::LineTooLong { limit_bytes: limit };
                return Err(LogError::at(&self.file, self.lines_before + 1, problem));
            }
            // A long line: read on in steps that double, so that it is searched once.
            searched = bytes.len();
            want = bytes.len() + target.max(bytes.len());
        }
        if bytes.is_empty() {
            return Ok(None);
        }
        let block = Block {
            lines_before: self.lines_before,
            bytes,
        };
        self.lines_before += count_lines(&block.bytes);
        Ok(Some(block))
    }

    /// The first line that is not blank, without its line end, and the number of lines up to
    /// it; `None` when the text holds no such line.
    ///
    /// # Errors
    /// As [`Feed::next_block`], with [`MAX_HEADER_BYTES`] as the limit; [`LogProblem::NotText`]
    /// when the line is not UTF-8.
    pub fn header(&mut self) -> Result<Option<(String, u64)>, LogError> {
        loop {
            let Some(mut block) = self.next_block(1 << 16, MAX_HEADER_BYTES)? else {
                return Ok(None);
            };
            // Keep the first line; the rest goes back in front of the next block.
            let end = memchr::memchr(b'\n', &block.bytes).map_or(block.bytes.len(), |i| i + 1);
            let mut rest = block.bytes.split_off(end);
            rest.append(&mut self.carry);
            self.carry = rest;
            self.lines_before = block.lines_before + 1;
            let line = self.lines_before;
            let mut text = block.bytes.as_slice();
            while let [rest @ .., b'\n' | b'\r'] = text {
                text = rest;
            }
            if text.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            return match std::str::from_utf8(text) {
                Ok(t) => Ok(Some((t.to_string(), line))),
                Err(_) => Err(LogError::at(&self.file, line, LogProblem::NotText)),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_parser_accepts_only_what_the_standard_one_does_with_the_same_bits() {
        // Every string of up to 4 characters over an alphabet of number parts and look-alikes.
        let alphabet = b"019+-.eEinfatyNI_x ";
        let mut checked = 0;
        let mut accepted = 0;
        for len in 0..=4u32 {
            for code in 0..alphabet.len().pow(len) {
                let mut c = code;
                let s: Vec<u8> = (0..len)
                    .map(|_| {
                        let b = alphabet[c % alphabet.len()];
                        c /= alphabet.len();
                        b
                    })
                    .collect();
                let text = std::str::from_utf8(&s).unwrap();
                let standard = text.trim().parse::<f64>();
                match number(&s, "x") {
                    Ok(x) => {
                        accepted += 1;
                        assert_eq!(standard.map(f64::to_bits), Ok(x.to_bits()), "`{text}`");
                    }
                    Err(LogProblem::NotFinite { .. }) => {
                        assert!(standard.is_ok_and(|x| !x.is_finite()), "`{text}`")
                    }
                    Err(_) => assert!(standard.is_err(), "`{text}`"),
                }
                checked += 1;
            }
        }
        assert!(
            accepted > 500 && checked > 100_000,
            "{accepted} of {checked}"
        );
        for text in [
            "1e308",
            "2.2250738585072014e-308",
            "0.1",
            "-7.5e-3",
            " 3 ",
            "\u{a0}4",
        ] {
            let x = number(text.as_bytes(), "x").unwrap();
            assert_eq!(x.to_bits(), text.trim().parse::<f64>().unwrap().to_bits());
        }
    }

    fn feed(text: &'static [u8]) -> Feed<'static> {
        Feed::new("a.csv", Box::new(text))
    }

    #[test]
    fn blocks_end_at_line_ends_and_count_lines() {
        let mut f = feed(b"h\n1,2\n3,4\n5,6");
        assert_eq!(f.header().unwrap(), Some(("h".to_string(), 1)));
        let b = f.next_block(3, 100).unwrap().unwrap();
        assert_eq!(
            (b.bytes.as_slice(), b.lines_before),
            (&b"1,2\n3,4\n5,6"[..], 1)
        );
        let mut f = feed(b"1,2\n3,4\n5,6");
        let b = f.next_block(3, 100).unwrap().unwrap();
        assert_eq!((b.bytes.as_slice(), b.lines_before), (&b"1,2\n"[..], 0));
        let b = f.next_block(8, 100).unwrap().unwrap();
        assert_eq!((b.bytes.as_slice(), b.lines_before), (&b"3,4\n5,6"[..], 1));
        assert!(f.next_block(8, 100).unwrap().is_none());
    }

    #[test]
    fn a_line_beyond_the_limit_is_refused_without_reading_on() {
        let mut zeros = std::io::repeat(0).take(u64::MAX);
        let mut f = Feed::new("zero", Box::new(&mut zeros));
        let e = f.header().unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(matches!(e.problem, LogProblem::LineTooLong { .. }));
        let mut f = feed(b"12345678901234567890\n");
        let e = f.next_block(4, 8).unwrap_err();
        assert_eq!(e.line, Some(1));
    }
}
