//! Temporaries as a user meets them: Ctrl-C or SIGTERM during a long write removes them and the
//! shell sees 130 or 143; a run killed by SIGKILL leaves them, and the next run that writes the
//! same file removes them, saying so on standard error, while a running process's temporary and
//! names that only look like one stay.

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Far more realizations than a test waits for: the run is still writing when it is signalled.
const LONG: &str = "10000000";

/// The names in `dir`, hidden ones included, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A process id that no process has: a child's, once it ended and was reaped.
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    child.wait().unwrap();
    let pid = child.id();
    assert!(!Path::new(&format!("/proc/{pid}")).exists(), "{pid} reused");
    pid
}

/// `accelcal args` in `dir`, its standard error piped.
fn spawn(program: &str, dir: &Path, args: &[&str]) -> Child {
    Command::new(program)
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .env("TMPDIR", dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs")
}

/// Runs `accelcal args` in `dir` to its end (at most 60 s); its standard error.
fn run_ok(dir: &Path, args: &[&str]) -> String {
    let (status, stderr) = common::wait_limited(spawn(common::bin(), dir, args), 60);
    assert!(status.is_some_and(|s| s.success()), "{args:?}: {stderr}");
    stderr
}

/// Starts a shard that spools into `dir/out` for longer than any test waits, and waits for its
/// two hidden files (`.part-1.bin.PID.blocks` and `.tmp`); the process id in their names.
fn start_long_shard(program: &str, dir: &Path, args: &[&str]) -> (Child, u32) {
    let shard = ["ensemble", "--realizations", LONG, "--shard", "1/2"];
    let partial = ["--partial", "out/part-1.bin"];
    let child = spawn(program, dir, &[args, &shard, &partial].concat());
    let start = Instant::now();
    while entries(&dir.join("out")).len() < 2 {
        assert!(start.elapsed().as_secs() < 30, "no temporaries appeared");
        std::thread::sleep(Duration::from_millis(20));
    }
    let names = entries(&dir.join("out"));
    let pid = names[0]
        .strip_prefix(".part-1.bin.")
        .and_then(|n| n.split('.').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{names:?}"));
    (child, pid)
}

/// Ctrl-C (SIGINT) or SIGTERM during a long write: the temporaries are gone and the shell that
/// ran the command sees 128 + the signal, 130 or 143, as it would for a command without handlers.
#[test]
fn an_interrupted_run_removes_its_temporaries_and_the_shell_sees_128_plus_the_signal() {
    for (signal, expected) in [("INT", "130"), ("TERM", "143")] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("out")).unwrap();
        // The shell waits for the command in the foreground and prints its status.
        let script = r#""$@" >/dev/null 2>&1; echo "$?""#;
        let (shell, pid) = start_long_shard("sh", d, &["-c", script, "sh", common::bin()]);
        assert_ne!(pid, shell.id(), "the command, not the shell");
        let killed = Command::new("kill")
            .args([format!("-{signal}"), pid.to_string()])
            .status();
        assert!(killed.unwrap().success());
        let start = Instant::now();
        let out = shell.wait_with_output().unwrap();
        assert!(start.elapsed().as_secs() < 30);
        assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), expected);
        assert!(entries(&d.join("out")).is_empty(), "{:?}", entries(d));
    }
}

/// A shard killed by SIGKILL cannot remove its temporaries: they stay. The next run that writes
/// the same partial removes both (the spool and the file's temporary) and names each on
/// standard error; the process id in their names runs no more.
#[test]
fn temporaries_left_by_sigkill_are_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("out")).unwrap();
    let (mut child, pid) = start_long_shard(common::bin(), d, &[]);
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let left = entries(&d.join("out"));
    let expected = [
        format!(".part-1.bin.{pid}.blocks"),
        format!(".part-1.bin.{pid}.tmp"),
    ];
    assert_eq!(left, expected, "what SIGKILL leaves");
    assert!(!Path::new(&format!("/proc/{pid}")).exists());

    let stderr = run_ok(
        d,
        &[
            "ensemble",
            "--realizations",
            "128",
            "--shard",
            "1/2",
            "--partial",
            "out/part-1.bin",
            "-q",
        ],
    );
    assert_eq!(entries(&d.join("out")), ["part-1.bin"], "{stderr}");
    for name in &expected {
        let line = format!("removed out/{name} (");
        assert_eq!(stderr.matches(&line).count(), 1, "{stderr}");
    }
    let said = format!("a temporary left by process {pid}, which no longer runs");
    assert_eq!(stderr.matches(&said).count(), 2, "{stderr}");
}

