//! The temporaries of this process: created, renamed and removed under one lock, so that on
//! SIGINT or SIGTERM every one still there is removed before the process ends.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::OutputError;

/// The temporaries that exist now.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
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
    let file = std::fs::File::create(path)?;
    live.push(path.to_path_buf());
    Ok(file)
}

/// Removes the temporary `path`.
pub(super) fn remove(path: &Path) {
    let mut live = live();
    let _ = std::fs::remove_file(path);
    live.retain(|p| p != path);
}

/// Renames the temporary `tmp` onto `dest`.
pub(super) fn rename(tmp: &Path, dest: &Path) -> std::io::Result<()> {
    let mut live = live();
    std::fs::rename(tmp, dest)?;
    live.retain(|p| p != tmp);
    Ok(())
}

/// Creates the temporary `path` and removes it: whether a file can be made there.
pub(super) fn try_creating(path: &Path) -> std::io::Result<()> {
    create(path).map(drop)?;
    remove(path);
    Ok(())
}

/// Removes this process's temporaries when it receives SIGINT, SIGTERM or SIGHUP (Ctrl-C, `kill`,
/// `scancel`, a batch system's time limit), then ends it as the signal would have. Call once,
/// early in `main`.
///
/// # Errors
/// The operating system's, when the handlers cannot be installed.
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Held until the process ends: no temporary is created or renamed meanwhile.
            let live = live();
            for path in live.iter() {
                let _ = std::fs::remove_file(path);
            }
            let _ = signal_hook::low_level::emulate_default_handler(signal);
            std::process::exit(128 + signal);
        }
    });
    Ok(())
}

/// A hidden scratch file beside an output, for data kept until the output can be written (a
/// shard's blocks, spooled until its run time is known): removed when dropped, and on SIGINT or
/// SIGTERM. Its errors name the output.
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
        let path = if special {
            let name = dest.file_name().unwrap_or_default().to_string_lossy();
            beside(
                &std::env::temp_dir().join(format!("accelcal-{name}")),
                suffix,
            )
        } else {
            beside(dest, suffix)
        };
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
