//! `accelcal allan --imu` on ROS recordings made by the ROS tools' own Python packages
//! (`tests/allan_imu_bag.py`: rosbags writes the bags and the messages, mcap the MCAP file): a
//! ROS 2 bag directory with MCAP storage, an MCAP file (lz4 chunks, two Imu topics with another
//! frame id, hence another CDR alignment), ROS 1 bags (plain, lz4 and bz2 chunks) and the CSV export
//! of the same messages give the same allan.json byte for byte; bad containers and messages exit with 2 naming the file, the topic
//! and the message.
//!
//! The packages come from PyPI: `.ci/run` installs `mcap` and `rosbags` into its virtual
//! environment `target/python-ci`. The test takes that environment's Python when it exists, else
//! `python3`, and is skipped (saying so) when neither has both packages.

use std::path::{Path, PathBuf};
use std::process::Command;

fn python() -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/python-ci/bin/python");
    [venv, PathBuf::from("python3")].into_iter().find(|p| {
        Command::new(p)
            .args(["-c", "import mcap, rosbags, numpy"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

fn allan(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .arg("allan")
        .args(args)
        .output()
        .unwrap()
}

/// allan.json of `--imu input` (with `--topic` when given), after a successful run.
fn allan_json(input: &Path, topic: Option<&str>, out: &Path) -> Vec<u8> {
    let mut args = vec![
        "--imu",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
    ];
    if let Some(t) = topic {
        args.extend(["--topic", t]);
    }
    let o = allan(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(out.join("allan.json")).unwrap()
}

/// The exit code 2 and every word of `words` in standard error.
fn refused(input: &Path, topic: Option<&str>, words: &[&str]) {
    let out = input.with_extension("out");
    let mut args = vec![
        "--imu",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(t) = topic {
        args.extend(["--topic", t]);
    }
    let o = allan(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}: {err}", input.display());
    for w in words {
        assert!(err.contains(w), "{w:?} not in {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_bag_its_mcap_and_its_csv_give_the_same_allan_json() {
    let Some(python) = python() else {
        // CI sets ACCELCAL_REQUIRE_REFERENCES: there a missing package is a failure.
        assert!(
            std::env::var_os("ACCELCAL_REQUIRE_REFERENCES").is_none(),
            "no Python with the mcap and rosbags packages (pip install mcap rosbags)"
        );
        eprintln!(
            "skipped: no Python with the mcap and rosbags packages (pip install mcap rosbags)"
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/allan_imu_bag.py");
    let o = Command::new(&python)
        .arg(script)
        .arg(d)
        .arg("20000")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bag = allan_json(&d.join("bag"), None, &d.join("o-bag"));
    let mcap = allan_json(&d.join("imu.mcap"), Some("/imu"), &d.join("o-mcap"));
    let mcap2 = allan_json(&d.join("imu.mcap"), Some("/imu2"), &d.join("o-mcap2"));
    let csv = allan_json(&d.join("imu.csv"), None, &d.join("o-csv"));
    assert!(
        bag == mcap && mcap == mcap2,
        "the bag and the MCAP file differ"
    );
    assert!(bag == csv, "the bag and its CSV export differ");
    ros1_bags(d, &csv);
    let json: serde_json::Value = serde_json::from_slice(&bag).unwrap();
    assert_eq!(json["samples"], 20_000);
    assert_eq!(json["channels"].as_object().unwrap().len(), 6);

    // Which topic: several Imu topics, or none, are listed with their types.
    let listing = "/imu (sensor_msgs/msg/Imu), /imu2 (sensor_msgs/msg/Imu), /temperature (sensor_msgs/msg/Temperature)";
    refused(&d.join("imu.mcap"), None, &["imu.mcap", "--topic", listing]);
    refused(&d.join("imu.mcap"), Some("/none"), &["/none", listing]);
    refused(
        &d.join("other.mcap"),
        None,
        &[
            "no sensor_msgs/msg/Imu topic",
            "/temperature (sensor_msgs/msg/Temperature)",
        ],
    );
    // A message's problem names the topic and the message.
    refused(
        &d.join("nan.mcap"),
        None,
        &["nan.mcap, topic /imu, message 7", "`gy_rad_s` = `NaN`"],
    );
    refused(
        &d.join("back.mcap"),
        None,
        &["back.mcap, topic /imu, message 9", "not after"],
    );
    refused(
        &d.join("imu.csv"),
        Some("/imu"),
        &["--topic", "read as CSV"],
    );

    bad_containers_are_refused(d);
    mutations_never_panic(d);
}

/// Bytes of the MCAP file and the ROS 1 bags changed at random (a byte flipped, a stretch cut
/// out, the end cut off; 24 each from a fixed seed, 6 of the bz2 bag): every run ends with 0 or
/// 2, never a panic.
fn mutations_never_panic(d: &Path) {
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    // bz2 decompresses at ~20 MB/s: 6 mutations of that bag keep the test's time short.
    for (name, count) in [("imu.mcap", 24), ("imu.bag", 24), ("imu_bz2.bag", 6)] {
        let bytes = std::fs::read(d.join(name)).unwrap();
        for k in 0..count {
            let mut b = bytes.clone();
            let at = next(b.len());
            match k % 3 {
                0 => b[at] ^= 1 << next(8),
                1 => {
                    let len = next(4096).min(b.len() - at);
                    b.drain(at..at + len);
                }
                _ => b.truncate(at),
            }
            let path = d.join(format!("mutated-{k}-{name}"));
            std::fs::write(&path, &b).unwrap();
            let out = d.join(format!("m-{k}-{name}"));
            let o = allan(&[
                "--imu",
                path.to_str().unwrap(),
                "--topic",
                "/imu",
                "--out",
                out.to_str().unwrap(),
                "-q",
            ]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(
                matches!(o.status.code(), Some(0 | 2)) && !err.contains("panicked"),
                "{name} mutation {k} at byte {at}: {:?} {err}",
                o.status.code()
            );
        }
    }
}

/// ROS 1 bags of the same messages (plain, lz4 and bz2 chunks, rosbags' three) give the CSV's
/// allan.json byte for byte; a chunk of another compression, a bz2 chunk whose data is damaged
/// and a truncated bag are refused with the byte offset of the record.
fn ros1_bags(d: &Path, csv: &[u8]) {
    for bag in ["imu.bag", "imu_lz4.bag", "imu_bz2.bag"] {
        let json = allan_json(&d.join(bag), None, &d.join(format!("o-{bag}")));
        assert!(json == csv, "{bag} and the CSV export differ");
    }
    let bz2 = std::fs::read(d.join("imu_bz2.bag")).unwrap();
    let named = bz2
        .windows(15)
        .position(|w| w == b"compression=bz2")
        .unwrap();
    let mut other = bz2.clone();
    other[named + 12..named + 15].copy_from_slice(b"xz9");
    std::fs::write(d.join("xz9.bag"), &other).unwrap();
    refused(
        &d.join("xz9.bag"),
        None,
        &[
            "xz9.bag",
            "the chunk at byte",
            "compressed with xz9",
            "expected none, lz4 or bz2",
        ],
    );
    // The first chunk's bzip2 stream ("BZh9", then its blocks): a byte of its blocks changed.
    let stream = bz2.windows(4).position(|w| w == b"BZh9").unwrap();
    let mut damaged = bz2.clone();
    damaged[stream + 40] ^= 0x55;
    std::fs::write(d.join("damaged.bag"), &damaged).unwrap();
    refused(
        &d.join("damaged.bag"),
        None,
        &[
            "damaged.bag",
            "the chunk at byte",
            "bz2 data that does not decompress",
        ],
    );
    let bytes = std::fs::read(d.join("imu.bag")).unwrap();
    let truncated = d.join("truncated.bag");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    refused(&truncated, None, &["truncated.bag", "byte", "cut short"]);
}

/// Containers the mcap crate refuses (truncated, a chunk whose CRC does not match, an unknown
/// compression) and a bag whose storage is not MCAP.
fn bad_containers_are_refused(d: &Path) {
    let bytes = std::fs::read(d.join("imu.mcap")).unwrap();
    let truncated = d.join("truncated.mcap");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    refused(
        &truncated,
        Some("/imu"),
        &["truncated.mcap", "ended in the middle"],
    );
    let lz4 = bytes.windows(3).position(|w| w == b"lz4").unwrap();
    let mut flipped = bytes.clone();
    flipped[lz4 + 2000] ^= 0x01;
    let crc = d.join("crc.mcap");
    std::fs::write(&crc, &flipped).unwrap();
    refused(&crc, Some("/imu"), &["crc.mcap", "CRC failed"]);
    let mut unknown = bytes.clone();
    unknown[lz4..lz4 + 3].copy_from_slice(b"xz9");
    let compression = d.join("compression.mcap");
    std::fs::write(&compression, &unknown).unwrap();
    refused(&compression, Some("/imu"), &["compression.mcap", "xz9"]);
    let sqlite = d.join("sqlite");
    std::fs::create_dir(&sqlite).unwrap();
    std::fs::write(
        sqlite.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n",
    )
    .unwrap();
    refused(&sqlite, None, &["storage is sqlite3", "expected mcap"]);
}