/// `simulate --logs` and `calibrate --out` into directories that hold the temporaries of their
/// files: a dead process's are removed, a running process's (this test's) stays, and names that
/// only look like a temporary stay. The files were there before the runs.
#[test]
fn simulate_and_calibrate_remove_stale_temporaries_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dead = dead_pid();
    let live = std::process::id();
    let planted = |sub: &str, file: &str| {
        std::fs::create_dir_all(d.join(sub)).unwrap();
        let stale = format!(".{file}.{dead}.tmp");
        let kept = [
            format!(".{file}.{live}.tmp"),
            format!(".{file}.{dead}.tmp.old"),
            format!("{file}.{dead}.tmp"),
            format!(".{file}.x{dead}.tmp"),
        ];
        for name in kept.iter().chain([&stale]) {
            std::fs::write(d.join(sub).join(name), vec![b'x'; 2048]).unwrap();
        }
        assert!(entries(&d.join(sub)).contains(&stale));
        (stale, kept)
    };

    let (stale, kept) = planted("logs", "accelerometer.csv");
    let stderr = run_ok(d, &["simulate", "--logs", "logs", "-q"]);
    let mut expected: Vec<String> = ["accelerometer.csv", "gps.csv", "truth.csv"]
        .iter()
        .map(|n| n.to_string())
        .chain(kept)
        .collect();
    expected.sort();
    assert_eq!(entries(&d.join("logs")), expected);
    let line = format!(
        "removed logs/{stale} (2.0 kB), a temporary left by process {dead}, which no longer runs\n"
    );
    assert_eq!(stderr.matches(&line).count(), 1, "{stderr}");
    assert_eq!(stderr.matches("removed ").count(), 1, "{stderr}");

    let (stale, kept) = planted("cal", "estimates.csv");
    let stderr = run_ok(
        d,
        &[
            "calibrate",
            "--accel",
            "logs/accelerometer.csv",
            "--gps",
            "logs/gps.csv",
            "--out",
            "cal",
        ],
    );
    let mut expected: Vec<String> = ["estimates.csv", "index.html", "summary.json"]
        .iter()
        .map(|n| n.to_string())
        .chain(kept)
        .collect();
    expected.sort();
    assert_eq!(entries(&d.join("cal")), expected);
    assert!(
        stderr.contains(&format!("removed cal/{stale} (2.0 kB)")),
        "{stderr}"
    );

    // Nothing stale: nothing said.
    let stderr = run_ok(d, &["simulate", "--logs", "logs", "-q"]);
    assert!(!stderr.contains("removed"), "{stderr}");
}

/// The library only removes its temporaries on a signal and hands the signal to its caller: a
/// program that does not end then keeps running, its temporary is gone, and writing a file fails
/// with an error that names the signal instead of leaving a temporary behind.
#[test]
fn the_library_hands_the_signal_to_its_caller_and_does_not_end_the_process() {
    use accelcal::output::{AtomicFile, remove_temporaries_on_signals};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (tx, rx) = std::sync::mpsc::channel();
    remove_temporaries_on_signals(move |signal| tx.send(signal).unwrap()).unwrap();
    let mut file = AtomicFile::create(&d.join("out.csv")).unwrap();
    file.write(b"t_s\n").unwrap();
    let pid = std::process::id();
    assert_eq!(entries(d), [format!(".out.csv.{pid}.tmp")]);

    signal_hook::low_level::raise(signal_hook::consts::SIGTERM).unwrap();
    let signal = rx.recv_timeout(Duration::from_secs(10)).unwrap();
    assert_eq!(signal, signal_hook::consts::SIGTERM);
    assert!(entries(d).is_empty(), "{:?}", entries(d));
    let err = file.commit().unwrap_err().to_string();
    assert!(err.contains("interrupted by signal 15"), "{err}");
    let err = AtomicFile::create(&d.join("other.csv")).err().unwrap();
    assert!(
        err.to_string().contains("interrupted by signal 15"),
        "{err}"
    );
    assert!(entries(d).is_empty(), "{:?}", entries(d));
}
