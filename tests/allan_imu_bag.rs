//! `accelcal allan --imu` on ROS 2 recordings made by the ROS tools' own Python packages
//! (`tests/allan_imu_bag.py`: rosbags writes the bag and the CDR, mcap the MCAP file): a ROS 2
//! bag directory with MCAP storage, an MCAP file (lz4 chunks, two Imu topics with another frame
//! id, hence another CDR alignment) and the CSV export of the same messages give the same
//! allan.json byte for byte; bad containers and messages exit with 2 naming the file, the topic
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
