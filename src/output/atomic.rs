//! One result file: written whole ([`write_atomic`]) or as a stream ([`AtomicFile`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::{OutputError, Target, io, open_in_place, target, temporaries};

/// Writes `bytes` to `path` atomically (temporary file, then rename), or in place when `path` is
/// a device or a FIFO.
///
/// # Errors
/// [`OutputError`] when the destination cannot be written ([`super::check_file`]) or a step
/// fails; the destination is then untouched and no temporary is left.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    match target(path)? {
        Target::InPlace(real) => {
            let mut f = open_in_place(&real).map_err(io(path))?;
            f.write_all(bytes)
                .and_then(|()| f.flush())
                .map_err(io(path))
        }
        Target::Replace(real) => {
            let tmp = temporaries::beside(&real, "tmp");
            let result = (|| {
                let mut f = temporaries::create(&tmp)?;
                f.write_all(bytes)?;
                f.sync_all()?;
                temporaries::rename(&tmp, &real)
            })();
            if result.is_err() {
                temporaries::remove(&tmp);
            }
            result.map_err(io(path))
        }
    }
}

/// A file written beside its destination under a temporary name and renamed into place by
/// [`AtomicFile::commit`]; dropped without a commit, it is removed and the destination is
/// untouched. A device or a FIFO is written in place.
pub struct AtomicFile {
    /// The destination as the user gave it, for messages.
    path: PathBuf,
    /// Where the file goes (through a symbolic link).
    real: PathBuf,
    /// The temporary; `None` when written in place.
    tmp: Option<PathBuf>,
    file: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Starts writing `dest`.
    ///
    /// # Errors
    /// [`OutputError`] when the destination cannot be written ([`super::check_file`]).
    pub fn create(dest: &Path) -> Result<Self, OutputError> {
        let (real, tmp, file) = match target(dest)? {
            Target::InPlace(real) => {
                let file = open_in_place(&real).map_err(io(dest))?;
                (real, None, file)
            }
            Target::Replace(real) => {
                let tmp = temporaries::beside(&real, "tmp");
                let file = temporaries::create(&tmp).map_err(io(dest))?;
                (real, Some(tmp), file)
            }
        };
        Ok(Self {
            path: dest.to_path_buf(),
            real,
            tmp,
            file: Some(std::io::BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// Writes `bytes`.
    ///
    /// # Errors
    /// [`OutputError`] when the write fails.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), OutputError> {
        let file = self.file.as_mut().expect("open until committed");
        file.write_all(bytes).map_err(io(&self.path))
    }

    /// The writer, for encoders that take one.
    pub fn writer(&mut self) -> &mut impl Write {
        self.file.as_mut().expect("open until committed")
    }

    /// The error `e` met while writing through [`AtomicFile::writer`], naming the destination.
    pub fn error(&self, e: std::io::Error) -> OutputError {
        io(&self.path)(e)
    }

    /// Flushes and renames the file into place.
    ///
    /// # Errors
    /// [`OutputError`] when the flush or the rename fails; the temporary is then removed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let file = self.file.take().expect("committed once");
        let flushed = file.into_inner().map_err(|e| e.into_error());
        let Some(tmp) = self.tmp.take() else {
            return flushed.map(drop).map_err(io(&self.path));
        };
        let result = flushed
            .and_then(|f| f.sync_all())
            .and_then(|()| temporaries::rename(&tmp, &self.real));
        if result.is_err() {
            temporaries::remove(&tmp);
        }
        result.map_err(io(&self.path))
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some()
            && let Some(tmp) = &self.tmp
        {
            temporaries::remove(tmp);
        }
    }
}
