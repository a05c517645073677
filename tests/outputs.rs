//! Outputs, from the reproducers: a destination that cannot be written is refused with
//! exit code 2 before the work starts, naming the user's path and the operating system's error
//! once (not a hidden temporary, not the error twice); a write error such as `/dev/full` is exit
//! 2; a shard that fails, is interrupted or terminated leaves no hidden file.

mod common;

use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Far more work than the limits below allow: a run that starts it is seen.
const LONG: &str = "10000000";

fn spawn(dir: &Path, args: &[&str]) -> Child {
    Command::new(common::bin())
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .env("TMPDIR", dir.join("tmp"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs")
}

/// Runs `args` in `dir` and expects exit code 2 within 10 s with a message that starts with
/// `cannot write <shown>: `, holds `why` and the operating system's text at most once.
fn refused(dir: &Path, args: &[&str], shown: &str, why: &str) {
    let (status, msg) = common::wait_limited(spawn(dir, args), 30);
    let what = args.join(" ");
    assert_eq!(status.and_then(|s| s.code()), Some(2), "{what}: {msg}");
    assert!(
        msg.starts_with(&format!("error: cannot write {shown}: ")),
        "{what}: {msg}"
    );
    assert!(msg.contains(why), "{what}: {msg}");
    assert_eq!(msg.matches(why).count(), 1, "{what}: said twice: {msg}");
    assert!(
        !msg.contains(".tmp") && !msg.contains(".blocks"),
        "{what}: {msg}"
    );
}

/// The names in `dir`, hidden ones included.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A place where nothing can be created: a read-only directory, or /sys for root.
fn unwritable(dir: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o500)).unwrap();
    if std::fs::File::create(ro.join("probe")).is_ok() {
        PathBuf::from("/sys")
    } else {
        ro
    }
}

/// Every command that writes, given a path it cannot write, refuses at once (the work asked for
/// would take minutes): exit 2 naming the path; it exited 1 naming `.c.30307.tmp`, printed the
/// error twice, and `report --out` computed for seconds first.
#[test]
fn bad_output_paths_are_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("tmp")).unwrap();
    std::fs::write(d.join("file"), "").unwrap();
    std::os::unix::fs::symlink("loop.json", d.join("loop.json")).unwrap();
    let ro = unwritable(d).join("o.json").display().to_string();
    let paths: [(&str, &str, &str); 5] = [
        (
            "nonexistent/a/b/c.json",
            "nonexistent/a/b/c.json",
            "does not exist",
        ),
        ("tmp", "tmp", "is a directory"),
        ("file/c.json", "file/c.json", "is not a directory"),
        (&ro, &ro, "denied"),
        ("loop.json", "loop.json", "symbolic links"),
    ];
    for (path, shown, why) in paths {
        let n = ["--realizations", LONG];
        refused(
            d,
            &[&["ensemble", "--json", path][..], &n].concat(),
            shown,
            why,
        );
        let shard = ["ensemble", "--shard", "1/2", "--partial", path];
        refused(d, &[&shard[..], &n].concat(), shown, why);
        refused(
            d,
            &[&["sensitivity", "--json", path][..], &n].concat(),
            shown,
            why,
        );
        refused(d, &["merge", "a.bin", "--json", path], shown, why);
    }
    // `report --out` a file, or in a place where nothing can be made.
    let out = [("file", "file/index.html"), (&ro[..], &ro[..])];
    for (path, shown) in out {
        let args = ["report", "--out", path, "--realizations", LONG];
        let (status, msg) = common::wait_limited(spawn(d, &args), 30);
        assert_eq!(status.and_then(|s| s.code()), Some(2), "{path}: {msg}");
        assert!(msg.contains(&format!("cannot write {shown}")), "{msg}");
    }
    assert_eq!(entries(d), ["file", "loop.json", "ro", "tmp"]);
    assert!(entries(&d.join("tmp")).is_empty());
}

