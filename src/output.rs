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
/// and only renamed into place once every one was written. A destination that cannot be replaced
/// (a directory) is refused before anything is written.
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> Result<()> {
    for (name, _) in files {
        let dest = dir.join(name);
        if dest.is_dir() {
            anyhow::bail!("cannot write {}: it is a directory", dest.display());
        }
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let remove_staged = |staged: &[(PathBuf, PathBuf)]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for (name, bytes) in files {
        let dest = dir.join(name);
        let tmp = temporary_beside(&dest);
        let written =
            std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()));
        staged.push((tmp, dest));
        if let Err(e) = written {
            remove_staged(&staged);
            return Err(e);
        }
    }
    for (k, (tmp, dest)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, dest) {
            remove_staged(&staged[k..]);
            return Err(e).with_context(|| format!("cannot rename onto {}", dest.display()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
