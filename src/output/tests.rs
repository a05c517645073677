//! Unit tests of the output module: nothing clobbered, nothing left, errors naming the user's path.

use std::io::Write as _;
use std::path::{Path, PathBuf};

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
    let err = write_all_atomic(dir.path(), &[("a.html", b"new"), ("b.json", b"new")]).unwrap_err();
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

/// An output where nothing can be created: a read-only directory, or (for root, who may write
/// there anyway) a directory of /sys.
fn unwritable_dir(dir: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let ro = dir.join("read-only");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o500)).unwrap();
    if std::fs::File::create(ro.join("probe")).is_ok() {
        PathBuf::from("/sys")
    } else {
        ro
    }
}

/// The entries of `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The reproducers: a missing parent, a directory, a file as the directory, a place
/// where nothing can be created. Each is refused by the check, and by every writer, naming the
/// user's path (never a temporary) and the operating system's error once.
#[test]
fn bad_destinations_are_refused_naming_the_users_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("file"), "keep").unwrap();
    let ro = unwritable_dir(d);
    let cases = [
        (d.join("nonexistent/a/b/c.json"), "the directory"),
        (d.to_path_buf(), "it is a directory"),
        (d.join("file/c.json"), "is not a directory"),
        (ro.join("c.json"), "denied"),
    ];
    for (path, why) in cases {
        let shown = path.display().to_string();
        let errors = [
            check_file(&path).unwrap_err(),
            write_atomic(&path, b"x").unwrap_err(),
            AtomicFile::create(&path).err().unwrap(),
        ];
        for err in errors {
            let msg = err.to_string();
            assert!(msg.starts_with(&format!("cannot write {shown}: ")), "{msg}");
            let temporary = format!(".{}.tmp", std::process::id());
            assert!(msg.contains(why) && !msg.contains(&temporary), "{msg}");
            assert!(
                std::error::Error::source(&err).is_none(),
                "chained twice: {msg}"
            );
        }
    }
    let out = d.join("file");
    for err in [
        check_directory(&out, &["a.json"]).unwrap_err(),
        write_all_atomic(&out, &[("a.json", b"x")]).unwrap_err(),
        StagedFiles::create(&out, &["a.json"]).unwrap_err(),
    ] {
        assert!(err.to_string().contains("is not a directory"), "{err}");
    }
    let err = check_directory(&ro.join("new/out"), &["a.json"]).unwrap_err();
    assert!(err.to_string().contains("denied"), "{err}");
    assert_eq!(std::fs::read_to_string(d.join("file")).unwrap(), "keep");
    assert_eq!(
        entries(d),
        ["file", "read-only"],
        "something was left behind"
    );
}

/// `/dev/full` as an output: the write fails (it "succeeded" before, through a regular file that
/// replaced the device) and the device stays.
#[test]
fn a_write_error_is_an_error_and_the_device_stays() {
    use std::os::unix::fs::FileTypeExt;
    let full = Path::new("/dev/full");
    if !std::fs::metadata(full).is_ok_and(|m| m.file_type().is_char_device()) {
        return;
    }
    let err = write_atomic(full, b"x").unwrap_err().to_string();
    assert_eq!(err.matches("No space left on device").count(), 1, "{err}");
    assert!(err.starts_with("cannot write /dev/full: "), "{err}");
    let mut f = AtomicFile::create(full).unwrap();
    f.write(&[0; 100]).unwrap();
    assert!(f.commit().is_err());
    assert!(
        std::fs::metadata(full)
            .unwrap()
            .file_type()
            .is_char_device()
    );
}

/// Every writer of several files writes a FIFO among them in place, and the others as files.
#[test]
fn several_files_with_a_fifo_among_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let (fifo, reader) = fifo_with_reader(out, "b.json");
    write_all_atomic(out, &[("a.html", b"page"), ("b.json", b"{}")]).unwrap();
    assert!(is_fifo(&fifo));
    assert_eq!(reader.join().unwrap(), b"{}");
    assert_eq!(std::fs::read_to_string(out.join("a.html")).unwrap(), "page");

    let path = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
    let mut staged = StagedFiles::create(out, &["a.html", "b.json"]).unwrap();
    staged.writer("a.html").write_all(b"page 2").unwrap();
    staged.writer("b.json").write_all(b"[]").unwrap();
    staged.commit().unwrap();
    assert!(is_fifo(&fifo));
    assert_eq!(reader.join().unwrap(), b"[]");
    assert_eq!(
        std::fs::read_to_string(out.join("a.html")).unwrap(),
        "page 2"
    );
    assert_eq!(entries(out), ["a.html", "b.json"]);
}

/// A symbolic link to a file is written through: the link stays a link.
#[test]
fn a_link_is_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("real.json"), "old").unwrap();
    std::os::unix::fs::symlink("real.json", d.join("link.json")).unwrap();
    write_atomic(&d.join("link.json"), b"new").unwrap();
    assert!(
        std::fs::symlink_metadata(d.join("link.json"))
            .unwrap()
            .is_symlink()
    );
    assert_eq!(std::fs::read_to_string(d.join("real.json")).unwrap(), "new");
    // A loop is refused, not replaced.
    std::os::unix::fs::symlink("loop.json", d.join("loop.json")).unwrap();
    let err = write_atomic(&d.join("loop.json"), b"x")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("loop.json") && err.contains("symbolic links"),
        "{err}"
    );
    assert!(
        std::fs::symlink_metadata(d.join("loop.json"))
            .unwrap()
            .is_symlink()
    );
}

