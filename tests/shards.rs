//! Ensembles split across processes: shards merged in any order, on any thread count, give the
//! summary of one run number for number; partial files of another ensemble, repeated, missing
//! or truncated are refused with exit code 2. And long runs: the whiteness check falls back to
//! lags when every pair of fixes would be too many.

mod common;

use std::path::Path;
use std::process::{Command, Output};

const CONFIG: &str =
    "[profile]\nduration_s = 4.0\n[ensemble]\nrealizations = 1500\ntruth = \"euler\"\n";

fn accelcal(args: &[&str], dir: &Path, threads: usize) -> Output {
    common::run_in(dir, args, Some(threads))
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn shard(dir: &Path, k: usize, m: usize, seed: &str, file: &str, threads: usize) {
    ok(&accelcal(
        &[
            "ensemble",
            "--config",
            "c.toml",
            "--seed",
            seed,
            "--shard",
            &format!("{k}/{m}"),
            "--partial",
            file,
            "--quiet",
        ],
        dir,
        threads,
    ));
}

#[test]
fn three_shards_merged_in_any_order_equal_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    ok(&accelcal(
        &[
            "ensemble",
            "--config",
            "c.toml",
            "--json",
            "whole.json",
            "--quiet",
        ],
        d,
        2,
    ));
    for (k, threads) in [(1, 1), (2, 2), (3, 3)] {
        shard(d, k, 3, "2017", &format!("p{k}.bin"), threads);
    }
    let whole = common::summary_without_timing(&d.join("whole.json"));
    for order in [
        ["p1.bin", "p2.bin", "p3.bin"],
        ["p3.bin", "p1.bin", "p2.bin"],
    ] {
        let mut args = vec!["merge"];
        args.extend(order);
        args.extend(["--json", "merged.json", "--quiet"]);
        ok(&accelcal(&args, d, 2));
        assert_eq!(
            common::summary_without_timing(&d.join("merged.json")),
            whole,
            "order {order:?}"
        );
    }
    // A differing ensemble is seen: the comparison is not vacuous.
    ok(&accelcal(
        &[
            "ensemble",
            "--config",
            "c.toml",
            "--seed",
            "9",
            "--json",
            "other.json",
            "--quiet",
        ],
        d,
        2,
    ));
    assert_ne!(common::summary_without_timing(&d.join("other.json")), whole);
}

/// `merge` with `files` must exit 2 naming `culprit` and write nothing.
fn refused(d: &Path, files: &[&str], culprit: &str, why: &str) {
    let mut args = vec!["merge"];
    args.extend(files);
    args.extend(["--json", "out.json"]);
    let o = accelcal(&args, d, 2);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{files:?}: {msg}");
    assert!(
        msg.contains(culprit) && msg.contains(why),
        "{files:?}: {msg}"
    );
    assert!(!d.join("out.json").exists());
}

#[test]
fn partials_of_another_ensemble_or_split_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    for k in 1..=3 {
        shard(d, k, 3, "2017", &format!("p{k}.bin"), 2);
    }
    shard(d, 2, 3, "5", "seed5.bin", 2);
    shard(d, 2, 4, "2017", "of4.bin", 2);
    refused(d, &["p1.bin", "seed5.bin", "p3.bin"], "seed5.bin", "seed 5");
    refused(d, &["p1.bin", "p3.bin"], "p1.bin", "shard 2/3 is missing");
    refused(
        d,
        &["p1.bin", "p2.bin", "p2.bin", "p3.bin"],
        "p2.bin",
        "given twice",
    );
    refused(d, &["p1.bin", "of4.bin", "p3.bin"], "of4.bin", "split");
    let bytes = std::fs::read(d.join("p2.bin")).unwrap();
    std::fs::write(d.join("cut.bin"), &bytes[..bytes.len() - 100]).unwrap();
    refused(d, &["p1.bin", "cut.bin", "p3.bin"], "cut.bin", "truncated");
    std::fs::write(d.join("text.bin"), "hello\n").unwrap();
    refused(
        d,
        &["p1.bin", "text.bin", "p3.bin"],
        "text.bin",
        "not an accelcal partial",
    );
    refused(
        d,
        &["p1.bin", "absent.bin", "p3.bin"],
        "absent.bin",
        "cannot read",
    );
    for bad in ["0/3", "4/3", "2", "a/b", "1/999"] {
        let o = accelcal(
            &[
                "ensemble",
                "--config",
                "c.toml",
                "--shard",
                bad,
                "--partial",
                "x.bin",
            ],
            d,
            2,
        );
        let msg = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {msg}");
        assert!(msg.contains("--shard"), "{bad}: {msg}");
        assert!(!d.join("x.bin").exists());
    }
}

#[test]
fn long_runs_test_lags_and_say_so() {
    // 10 min at 100 Hz with a fix every second: 600 fixes, lags up to 20 by configuration.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("c.toml"),
        "[profile]\nduration_s = 600.0\n[accelerometer]\nsample_rate_hz = 100.0\n[gps]\nsample_rate_hz = 1.0\n[ensemble]\nrealizations = 300\ntruth = \"euler\"\n[checks]\nresidual_max_lag = 20\n",
    )
    .unwrap();
    ok(&accelcal(
        &[
            "ensemble", "--config", "c.toml", "--json", "e.json", "--quiet",
        ],
        d,
        2,
    ));
    let e = common::summary_without_timing(&d.join("e.json"));
    let s = &e["summary"];
    assert_eq!(s["all_passed"], true, "{}", s["checks"]);
    assert_eq!(s["residual_pairs"]["all_pairs"], false);
    assert_eq!(s["residual_pairs"]["max_lag"], 20);
    let whiteness = s["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "residual_whiteness")
        .unwrap();
    // Pairs (i, m) with 1 ≤ i − m ≤ 20 over 600 fixes, four component pairs each.
    let pairs: u64 = (1..=20).map(|lag| 600 - lag).sum();
    assert_eq!(whiteness["members"], 4 * pairs);
    assert_eq!(e["residual_whiteness_by_lag"].as_array().unwrap().len(), 20);
}

