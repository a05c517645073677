//! Writing results without clobbering: every file is written beside its destination under a
//! temporary name and renamed into place, so a run that fails leaves earlier files untouched.
//! A destination that exists and is neither a regular file nor a directory (a character device
//! such as `/dev/null` or `/dev/stdout`, a FIFO) is written in place: renaming onto it would
//! replace the device with a regular file.

use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// A result file that could not be written. Nothing was replaced.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The destination is a directory.
    #[error("cannot write {}: it is a directory", path.display())]
    IsDirectory {
        /// The destination.
        path: PathBuf,
    },
    /// The operating system refused a step.
    #[error("cannot {action} {}: {source}", path.display())]
    Io {
        /// What was being done: "create", "write", "rename onto".
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> OutputError {
    let path = path.to_path_buf();
    move |source| OutputError::Io {
        action,
        path,
        source,
    }
}

fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Whether `path` exists and is something other than a regular file or a directory (a device, a
/// FIFO, a socket), which is written in place rather than replaced.
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Opens the special file `path` for writing, in place.
fn open_in_place(path: &Path) -> Result<std::fs::File, OutputError> {
    std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(io("open", path))
}

/// Writes `bytes` to `path` atomically (temporary file, then rename), or in place when `path` is
/// a device or a FIFO.
///
/// # Errors
/// [`OutputError`] when the destination is a directory or a step fails; the destination is then
/// untouched and no temporary is left.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    if is_special(path) {
        let mut f = open_in_place(path)?;
        return f
            .write_all(bytes)
            .and_then(|()| f.flush())
            .map_err(io("write", path));
    }
    let tmp = temporary_beside(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io("create", &tmp))?;
        f.write_all(bytes)
            .and_then(|()| f.sync_all())
            .map_err(io("write", &tmp))?;
        std::fs::rename(&tmp, path).map_err(io("rename onto", path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A file written beside its destination under a temporary name and renamed into place by
/// [`AtomicFile::commit`]; dropped without a commit, it is removed and the destination is
/// untouched.
pub struct AtomicFile {
    tmp: PathBuf,
    dest: PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
    /// The destination is a device or a FIFO, written in place (`tmp` is `dest`).
    in_place: bool,
}

impl AtomicFile {
    /// Starts writing `dest`.
    ///
    /// # Errors
    /// [`OutputError`] when the destination is a directory or the temporary cannot be created.
    pub fn create(dest: &Path) -> Result<Self, OutputError> {
        if dest.is_dir() {
            return Err(OutputError::IsDirectory {
                path: dest.to_path_buf(),
            });
        }
        let in_place = is_special(dest);
        let (tmp, file) = if in_place {
            (dest.to_path_buf(), open_in_place(dest)?)
        } else {
            let tmp = temporary_beside(dest);
            let file = std::fs::File::create(&tmp).map_err(io("create", &tmp))?;
            (tmp, file)
        };
        Ok(Self {
            tmp,
            dest: dest.to_path_buf(),
            file: Some(std::io::BufWriter::new(file)),
            in_place,
        })
    }

    /// Writes `bytes`.
    ///
    /// # Errors
    /// [`OutputError`] when the write fails.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), OutputError> {
        let file = self.file.as_mut().expect("open until committed");
        file.write_all(bytes).map_err(io("write", &self.tmp))
    }

    /// The writer, for encoders that take one.
    pub fn writer(&mut self) -> &mut impl Write {
        self.file.as_mut().expect("open until committed")
    }

    /// The path being written (the temporary), for error messages.
    pub fn temporary(&self) -> &Path {
        &self.tmp
    }

    /// Flushes and renames the file into place.
    ///
    /// # Errors
    /// [`OutputError`] when the flush or the rename fails; the temporary is then removed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let file = self.file.take().expect("committed once");
        if self.in_place {
            return file
                .into_inner()
                .map(drop)
                .map_err(|e| io("write", &self.dest)(e.into_error()));
        }
        let result = file
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .map_err(io("write", &self.tmp))
            .and_then(|()| {
                std::fs::rename(&self.tmp, &self.dest).map_err(io("rename onto", &self.dest))
            });
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.is_some() {
            self.file = None;
            if !self.in_place {
                let _ = std::fs::remove_file(&self.tmp);
            }
        }
    }
}

/// Writes several files into `dir` (created if missing): all are written to temporaries first,
/// and only renamed into place once every one was written. A destination that cannot be replaced
/// (a directory) is refused before anything is written.
///
/// # Errors
/// [`OutputError`] when a destination is a directory or a step fails; earlier files are then
/// untouched and no temporary is left.
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> Result<(), OutputError> {
    for (name, _) in files {
        let dest = dir.join(name);
        if dest.is_dir() {
            return Err(OutputError::IsDirectory { path: dest });
        }
    }
    std::fs::create_dir_all(dir).map_err(io("create directory", dir))?;
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let remove_staged = |staged: &[(PathBuf, PathBuf)]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for (name, bytes) in files {
        let dest = dir.join(name);
        let tmp = temporary_beside(&dest);
        let written = std::fs::write(&tmp, bytes).map_err(io("write", &tmp));
        staged.push((tmp, dest));
        if let Err(e) = written {
            remove_staged(&staged);
            return Err(e);
        }
    }
    for (k, (tmp, dest)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, dest) {
            remove_staged(&staged[k..]);
            return Err(io("rename onto", dest)(e));
        }
    }
    Ok(())
}

