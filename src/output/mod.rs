//! Writing results without clobbering: every file is written beside its destination under a
//! hidden temporary name and renamed into place, so a run that fails leaves earlier files
//! untouched, and leaves no temporary behind (removed on an error, and on SIGINT or SIGTERM once
//! [`remove_temporaries_on_signals`] is called). A run killed by SIGKILL cannot remove its own: the
//! next run that checks or stages the same destination removes those of processes that no
//! longer run, and lists them in [`take_removed_stale_temporaries`] (the `stale` module says
//! which files qualify).
//!
//! A destination that exists and is neither a regular file nor a directory (a character device
//! such as `/dev/null`, `/dev/stdout` or `/dev/full`, a FIFO) is written in place: renaming onto
//! it would replace the device with a regular file. A destination that is a symbolic link to a
//! file is written through the link, which stays.
//!
//! Every destination can be checked before the work that fills it starts ([`check_file`],
//! [`check_directory`]): a missing directory, a directory in the way, or a place where nothing can
//! be written is then an error at once rather than after a long run. Errors name the user's path
//! and the operating system's error once, never a temporary.

use std::path::{Path, PathBuf};

use thiserror::Error;

mod atomic;
mod staged;
mod stale;
mod temporaries;
#[cfg(test)]
mod tests;

pub use atomic::{AtomicFile, write_atomic};
pub use staged::{StagedFiles, write_all_atomic};
pub use stale::{StaleTemporary, take_removed_stale_temporaries};
pub use temporaries::{ScratchFile, remove_temporaries_on_signals};

/// A result file that could not be written. Nothing was replaced.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The destination is a directory.
    #[error("cannot write {}: it is a directory", path.display())]
    IsDirectory {
        /// The destination.
        path: PathBuf,
    },
    /// The directory of the destination does not exist.
    #[error("cannot write {}: the directory {} does not exist", path.display(), dir.display())]
    NoDirectory {
        /// The destination.
        path: PathBuf,
        /// Its directory.
        dir: PathBuf,
    },
    /// What should hold the destination is not a directory.
    #[error("cannot write {}: {} is not a directory", path.display(), dir.display())]
    NotADirectory {
        /// The destination.
        path: PathBuf,
        /// What is not a directory.
        dir: PathBuf,
    },
    /// The operating system refused a step (creating, writing, renaming into place).
    #[error("cannot write {}: {error}", path.display())]
    Io {
        /// The destination, as the user gave it.
        path: PathBuf,
        /// The operating system's error (shown in this message, not chained again).
        error: std::io::Error,
    },
}

/// The [`OutputError::Io`] of the destination `path`.
fn io(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError {
    let path = path.to_path_buf();
    move |error| OutputError::Io { path, error }
}

/// How a destination is written.
enum Target {
    /// In place: a device or a FIFO, opened for writing.
    InPlace(PathBuf),
    /// Beside it under a temporary name, then renamed onto this path (the destination, or the
    /// file its symbolic link points to).
    Replace(PathBuf),
}

/// The directory of `path` (`.` for a bare file name).
fn parent_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Opens the special file `path` for writing, in place.
fn open_in_place(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::OpenOptions::new().write(true).open(path)
}

/// How to write the destination `path`, once it is checked: not a directory, in a directory
/// that exists and where a file can be created (a temporary is created there and removed, and
/// the stale temporaries of `path` there too), or a device that opens for writing (a FIFO is not
/// opened: that waits for its reader).
fn target(path: &Path) -> Result<Target, OutputError> {
    use std::io::ErrorKind;
    use std::os::unix::fs::FileTypeExt;
    let real = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).map_err(io(path))?,
        _ => path.to_path_buf(),
    };
    match std::fs::metadata(&real) {
        Ok(m) if m.is_dir() => {
            return Err(OutputError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        Ok(m) if !m.is_file() => {
            if !m.file_type().is_fifo() {
                open_in_place(&real).map_err(io(path))?;
            }
            return Ok(Target::InPlace(real));
        }
        Ok(_) => {}
        Err(e) if matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory) => {}
        Err(e) => return Err(io(path)(e)),
    }
    let dir = parent_of(&real);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(OutputError::NotADirectory {
                path: path.to_path_buf(),
                dir,
            });
        }
        Err(e) if e.kind() == ErrorKind::NotFound => {
            return Err(OutputError::NoDirectory {
                path: path.to_path_buf(),
                dir,
            });
        }
        Err(e) => return Err(io(path)(e)),
    }
    stale::remove_stale(&real, "tmp");
    temporaries::try_creating(&temporaries::beside(&real, "tmp")).map_err(io(path))?;
    Ok(Target::Replace(real))
}

/// Checks that the file `path` can be written, before the work that fills it; removes the
/// temporaries of `path` left beside it by processes that no longer run.
///
/// # Errors
/// [`OutputError`] when `path` is a directory, its directory does not exist or is not one, or
/// nothing can be created there (read-only, no permission), or it is a device that cannot be
/// opened for writing.
pub fn check_file(path: &Path) -> Result<(), OutputError> {
    target(path).map(drop)
}

/// Checks that the files `names` can be written into the directory `dir`, before the work that
/// fills them: `dir` exists and each file can be written ([`check_file`]), or `dir` does not
/// exist yet and can be created (its nearest existing ancestor is a directory where a file can be
/// created).
///
/// # Errors
/// [`OutputError`] naming the first destination that cannot be written.
pub fn check_directory(dir: &Path, names: &[&str]) -> Result<(), OutputError> {
    use std::io::ErrorKind;
    let first = dir.join(names.first().copied().unwrap_or_default());
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => return names.iter().try_for_each(|n| check_file(&dir.join(n))),
        Ok(_) => {
            return Err(OutputError::NotADirectory {
                path: first,
                dir: dir.to_path_buf(),
            });
        }
        Err(e) if matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory) => {}
        Err(e) => return Err(io(&first)(e)),
    }
    // Created when the files are written: the nearest ancestor that exists must take it.
    let mut ancestor = parent_of(dir);
    while !ancestor.exists() && ancestor != Path::new(".") {
        ancestor = parent_of(&ancestor);
    }
    if !ancestor.is_dir() {
        return Err(OutputError::NotADirectory {
            path: first,
            dir: ancestor,
        });
    }
    let probe = ancestor.join("accelcal");
    stale::remove_stale(&probe, "tmp");
    temporaries::try_creating(&temporaries::beside(&probe, "tmp")).map_err(io(&first))
}