/// Runs examples/slurm-ensemble.sh in `d` as array task `task` of the array `first..=last` with
/// `args`, the built binary on the PATH when `on_path`.
fn slurm_task(
    d: &Path,
    (task, first, last): (u64, u64, u64),
    args: &[&str],
    on_path: bool,
) -> Output {
    let bin_dir = Path::new(common::bin()).parent().unwrap();
    let path = if on_path {
        format!("{}:/usr/bin:/bin", bin_dir.display())
    } else {
        "/usr/bin:/bin".to_string()
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/slurm-ensemble.sh");
    Command::new("bash")
        .arg(&script)
        .args(args)
        .current_dir(d)
        .env("PATH", &path)
        .env("SLURM_ARRAY_TASK_COUNT", (last - first + 1).to_string())
        .env("SLURM_ARRAY_TASK_MIN", first.to_string())
        .env("SLURM_ARRAY_TASK_MAX", last.to_string())
        .env("SLURM_ARRAY_TASK_ID", task.to_string())
        .env_remove("SLURM_CPUS_PER_TASK")
        .output()
        .unwrap()
}

#[test]
fn the_slurm_example_runs_each_array_task_as_a_shard() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    for task in 1..=3 {
        ok(&slurm_task(d, (task, 1, 3), &["c.toml", "out"], true));
    }
    let merge = [
        "merge",
        "out/part-1.bin",
        "out/part-2.bin",
        "out/part-3.bin",
        "--json",
        "m.json",
        "--quiet",
    ];
    ok(&accelcal(&merge, d, 2));
    ok(&accelcal(
        &[
            "ensemble",
            "--config",
            "c.toml",
            "--json",
            "whole.json",
            "--quiet",
        ],
        d,
        2,
    ));
    let whole = common::summary_without_timing(&d.join("whole.json"));
    assert_eq!(common::summary_without_timing(&d.join("m.json")), whole);

    // A lost shard rerun alone, as the array 2-2 with M given: the merge is exact again.
    std::fs::remove_file(d.join("out/part-2.bin")).unwrap();
    ok(&slurm_task(d, (2, 2, 2), &["c.toml", "out", "3"], true));
    ok(&accelcal(&merge, d, 2));
    assert_eq!(common::summary_without_timing(&d.join("m.json")), whole);
    assert_eq!(
        std::fs::read_dir(d.join("out")).unwrap().count(),
        3,
        "hidden files left"
    );

    // The same without M would run shard 2/1: refused, as an array that is not 1-M.
    for (task, first, last) in [(2, 2, 2), (3, 2, 4)] {
        let o = slurm_task(d, (task, first, last), &["c.toml", "out"], true);
        let msg = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{msg}");
        assert!(msg.contains("must be exactly 1-M"), "{msg}");
    }
    // accelcal not on the PATH: said so, with the way out.
    let o = slurm_task(d, (1, 1, 3), &["c.toml", "out"], false);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{msg}");
    assert!(
        msg.contains("not on the PATH") && msg.contains("ACCELCAL="),
        "{msg}"
    );
}

/// The script's threads follow the CPUs Slurm gives the task (`SLURM_CPUS_PER_TASK`), or the
/// node's when none is set (it fixed 4 CPUs, and a smaller node left the array pending); the
/// command it runs is shard K/M of the array. Seen through a stand-in for accelcal (`ACCELCAL`)
/// that prints its thread count and arguments.
#[test]
fn the_slurm_example_takes_its_threads_from_the_task() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let stand_in = d.join("stand-in");
    std::fs::write(&stand_in, "#!/bin/sh\necho \"$RAYON_NUM_THREADS $*\"\n").unwrap();
    let executable = std::os::unix::fs::PermissionsExt::from_mode(0o755);
    std::fs::set_permissions(&stand_in, executable).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/slurm-ensemble.sh");
    let nproc = String::from_utf8(Command::new("nproc").output().unwrap().stdout).unwrap();
    for cpus in [Some("3"), None] {
        let mut c = Command::new("bash");
        c.arg(&script)
            .args(["c.toml", "out"])
            .current_dir(d)
            .env("ACCELCAL", &stand_in)
            .env("SLURM_ARRAY_TASK_COUNT", "3")
            .env("SLURM_ARRAY_TASK_MIN", "1")
            .env("SLURM_ARRAY_TASK_MAX", "3")
            .env("SLURM_ARRAY_TASK_ID", "2");
        match cpus {
            Some(n) => c.env("SLURM_CPUS_PER_TASK", n),
            None => c.env_remove("SLURM_CPUS_PER_TASK"),
        };
        let o = c.output().unwrap();
        ok(&o);
        let threads = cpus.unwrap_or(nproc.trim());
        assert_eq!(
            String::from_utf8_lossy(&o.stdout).trim(),
            format!(
                "{threads} ensemble --config c.toml --shard 2/3 --partial out/part-2.bin --quiet"
            )
        );
    }
}
