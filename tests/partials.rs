//! Partial files that cannot be trusted are refused by `merge` with exit code 2, naming the file
//! and what failed: a changed bit anywhere, non-finite or huge values written into a block, a
//! configuration edited alike in every file's header (with or without a new header digest), a
//! partial of the first format, a missing shard, an input that is a device. The untouched files
//! merge, as the control of each case.

mod common;

use std::path::Path;
use std::process::Output;

use common::partials::{self, DIGEST};

/// Writes the shard partials `a.bin` (1/2) and `b.bin` (2/2) of a 200-realization ensemble.
fn two_partials(d: &Path) {
    for (k, file) in [("1/2", "a.bin"), ("2/2", "b.bin")] {
        let args = ["ensemble", "--realizations", "200", "-q", "--shard", k];
        let o = common::run_in(d, &[&args[..], &["--partial", file]].concat(), Some(2));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

fn merge(d: &Path, files: &[&str]) -> Output {
    let _ = std::fs::remove_file(d.join("m.json"));
    let args = [&["merge"][..], files, &["--json", "m.json", "-q"]].concat();
    common::run_in(d, &args, Some(2))
}

/// `merge` of `files` exits 2 with every word of `expect` in its message and writes nothing.
fn refused(d: &Path, files: &[&str], expect: &[&str], what: &str) {
    let o = merge(d, files);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {msg}");
    assert!(!msg.contains("panicked"), "{what}: {msg}");
    for word in expect {
        assert!(msg.contains(word), "{what}: message lacks {word:?}: {msg}");
    }
    assert!(!d.join("m.json").exists(), "{what}: a refused merge wrote");
}

fn accepted(d: &Path, files: &[&str]) {
    let o = merge(d, files);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A copy of `b.bin` named `name` with `change` applied to its bytes.
fn damaged(d: &Path, name: &str, change: impl FnOnce(&mut Vec<u8>)) {
    let mut bytes = std::fs::read(d.join("b.bin")).unwrap();
    change(&mut bytes);
    std::fs::write(d.join(name), bytes).unwrap();
}

/// The issue's reproducer: one flipped bit in a block's payload moved a whiteness value from
/// 4.38 to 53 712.8 and `merge` exited 0. Every position tried here (the header, the digest
/// line, a block's index, count, first and last sums, a digest) is refused.
#[test]
fn a_flipped_bit_anywhere_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    accepted(d, &["a.bin", "b.bin"]);
    let bytes = std::fs::read(d.join("b.bin")).unwrap();
    let head = partials::header_len(&bytes);
    let block = (bytes.len() - head) / 2;
    let positions = [
        (40, "header"),
        (head - 5, "header"),
        (head + 3, "block 2"),
        (head + 9, "block 2"),
        (head + 16 + 8 * 57 + 6, "block 2"),
        (head + block - DIGEST - 1, "block 2"),
        (head + block - 1, "block 2"),
        (head + block + 800, "block 3"),
        (bytes.len() - DIGEST - 2, "block 3"),
    ];
    for (at, part) in positions {
        for bit in [0, 4, 6] {
            damaged(d, "flipped.bin", |b| b[at] ^= 1 << bit);
            refused(
                d,
                &["a.bin", "flipped.bin"],
                &["flipped.bin", "damaged or edited", part],
                &format!("byte {at} bit {bit}"),
            );
        }
    }
}

/// NaN, ±∞ and 1e308 written over a sum in a block are refused; written with a block digest
/// computed anew (a forged file), the non-finite ones are still refused as not finite.
#[test]
fn values_written_into_a_block_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    let bytes = std::fs::read(d.join("b.bin")).unwrap();
    let head = partials::header_len(&bytes);
    for value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e308] {
        let at = head + 16 + 8 * 1234;
        damaged(d, "written.bin", |b| {
            b[at..at + 8].copy_from_slice(&value.to_le_bytes());
        });
        let what = format!("{value} written");
        refused(
            d,
            &["a.bin", "written.bin"],
            &["written.bin", "block 2"],
            &what,
        );
        let mut parts = partials::split(&bytes);
        parts.blocks[1][16 + 8 * 99..16 + 8 * 100].copy_from_slice(&value.to_le_bytes());
        std::fs::write(d.join("forged.bin"), partials::join(&parts)).unwrap();
        if value.is_finite() {
            // Beyond the digest's reach: a file forged on purpose.
            continue;
        }
        let what = format!("{value} forged");
        refused(
            d,
            &["a.bin", "forged.bin"],
            &["forged.bin", "block 3", "not finite"],
            &what,
        );
    }
    // The format as the test reads it is the format as written: an unchanged split and join is
    // the same file, and merges.
    std::fs::write(
        d.join("rejoined.bin"),
        partials::join(&partials::split(&bytes)),
    )
    .unwrap();
    assert_eq!(std::fs::read(d.join("rejoined.bin")).unwrap(), bytes);
    accepted(d, &["a.bin", "rejoined.bin"]);
}

