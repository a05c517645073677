//! The temporaries of this process: created, renamed and removed under one lock, so that on
//! SIGINT, SIGTERM or SIGHUP every one still there is removed, and none is made afterwards. What
//! the process then does (end as the signal would) is its caller's choice: the library never
//! ends the process.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::OutputError;

/// The temporaries of this process.
struct Registry {
    /// Those that exist now.
    paths: Vec<PathBuf>,
    /// The signal that removed them, after which none is created or renamed.
    ended_by: Option<i32>,
}

static LIVE: Mutex<Registry> = Mutex::new(Registry {
    paths: Vec::new(),
    ended_by: None,
});

fn live() -> MutexGuard<'static, Registry> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Registry {
    /// An error once a signal removed the temporaries: none is created or renamed then.
    fn still_open(&self) -> std::io::Result<()> {
        match self.ended_by {
            None => Ok(()),
            Some(signal) => Err(std::io::Error::other(format!(
                "interrupted by signal {signal}"
            ))),
        }
    }
}

/// The hidden name beside `dest` for this process: `.NAME.PID.SUFFIX`.
pub(super) fn beside(dest: &Path, suffix: &str) -> PathBuf {
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dest.with_file_name(format!(".{name}.{}.{suffix}", std::process::id()))
}

/// Creates the temporary `path` (empty), to be removed on SIGINT or SIGTERM until it is renamed
/// or removed.
pub(super) fn create(path: &Path) -> std::io::Result<std::fs::File> {
    let mut live = live();
    live.still_open()?;
    let file = std::fs::File::create(path)?;
    live.paths.push(path.to_path_buf());
    Ok(file)
}

/// Removes the temporary `path`.
pub(super) fn remove(path: &Path) {
    let mut live = live();
    let _ = std::fs::remove_file(path);
    live.paths.retain(|p| p != path);
}

/// Renames the temporary `tmp` onto `dest`.
pub(super) fn rename(tmp: &Path, dest: &Path) -> std::io::Result<()> {
    let mut live = live();
    live.still_open()?;
    std::fs::rename(tmp, dest)?;
    live.paths.retain(|p| p != tmp);
    Ok(())
}

/// Creates the temporary `path` and removes it: whether a file can be made there.
pub(super) fn try_creating(path: &Path) -> std::io::Result<()> {
    create(path).map(drop)?;
    remove(path);
    Ok(())
}

/// Removes this process's temporaries when it receives SIGINT, SIGTERM or SIGHUP (Ctrl-C, `kill`,
/// `scancel`, a batch system's time limit), then calls `then` with the signal's number. Call
/// once, early in `main`.
///
/// `then` runs while the temporaries are locked: until it returns, nothing is created, renamed or
/// removed, so a program that ends there (as the signal would have: `accelcal` does) ends with
/// no temporary and no half-placed output. Once it returns, creating or renaming a temporary
/// fails with "interrupted by signal N"; the next signal calls `then` again.
///
/// # Errors
/// The operating system's, when the handlers cannot be installed.
pub fn remove_temporaries_on_signals<F>(mut then: F) -> std::io::Result<()>
where
    F: FnMut(i32) + Send + 'static,
{
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::spawn(move || {
        for signal in signals.forever() {
            let mut live = live();
            for path in live.paths.drain(..) {
                let _ = std::fs::remove_file(path);
            }
            live.ended_by = Some(signal);
            then(signal);
        }
    });
    Ok(())
}

/// A hidden scratch file beside an output, for data kept until the output can be written (a
/// shard's blocks, spooled until its run time is known): removed when dropped, and on SIGINT or
/// SIGTERM; those of processes that no longer run, left beside the output under the same name
/// and suffix, are removed when it is created. Its errors name the output.
#[derive(Debug)]
pub struct ScratchFile {
    path: PathBuf,
    dest: PathBuf,
}

impl ScratchFile {
    /// Creates the scratch file `.NAME.PID.SUFFIX` beside the output `dest`, open for writing;
    /// in the temporary directory (`TMPDIR`) when `dest` is a device or a FIFO, whose directory
    /// (`/dev`) is no place for it.
    ///
    /// # Errors
    /// [`OutputError`] naming `dest` when it cannot be created.
    pub fn beside(dest: &Path, suffix: &str) -> Result<(Self, std::fs::File), OutputError> {
        let special = std::fs::metadata(dest).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let base = if special {
            let name = dest.file_name().unwrap_or_default().to_string_lossy();
            std::env::temp_dir().join(format!("accelcal-{name}"))
        } else {
            dest.to_path_buf()
        };
        super::stale::remove_stale(&base, suffix);
        let path = beside(&base, suffix);
        let file = create(&path).map_err(super::io(dest))?;
        let scratch = Self {
            path,
            dest: dest.to_path_buf(),
        };
        Ok((scratch, file))
    }

    /// Opens the scratch file for reading.
    ///
    /// # Errors
    /// [`OutputError`] naming the output when it cannot be opened.
    pub fn open(&self) -> Result<std::fs::File, OutputError> {
        std::fs::File::open(&self.path).map_err(super::io(&self.dest))
    }

    /// The error `e` met while writing or reading the scratch file, naming the output.
    pub fn error(&self, e: std::io::Error) -> OutputError {
        super::io(&self.dest)(e)
    }
}

impl Drop for ScratchFile {
    fn drop(&mut self) {
        remove(&self.path);
    }
}
