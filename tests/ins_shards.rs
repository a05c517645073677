//! `ensemble --model ins --shard K/M --partial F` and `merge`: the merged JSON is the text one
//! run writes (its run time apart), for any split, file order and thread count; every damaged,
//! missing or foreign partial is refused with exit code 2 and the file named.

mod common;

use std::path::Path;
use std::process::Output;

/// A short drive: N = 40 makes 3 blocks of 16, 16 and 8 realizations.
const CONFIG: &str = "[drive]\nduration_s = 60.0\n[ensemble]\nrealizations = 40\n";

fn accelcal(dir: &Path, args: &[&str], threads: usize) -> Output {
    common::run_in(dir, args, Some(threads))
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Exit code 2 and standard error naming every one of `words`.
fn refused(o: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in words {
        assert!(err.contains(w), "`{w}` not in: {err}");
    }
}

fn ins(extra: &[&str]) -> Vec<String> {
    let mut args = vec![
        "ensemble", "--model", "ins", "--config", "c.toml", "--quiet",
    ];
    args.extend(extra);
    args.into_iter().map(String::from).collect()
}

fn run(dir: &Path, args: &[String], threads: usize) -> Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    accelcal(dir, &args, threads)
}

/// Shard `k` of `m` into `part-k-of-m.bin`, on `threads` threads; its file name.
fn shard(dir: &Path, k: usize, m: usize, threads: usize) -> String {
    let file = format!("part-{k}-of-{m}.bin");
    ok(&run(
        dir,
        &ins(&["--shard", &format!("{k}/{m}"), "--partial", &file]),
        threads,
    ));
    file
}

fn merge(dir: &Path, files: &[String], json: &str) -> Output {
    let mut args = vec!["merge".to_string()];
    args.extend(files.iter().cloned());
    args.extend([
        "--json".to_string(),
        json.to_string(),
        "--quiet".to_string(),
    ]);
    run(dir, &args, 2)
}

/// The JSON's text without the lines of its run time (`elapsed_s`, `realizations_per_s`).
fn text_without_timing(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.contains("\"elapsed_s\"") && !l.contains("\"realizations_per_s\""))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn shards_merged_in_any_order_write_the_text_of_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    ok(&run(d, &ins(&["--json", "whole.json"]), 2));
    let whole = text_without_timing(&d.join("whole.json"));
    for m in 1..=3 {
        // Shards alternate between one and two threads; the files are given in reverse order.
        let mut files: Vec<String> = (1..=m).map(|k| shard(d, k, m, 1 + k % 2)).collect();
        files.reverse();
        let json = format!("merged-{m}.json");
        ok(&merge(d, &files, &json));
        assert_eq!(text_without_timing(&d.join(&json)), whole, "M = {m}");
    }
    // Negative control: another seed's ensemble is another text, so the comparison can fail.
    ok(&run(d, &ins(&["--seed", "5", "--json", "seed5.json"]), 2));
    assert_ne!(text_without_timing(&d.join("seed5.json")), whole);
    // The merged run time is the shards' (their headers' `elapsed_s`) added up in shard order.
    let header_elapsed = |f: String| {
        let text = std::fs::read(d.join(f)).unwrap();
        let line = text.split(|&b| b == b'\n').nth(1).unwrap().to_vec();
        let v: serde_json::Value = serde_json::from_slice(&line).unwrap();
        assert_eq!(v["model"], "ins");
        v["elapsed_s"].as_f64().unwrap()
    };
    let shards: f64 = (1..=3)
        .map(|k| header_elapsed(format!("part-{k}-of-3.bin")))
        .sum();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("merged-3.json")).unwrap()).unwrap();
    assert_eq!(v["summary"]["elapsed_s"].as_f64().unwrap(), shards);
}