/// Result files written as streams and put in place together. Each is written beside its
/// destination under a temporary name; [`StagedFiles::commit`] renames them all once every one
/// was written. Dropped without a commit (a failed run), it removes its temporaries, and the
/// directory too when it created it: files already there stay untouched.
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
    tmp: PathBuf,
    dest: PathBuf,
    writer: Option<std::io::BufWriter<std::fs::File>>,
}

impl StagedFiles {
    /// Stages the files `names` in `dir` (created if missing): opens a temporary beside each.
    ///
    /// # Errors
    /// [`OutputError`] when a destination is a directory or a temporary cannot be created;
    /// nothing is left behind.
    pub fn create(dir: &Path, names: &[&str]) -> Result<Self, OutputError> {
        for name in names {
            let dest = dir.join(name);
            if dest.is_dir() {
                return Err(OutputError::IsDirectory { path: dest });
            }
        }
        let created_dir = !dir.exists();
        std::fs::create_dir_all(dir).map_err(io("create directory", dir))?;
        let mut staged = Self {
            dir: dir.to_path_buf(),
            created_dir,
            files: Vec::with_capacity(names.len()),
            committed: false,
        };
        for name in names {
            let dest = dir.join(name);
            let tmp = temporary_beside(&dest);
            let file = std::fs::File::create(&tmp).map_err(io("create", &tmp))?;
            staged.files.push(Staged {
                name: (*name).to_string(),
                tmp,
                dest,
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
    /// [`OutputError`] when a file cannot be written or renamed; the files not yet renamed are
    /// then left as they were.
    pub fn commit(mut self) -> Result<(), OutputError> {
        for f in &mut self.files {
            let writer = f.writer.take().expect("each file is committed once");
            let file = writer
                .into_inner()
                .map_err(|e| e.into_error())
                .map_err(io("write", &f.tmp))?;
            file.sync_all().map_err(io("write", &f.tmp))?;
        }
        for f in &self.files {
            std::fs::rename(&f.tmp, &f.dest).map_err(io("rename onto", &f.dest))?;
            // Renamed: nothing left to remove for this one.
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
            let _ = std::fs::remove_file(&f.tmp);
        }
        if self.created_dir {
            // Only succeeds when empty: never removes anything but what this run made.
            let _ = std::fs::remove_dir(&self.dir);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FIFO at `dir/name` and a thread reading it to its end.
    fn fifo_with_reader(dir: &Path, name: &str) -> (PathBuf, std::thread::JoinHandle<Vec<u8>>) {
        let fifo = dir.join(name);
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        let path = fifo.clone();
        let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
        (fifo, reader)
    }

    fn is_fifo(path: &Path) -> bool {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
    }

    /// An output that is a FIFO (like `/dev/null` or `/dev/stdout`, a file that is not a regular
    /// file) is written in place and stays what it was; renamed onto, it would become a regular
    /// file.
    #[test]
    fn a_fifo_is_written_in_place_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let (fifo, reader) = fifo_with_reader(dir.path(), "out.json");
        write_atomic(&fifo, b"{\"a\": 1}").unwrap();
        assert!(is_fifo(&fifo), "the FIFO was replaced");
        assert_eq!(reader.join().unwrap(), b"{\"a\": 1}");

        let (fifo, reader) = fifo_with_reader(dir.path(), "streamed.csv");
        let mut f = AtomicFile::create(&fifo).unwrap();
        f.write(b"t_s\n0\n").unwrap();
        f.commit().unwrap();
        assert!(is_fifo(&fifo), "the FIFO was replaced");
        assert_eq!(reader.join().unwrap(), b"t_s\n0\n");
        // Nothing else appeared beside it.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn a_directory_in_the_way_leaves_everything_untouched() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.html"), "earlier").unwrap();
        std::fs::create_dir(dir.path().join("b.json")).unwrap();
        let err =
            write_all_atomic(dir.path(), &[("a.html", b"new"), ("b.json", b"new")]).unwrap_err();
        assert!(err.to_string().contains("directory"), "{err}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.html")).unwrap(),
            "earlier"
        );
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "temporaries left behind"
        );
    }

    #[test]
    fn writes_every_file() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new");
        write_all_atomic(&out, &[("a", b"1"), ("b", b"2")]).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a")).unwrap(), "1");
        assert_eq!(std::fs::read_to_string(out.join("b")).unwrap(), "2");
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
    }

    #[test]
    fn staged_files_appear_together_or_not_at_all() {
        use std::io::Write as _;
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new");
        let mut staged = StagedFiles::create(&out, &["a.csv", "b.json"]).unwrap();
        writeln!(staged.writer("a.csv"), "1").unwrap();
        assert!(!out.join("a.csv").exists());
        drop(staged);
        assert!(!out.exists(), "a failed run left the directory it created");

        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("a.csv"), "earlier").unwrap();
        let mut staged = StagedFiles::create(&out, &["a.csv", "b.json"]).unwrap();
        writeln!(staged.writer("a.csv"), "new").unwrap();
        drop(staged);
        assert_eq!(
            std::fs::read_to_string(out.join("a.csv")).unwrap(),
            "earlier"
        );
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1);

        let mut staged = StagedFiles::create(&out, &["a.csv", "b.json"]).unwrap();
        write!(staged.writer("a.csv"), "new").unwrap();
        write!(staged.writer("b.json"), "{{}}").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "new");
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
    }
}