/// The issue's reproducer: the configuration edited alike in every file's header was reported
/// over data made with another. Edited, the header no longer matches its digest; given a digest
/// of its own, it no longer matches its blocks'.
#[test]
fn a_configuration_edited_in_every_header_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    let edits = [
        (r#""noise_var_m2_s4":0.0004"#, r#""noise_var_m2_s4":0.0009"#),
        (r#""seed":2017"#, r#""seed":2018"#),
        (r#""truth":"analytic""#, r#""truth":"euler""#),
        (r#""elapsed_s":"#, r#""elapsed_s":1"#),
    ];
    for (from, to) in edits {
        for redigest in [false, true] {
            for file in ["a.bin", "b.bin"] {
                let edited = d.join(format!("e-{file}"));
                std::fs::copy(d.join(file), &edited).unwrap();
                partials::edit_header(&edited, from, to, redigest);
            }
            let part = if redigest { "block 0" } else { "header" };
            refused(
                d,
                &["e-a.bin", "e-b.bin"],
                &["e-a.bin", "damaged or edited", part],
                &format!("{to}, new header digest: {redigest}"),
            );
        }
    }
}

/// The issue's reproducer: with one file's header edited, the intact file was blamed. The edited
/// one is named, whichever comes first.
#[test]
fn the_edited_file_is_named_not_the_intact_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    std::fs::copy(d.join("b.bin"), d.join("e-b.bin")).unwrap();
    partials::edit_header(&d.join("e-b.bin"), r#""seed":2017"#, r#""seed":5"#, false);
    for files in [["a.bin", "e-b.bin"], ["e-b.bin", "a.bin"]] {
        refused(
            d,
            &files,
            &["e-b.bin: damaged or edited"],
            &format!("{files:?}"),
        );
    }
}

#[test]
fn a_partial_of_the_first_format_is_refused_with_the_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    damaged(d, "old.bin", |b| b[17] = b'1');
    refused(
        d,
        &["a.bin", "old.bin"],
        &["old.bin", "format 1", "run its shard again"],
        "format 1",
    );
}

/// The issue's reproducer: `part-1.bin: shard 2/4 is missing` blamed a file that is fine. The
/// message names the missing shard and which file holds which.
#[test]
fn a_missing_shard_is_named_without_blaming_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    let o = merge(d, &["b.bin"]);
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{msg}");
    assert!(
        msg.contains("error: shard 1/2 is missing") && msg.contains("b.bin (shard 2/2)"),
        "{msg}"
    );
}

/// Inputs that are not files: a device read without bound (4.2 GB, then an abort) and a
/// directory; and a file that is not there, which was called "not an accelcal partial file".
#[test]
fn inputs_that_are_not_partial_files_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    two_partials(d);
    let start = std::time::Instant::now();
    refused(
        d,
        &["a.bin", "/dev/zero"],
        &["/dev/zero", "not an accelcal partial file"],
        "/dev/zero",
    );
    assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
    refused(
        d,
        &["a.bin", "."],
        &["cannot read", "directory"],
        "a directory",
    );
    refused(
        d,
        &["a.bin", "absent.bin"],
        &["absent.bin: cannot read", "No such file"],
        "a missing file",
    );
}