/// A scratch file is gone once dropped, and its errors name the output.
#[test]
fn a_scratch_file_is_removed_when_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let dest = dir.path().join("part-1.bin");
    let (scratch, mut f) = ScratchFile::beside(&dest, "blocks").unwrap();
    f.write_all(b"blocks").unwrap();
    assert_eq!(entries(dir.path()).len(), 1);
    let err = scratch
        .error(std::io::Error::from_raw_os_error(28))
        .to_string();
    assert!(
        err.starts_with(&format!("cannot write {}: ", dest.display())),
        "{err}"
    );
    drop(scratch);
    assert!(entries(dir.path()).is_empty());
}

/// The temporary names of a destination are told apart from names that merely look like them.
#[test]
fn only_the_exact_temporary_name_carries_a_process_id() {
    use std::ffi::OsStr;
    let pid = |name: &str| stale::pid_in(OsStr::new(name), OsStr::new("estimates.csv"), "tmp");
    assert_eq!(pid(".estimates.csv.4242.tmp"), Some(4242));
    assert_eq!(pid(".estimates.csv.4294967295.tmp"), Some(u32::MAX));
    for name in [
        "estimates.csv.4242.tmp",
        ".estimates.csv.4242.tmp~",
        ".estimates.csv.4242.tmp.bak",
        ".estimates.csv.4242.blocks",
        ".estimates.csv.04242.tmp",
        ".estimates.csv.0.tmp",
        ".estimates.csv..tmp",
        ".estimates.csv.42a.tmp",
        ".estimates.csv.+42.tmp",
        ".estimates.csv.4294967296.tmp",
        ".estimates.csv.5.4242.tmp",
        ".other.csv.4242.tmp",
        ".Estimates.csv.4242.tmp",
    ] {
        assert_eq!(pid(name), None, "{name}");
    }
}

/// A process id that no process has: a child's, once it ended and was reaped.
fn dead_pid() -> u32 {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    child.wait().unwrap();
    let pid = child.id();
    assert!(!Path::new(&format!("/proc/{pid}")).exists(), "{pid} reused");
    pid
}

/// Checking or staging a destination removes its temporaries whose process no longer runs, and
/// nothing else: not a running process's, not a name that only looks like one, not a link or a
/// directory under that name. A scratch file clears those of its own suffix.
#[test]
fn stale_temporaries_of_dead_processes_are_removed_and_nothing_else() {
    use std::os::unix::fs::symlink;
    if !Path::new("/proc/self").exists() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dead = dead_pid();
    let beyond = std::fs::read_to_string("/proc/sys/kernel/pid_max")
        .map_or(4_194_304, |s| s.trim().parse::<u32>().unwrap())
        + 1;
    let mut sleeper = std::process::Command::new("sleep")
        .arg("60")
        .spawn()
        .unwrap();
    let live = sleeper.id();
    let stale = [
        format!(".estimates.csv.{dead}.tmp"),
        format!(".estimates.csv.{beyond}.tmp"),
        format!(".part-1.bin.{dead}.blocks"),
    ];
    let kept = [
        format!(".estimates.csv.{live}.tmp"),
        format!(".estimates.csv.{dead}.tmp~"),
        format!(".estimates.csv.0{dead}.tmp"),
        format!("estimates.csv.{dead}.tmp"),
        format!(".estimates.csv.{dead}.blocks"),
        format!(".summary.json.{dead}.tmp"),
        format!(".part-1.bin.{live}.blocks"),
    ];
    for name in stale.iter().chain(&kept) {
        std::fs::write(d.join(name), name).unwrap();
    }
    let dead_2 = dead_pid();
    std::fs::create_dir(d.join(format!(".estimates.csv.{dead_2}.tmp"))).unwrap();
    symlink(
        "estimates.csv",
        d.join(format!(".estimates.csv.{beyond}1.tmp")),
    )
    .unwrap();
    let before = entries(d);
    for name in &stale {
        assert!(before.contains(name), "{name} was not made");
    }

    check_file(&d.join("estimates.csv")).unwrap();
    drop(ScratchFile::beside(&d.join("part-1.bin"), "blocks").unwrap());
    sleeper.kill().unwrap();
    sleeper.wait().unwrap();

    let after = entries(d);
    let gone: Vec<&String> = before.iter().filter(|n| !after.contains(n)).collect();
    let mut expected: Vec<&String> = stale.iter().collect();
    expected.sort();
    assert_eq!(gone, expected, "left: {after:?}");
    assert_eq!(after.len(), before.len() - stale.len(), "{after:?}");
    let mut told: Vec<(String, u32, u64)> = take_removed_stale_temporaries()
        .into_iter()
        .filter(|t| t.path.starts_with(d))
        .map(|t| {
            let name = t.path.file_name().unwrap().to_string_lossy().into_owned();
            (name, t.pid, t.bytes)
        })
        .collect();
    told.sort();
    let mut expected: Vec<(String, u32, u64)> = [dead, beyond, dead]
        .iter()
        .zip(&stale)
        .map(|(&pid, name)| (name.clone(), pid, name.len() as u64))
        .collect();
    expected.sort();
    assert_eq!(told, expected);
}
