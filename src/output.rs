//! Writing results without clobbering: every file is written beside its destination under a
//! temporary name and renamed into place, so a run that fails leaves earlier files untouched.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `bytes` to `path` atomically (temporary file, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temporary_beside(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
        f.write_all(bytes)
            .and_then(|()| f.sync_all())
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot rename onto {}", path.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes several files into `dir` (created if missing): all are written to temporaries first,
/// and only renamed into place once every one was written.
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let mut staged = Vec::new();
    for (name, bytes) in files {
        let dest = dir.join(name);
        let tmp = temporary_beside(&dest);
        let written =
            std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()));
        staged.push((tmp, dest));
        if let Err(e) = written {
            for (t, _) in &staged {
                let _ = std::fs::remove_file(t);
            }
            return Err(e);
        }
    }
    for (tmp, dest) in &staged {
        std::fs::rename(tmp, dest)
            .with_context(|| format!("cannot rename onto {}", dest.display()))?;
    }
    Ok(())
}