/// `/dev/full` as an output "succeeded" (a regular file replaced the device). Now exit 2 with the
/// error once; the device stays, and the shard's scratch file is removed.
#[test]
fn a_full_device_is_exit_2_with_the_error_once() {
    use std::os::unix::fs::FileTypeExt;
    let full = Path::new("/dev/full");
    if !std::fs::metadata(full).is_ok_and(|m| m.file_type().is_char_device()) {
        eprintln!("no /dev/full here: skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("tmp")).unwrap();
    let why = "No space left on device";
    let n = ["--realizations", "200", "-q"];
    refused(
        d,
        &[&["ensemble", "--json", "/dev/full"][..], &n].concat(),
        "/dev/full",
        why,
    );
    let shard = ["ensemble", "--shard", "1/2", "--partial", "/dev/full"];
    refused(d, &[&shard[..], &n].concat(), "/dev/full", why);
    refused(d, &["simulate", "--csv", "/dev/full"], "/dev/full", why);
    assert!(
        std::fs::metadata(full)
            .unwrap()
            .file_type()
            .is_char_device()
    );
    assert!(entries(&d.join("tmp")).is_empty(), "scratch files left");
}

/// The JSON of `ensemble`, `merge` and `sensitivity` is written as it is serialized, never held
/// whole: a full device met mid-stream, given as the output or as standard output, is exit 2
/// with the error once, and a symbolic link to the device stays one.
#[test]
fn a_streamed_output_that_meets_a_full_device_is_exit_2_with_the_error_once() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("no /dev/full here: skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("tmp")).unwrap();
    let made = Command::new(common::bin())
        .args(["ensemble", "--realizations", "200", "-q"])
        .args(["--shard", "1/1", "--partial", "p.bin"])
        .current_dir(d)
        .status()
        .unwrap();
    assert!(made.success());
    std::os::unix::fs::symlink(full, d.join("full.json")).unwrap();
    let why = "No space left on device";
    let commands: [&[&str]; 3] = [
        &["ensemble", "--realizations", "200", "-q"],
        &["merge", "p.bin", "-q"],
        &[
            "sensitivity",
            "--realizations",
            "64",
            "--draws",
            "10",
            "--ensembles",
            "0",
            "-q",
        ],
    ];
    for args in commands {
        for path in ["/dev/full", "full.json"] {
            refused(d, &[args, &["--json", path]].concat(), path, why);
        }
        // Standard output a full device: the document is streamed there.
        let out = Command::new(common::bin())
            .args(args)
            .current_dir(d)
            .env("TMPDIR", d.join("tmp"))
            .stdout(std::fs::File::create(full).unwrap())
            .output()
            .unwrap();
        let msg = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {msg}");
        assert!(
            msg.starts_with("error: cannot write to standard output: "),
            "{args:?}: {msg}"
        );
        assert_eq!(msg.matches(why).count(), 1, "{args:?}: {msg}");
    }
    assert_eq!(std::fs::read_link(d.join("full.json")).unwrap(), full);
    assert_eq!(entries(d), ["full.json", "p.bin", "tmp"]);
    assert!(entries(&d.join("tmp")).is_empty(), "scratch files left");
}

/// A shard interrupted (SIGINT) or terminated (SIGTERM, as `scancel` and a time limit do) left
/// its hidden `.part-K.bin.PID.blocks` and `.tmp` files; it now removes them and ends by the
/// signal.
#[test]
fn a_cancelled_shard_leaves_no_hidden_files() {
    for (signal, name) in [(15, "TERM"), (2, "INT")] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir_all(d.join("tmp")).unwrap();
        std::fs::create_dir(d.join("out")).unwrap();
        let args = ["ensemble", "--realizations", LONG, "--shard", "1/2"];
        let child = spawn(d, &[&args[..], &["--partial", "out/part-1.bin"]].concat());
        let start = Instant::now();
        while entries(&d.join("out")).len() < 2 {
            assert!(start.elapsed().as_secs() < 20, "no temporaries appeared");
            std::thread::sleep(Duration::from_millis(20));
        }
        let hidden = entries(&d.join("out"));
        assert!(hidden.iter().any(|n| n.ends_with(".blocks")), "{hidden:?}");
        let pid = child.id().to_string();
        let killed = Command::new("kill")
            .args([&format!("-{name}"), &pid])
            .status();
        assert!(killed.unwrap().success());
        let (status, msg) = common::wait_limited(child, 20);
        let status = status.expect("ended after the signal");
        assert_eq!(status.signal(), Some(signal), "{status:?}: {msg}");
        assert!(
            entries(&d.join("out")).is_empty(),
            "{:?}",
            entries(&d.join("out"))
        );
    }
}

/// `calibrate --out` and `simulate --csv`/`--logs` are checked before the work: a calibration
/// into a file's place is refused before either log is opened (the missing log is not what is
/// reported), and a `--csv` that cannot be written leaves no `--logs` directory behind.
#[test]
fn calibrate_and_simulate_check_their_outputs_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("file"), "").unwrap();
    refused(
        d,
        &[
            "calibrate",
            "--accel",
            "missing.csv",
            "--gps",
            "missing.csv",
            "--out",
            "file/cal",
        ],
        "file/cal/estimates.csv",
        "is not a directory",
    );
    refused(
        d,
        &["simulate", "--logs", "logs", "--csv", "file/r.csv"],
        "file/r.csv",
        "is not a directory",
    );
    assert_eq!(entries(d), ["file"]);
}