#[test]
fn damaged_missing_and_foreign_partials_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    let files: Vec<String> = (1..=3).map(|k| shard(d, k, 3, 2)).collect();
    ok(&merge(d, &files, "ok.json"));

    // One flipped bit in the last block of shard 2.
    let mut bytes = std::fs::read(d.join(&files[1])).unwrap();
    let at = bytes.len() - 1000;
    bytes[at] ^= 0x10;
    std::fs::write(d.join("flipped.bin"), &bytes).unwrap();
    let with = |i: usize, f: &str| {
        let mut v = files.clone();
        v[i] = f.to_string();
        v
    };
    refused(
        &merge(d, &with(1, "flipped.bin"), "x.json"),
        &["flipped.bin", "damaged"],
    );
    // Cut inside a block.
    std::fs::write(d.join("cut.bin"), &bytes[..bytes.len() / 2]).unwrap();
    refused(
        &merge(d, &with(1, "cut.bin"), "x.json"),
        &["cut.bin", "truncated"],
    );
    // A shard missing, named; a shard twice.
    refused(
        &merge(d, &[files[0].clone(), files[2].clone()], "x.json"),
        &["shard 2/3 is missing", &files[0], &files[2]],
    );
    refused(
        &merge(d, &with(1, &files[0]), "x.json"),
        &["given twice", &files[0]],
    );
    // Another seed's shard.
    ok(&run(
        d,
        &ins(&["--seed", "5", "--shard", "2/3", "--partial", "seed5.bin"]),
        2,
    ));
    refused(
        &merge(d, &with(1, "seed5.bin"), "x.json"),
        &["seed5.bin", "seed 5"],
    );
    // A one-axis partial among the three-axis ones.
    std::fs::write(d.join("one.toml"), "[profile]\nduration_s = 4.0\n").unwrap();
    ok(&accelcal(
        d,
        &[
            "ensemble",
            "--config",
            "one.toml",
            "--realizations",
            "64",
            "--shard",
            "1/1",
            "--partial",
            "one_axis.bin",
            "--quiet",
        ],
        2,
    ));
    refused(
        &merge(d, &with(1, "one_axis.bin"), "x.json"),
        &["one_axis.bin", "accelerometer", "ins"],
    );
    assert!(!d.join("x.json").exists(), "a refused merge writes nothing");

    // M above the blocks of N = 40, which are 3; --engine of the one-axis model.
    refused(
        &run(d, &ins(&["--shard", "1/4", "--partial", "p.bin"]), 2),
        &["--shard", "≤ 3"],
    );
    assert!(!d.join("p.bin").exists());
    refused(
        &run(d, &ins(&["--engine", "epoch", "--json", "e.json"]), 2),
        &["--engine", "one-axis"],
    );
    ok(&run(
        d,
        &ins(&["--engine", "sample", "--json", "e.json"]),
        2,
    ));
}

#[test]
fn shards_of_a_21_state_ensemble_merge_to_the_text_of_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = format!(
        "{CONFIG}[imu]\ngyro_scale_factor_sigma_ppm = 1000.0\naccel_scale_factor_sigma_ppm = \
         1000.0\n[filter]\nerror_states = 21\n"
    );
    std::fs::write(d.join("c.toml"), config).unwrap();
    ok(&run(d, &ins(&["--json", "whole.json"]), 2));
    let whole = text_without_timing(&d.join("whole.json"));
    // The scale factors are in the final states.
    assert!(whole.contains("\"accel_scale_z\""), "{whole}");
    let files: Vec<String> = (1..=2).map(|k| shard(d, k, 2, k)).collect();
    ok(&merge(d, &files, "merged.json"));
    assert_eq!(text_without_timing(&d.join("merged.json")), whole);
    // Control: a 15-state shard of the same drive is of another ensemble.
    std::fs::write(d.join("c.toml"), CONFIG).unwrap();
    let other = shard(d, 2, 2, 2);
    std::fs::rename(d.join(&other), d.join("other.bin")).unwrap();
    refused(
        &merge(d, &[files[0].clone(), "other.bin".to_string()], "x.json"),
        &["other.bin", "another ensemble"],
    );
}
