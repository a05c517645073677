//! A log that can be read only once — a pipe, a FIFO, a device — copied as it arrives to an
//! anonymous temporary file, which is then read as a file is, as often as the analysis needs
//! (`allan --imu`'s streamed analysis reads it twice): memory stays that of the streams, whatever the length.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use crate::input::container::{Kind, copy_stream};
use crate::input::csv::read::{LogSource, decompressed};
use crate::input::{LogError, LogProblem};

/// The bytes of a log read once, kept in a temporary file (unlinked at creation: removed
/// however the process ends).
#[derive(Debug)]
pub struct PipedLog {
    name: String,
    file: File,
}

impl PipedLog {
    /// Copies every byte of `path` (as it is: gzip is told when the copy is read) to a temporary
    /// file in `spill_dir`, once its first bytes tell text or gzip.
    ///
    /// # Errors
    /// [`LogProblem::Unreadable`] naming `path` when it cannot be read or its first bytes are
    /// not text (binary data, a recording; nothing is copied then), or the temporary file when
    /// it cannot be made or written.
    pub fn copy(path: &Path, spill_dir: &Path) -> Result<Self, LogError> {
        let name = path.display().to_string();
        match copy_stream(path, spill_dir, CSV_EXPECTED)? {
            (Kind::Text | Kind::Gzip, file) => Ok(Self::from_copy(&name, file)),
            (kind, _) => {
                let message = format!("{}, not a CSV log: expected {CSV_EXPECTED}", kind.words());
                Err(LogError::of_file(&name, LogProblem::Unreadable { message }))
            }
        }
    }

    /// The log `name` whose bytes were copied to `file`.
    pub fn from_copy(name: &str, file: File) -> Self {
        Self {
            name: name.to_string(),
            file,
        }
    }
}

/// What a CSV log is, in the words of a message refusing another.
pub const CSV_EXPECTED: &str = "a CSV log (UTF-8 text: a header row naming the columns, then \
                                rows of numbers)";

/// The copy read from its start, by positioned reads (no shared offset).
struct FromStart<'a> {
    file: &'a File,
    at: u64,
}

impl Read for FromStart<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let k = read_at(self.file, out, self.at)?;
        self.at += k as u64;
        Ok(k)
    }
}

#[cfg(unix)]
fn read_at(file: &File, out: &mut [u8], at: u64) -> std::io::Result<usize> {
    std::os::unix::fs::FileExt::read_at(file, out, at)
}

#[cfg(windows)]
fn read_at(file: &File, out: &mut [u8], at: u64) -> std::io::Result<usize> {
    std::os::windows::fs::FileExt::seek_read(file, out, at)
}

impl LogSource for PipedLog {
    fn name(&self) -> &str {
        &self.name
    }

    fn open(&self) -> Result<Box<dyn BufRead + '_>, LogError> {
        let reader = BufReader::with_capacity(
            1 << 16,
            FromStart {
                file: &self.file,
                at: 0,
            },
        );
        decompressed(Box::new(reader)).map_err(|e| {
            let message = e.to_string();
            LogError::of_file(&self.name, LogProblem::Unreadable { message })
        })
    }
}
