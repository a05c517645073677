//! Temporaries left by processes that no longer run (killed by SIGKILL, by the out-of-memory
//! killer, by a power cut: nothing could remove them). Each time a destination is checked or
//! staged, the temporaries of that destination beside it whose process is gone are removed, and
//! recorded for the caller to report ([`take_removed_stale_temporaries`]); the library prints
//! nothing.
//!
//! A file is removed only when all of these hold: its name is exactly the temporary name of that
//! destination, `.NAME.PID.SUFFIX` (`PID` in decimal without a leading zero, as
//! [`super::temporaries`] writes it); it is a regular file (not a link, not a directory) owned by
//! this process's user; `PID` is not this process; and no process `PID` exists. Whether a process
//! exists is read from `/proc`, so off Linux, or where `/proc` is not mounted, nothing is removed.
//! `/proc` shows the processes of this machine only: a temporary that a run on another machine
//! writes into a shared directory (NFS) under the same name looks stale from here.

use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

/// A temporary of a process that no longer runs, removed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StaleTemporary {
    /// Where it was.
    pub path: PathBuf,
    /// The process that wrote it, from its name.
    pub pid: u32,
    /// Its size when removed, bytes.
    pub bytes: u64,
}

/// The stale temporaries removed and not yet taken.
static REMOVED: Mutex<Vec<StaleTemporary>> = Mutex::new(Vec::new());

/// The stale temporaries removed since the last call (in the order they were removed), for the
/// caller to report.
pub fn take_removed_stale_temporaries() -> Vec<StaleTemporary> {
    std::mem::take(&mut *REMOVED.lock().unwrap_or_else(PoisonError::into_inner))
}

/// The process id in `name` when `name` is `.{dest}.{PID}.{suffix}`, the temporary name of the
/// destination file named `dest`, with `PID` written as `u32`'s `Display` writes it.
pub(super) fn pid_in(name: &OsStr, dest: &OsStr, suffix: &str) -> Option<u32> {
    let rest = name.as_bytes().strip_prefix(b".")?;
    let rest = rest.strip_prefix(dest.as_bytes())?.strip_prefix(b".")?;
    let digits = rest.strip_suffix(suffix.as_bytes())?.strip_suffix(b".")?;
    let well_formed = digits.first().is_some_and(|d| (b'1'..=b'9').contains(d))
        && digits.iter().all(u8::is_ascii_digit);
    if !well_formed {
        return None;
    }
    std::str::from_utf8(digits).ok()?.parse().ok()
}

/// What this machine says about its processes: this process's user, and whether a process id is
/// in use. `None` off Linux or without `/proc`, where nothing can be told.
struct Processes {
    /// The user of this process (the owner of `/proc/self`).
    uid: u32,
}

impl Processes {
    fn here() -> Option<Self> {
        use std::os::unix::fs::MetadataExt;
        if !cfg!(target_os = "linux") {
            return None;
        }
        let me = std::fs::metadata("/proc/self").ok()?;
        Some(Self { uid: me.uid() })
    }

    /// Whether process `pid` surely no longer runs: `/proc/PID` is absent (an error reading
    /// `/proc` counts as running).
    fn is_gone(&self, pid: u32) -> bool {
        Path::new("/proc")
            .join(pid.to_string())
            .try_exists()
            .is_ok_and(|exists| !exists)
    }
}

/// Removes the temporaries `.NAME.PID.{suffix}` of the destination `dest` that sit beside it and
/// whose process no longer runs (see the module's documentation), and records them.
pub(super) fn remove_stale(dest: &Path, suffix: &str) {
    use std::os::unix::fs::MetadataExt;
    let Some(name) = dest.file_name() else {
        return;
    };
    let Some(processes) = Processes::here() else {
        return;
    };
    let Ok(entries) = std::fs::read_dir(super::parent_of(dest)) else {
        return;
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let Some(pid) = pid_in(&entry.file_name(), name, suffix) else {
            continue;
        };
        if pid == std::process::id() {
            // This process's own: the registry of its temporaries decides.
            continue;
        }
        let path = dest.with_file_name(entry.file_name());
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if !meta.is_file() || meta.uid() != processes.uid || !processes.is_gone(pid) {
            continue;
        }
        if std::fs::remove_file(&path).is_ok() {
            removed.push(StaleTemporary {
                path,
                pid,
                bytes: meta.len(),
            });
        }
    }
    if !removed.is_empty() {
        REMOVED
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .append(&mut removed);
    }
}
