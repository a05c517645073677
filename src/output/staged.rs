//! Several result files put in place together: written whole ([`write_all_atomic`]) or as
//! streams ([`StagedFiles`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::{OutputError, Target, check_directory, io, open_in_place, target, temporaries};

/// Writes several files into `dir` (created if missing): all are written to temporaries first,
/// and only put in place once every one was written; a device or a FIFO among them is written
/// in place then. Every destination is checked before anything is written.
///
/// # Errors
/// [`OutputError`] when a destination cannot be written ([`super::check_directory`]) or a step
/// fails; earlier files are then untouched and no temporary is left.
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> Result<(), OutputError> {
    let names: Vec<&str> = files.iter().map(|f| f.0).collect();
    check_directory(dir, &names)?;
    std::fs::create_dir_all(dir).map_err(io(&dir.join(names.first().unwrap_or(&""))))?;
    // (the user's path, where it goes, its temporary if renamed into place, its bytes)
    let mut staged: Vec<(PathBuf, Target, Option<PathBuf>, &[u8])> = Vec::new();
    let remove_staged = |staged: &[(PathBuf, Target, Option<PathBuf>, &[u8])]| {
        for tmp in staged.iter().filter_map(|s| s.2.as_ref()) {
            temporaries::remove(tmp);
        }
    };
    for (name, bytes) in files {
        let dest = dir.join(name);
        let written = target(&dest).and_then(|t| match &t {
            Target::InPlace(_) => Ok((t, None)),
            Target::Replace(real) => {
                let tmp = temporaries::beside(real, "tmp");
                let result = temporaries::create(&tmp).and_then(|mut f| {
                    f.write_all(bytes)?;
                    f.sync_all()
                });
                if let Err(e) = result {
                    temporaries::remove(&tmp);
                    return Err(io(&dest)(e));
                }
                Ok((t, Some(tmp)))
            }
        });
        match written {
            Ok((t, tmp)) => staged.push((dest, t, tmp, bytes)),
            Err(e) => {
                remove_staged(&staged);
                return Err(e);
            }
        }
    }
    for (k, (dest, t, tmp, bytes)) in staged.iter().enumerate() {
        let placed = match (t, tmp) {
            (Target::Replace(real), Some(tmp)) => temporaries::rename(tmp, real),
            (Target::InPlace(real), _) | (Target::Replace(real), None) => {
                open_in_place(real).and_then(|mut f| f.write_all(bytes).and_then(|()| f.flush()))
            }
        };
        if let Err(e) = placed {
            remove_staged(&staged[k..]);
            return Err(io(dest)(e));
        }
    }
    Ok(())
}

/// Result files written as streams and put in place together. Each is written beside its
/// destination under a temporary name (a device or a FIFO in place); [`StagedFiles::commit`]
/// renames them all once every one was written. Dropped without a commit (a failed run), it
/// removes its temporaries, and the directory too when it created it: files already there stay
/// untouched.
#[derive(Debug)]
pub struct StagedFiles {
    dir: PathBuf,
    created_dir: bool,
    files: Vec<Staged>,
    committed: bool,
}

#[derive(Debug)]
struct Staged {
    name: String,
    /// Its temporary; `None` when written in place.
    tmp: Option<PathBuf>,
    /// The destination as the user gave it, for messages.
    dest: PathBuf,
    /// Where it goes (through a symbolic link).
    real: PathBuf,
    writer: Option<std::io::BufWriter<std::fs::File>>,
}

impl StagedFiles {
    /// Stages the files `names` in `dir` (created if missing): opens a temporary beside each.
    ///
    /// # Errors
    /// [`OutputError`] when a destination cannot be written ([`super::check_directory`]);
    /// nothing is left behind.
    pub fn create(dir: &Path, names: &[&str]) -> Result<Self, OutputError> {
        check_directory(dir, names)?;
        let created_dir = !dir.exists();
        std::fs::create_dir_all(dir).map_err(io(&dir.join(names.first().unwrap_or(&""))))?;
        let mut staged = Self {
            dir: dir.to_path_buf(),
            created_dir,
            files: Vec::with_capacity(names.len()),
            committed: false,
        };
        for name in names {
            let dest = dir.join(name);
            let (real, tmp, file) = match target(&dest)? {
                Target::InPlace(real) => {
                    let file = open_in_place(&real).map_err(io(&dest))?;
                    (real, None, file)
                }
                Target::Replace(real) => {
                    let tmp = temporaries::beside(&real, "tmp");
                    let file = temporaries::create(&tmp).map_err(io(&dest))?;
                    (real, Some(tmp), file)
                }
            };
            staged.files.push(Staged {
                name: (*name).to_string(),
                tmp,
                dest,
                real,
                writer: Some(std::io::BufWriter::with_capacity(1 << 16, file)),
            });
        }
        Ok(staged)
    }

    /// The writer of the staged file `name`.
    ///
    /// # Panics
    /// When `name` was not staged: a mistake of the caller, not of its input.
    pub fn writer(&mut self, name: &str) -> &mut std::io::BufWriter<std::fs::File> {
        self.files
            .iter_mut()
            .find(|f| f.name == name)
            .and_then(|f| f.writer.as_mut())
            .expect("a file staged by this StagedFiles")
    }

    /// The writers of every staged file, in the order they were named.
    pub fn writers(&mut self) -> Vec<&mut std::io::BufWriter<std::fs::File>> {
        self.files
            .iter_mut()
            .filter_map(|f| f.writer.as_mut())
            .collect()
    }

    /// Where the staged file `name` goes.
    pub fn destination(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Flushes every file to disk, then renames all into place.
    ///
    /// # Errors
    /// [`OutputError`] naming the file that cannot be written or renamed; the files not yet
    /// renamed are then left as they were.
    pub fn commit(mut self) -> Result<(), OutputError> {
        for f in &mut self.files {
            let writer = f.writer.take().expect("each file is committed once");
            let file = writer
                .into_inner()
                .map_err(|e| io(&f.dest)(e.into_error()))?;
            if f.tmp.is_some() {
                file.sync_all().map_err(io(&f.dest))?;
            }
        }
        for f in &mut self.files {
            if let Some(tmp) = &f.tmp {
                temporaries::rename(tmp, &f.real).map_err(io(&f.dest))?;
                // Renamed: nothing left to remove for this one.
                f.tmp = None;
            }
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        for f in &mut self.files {
            drop(f.writer.take());
            if let Some(tmp) = &f.tmp {
                temporaries::remove(tmp);
            }
        }
        if self.created_dir {
            // Only succeeds when empty: never removes anything but what this run made.
            let _ = std::fs::remove_dir(&self.dir);
        }
    }
}
