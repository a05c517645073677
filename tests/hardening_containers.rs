//! The containers and streams `allan --imu` and `allan --accel` read, at their edges: a
//! declared size beyond what the file can hold (a ROS 1 bag's bz2 chunk, an MCAP chunk's
//! record), a device or a stream of binary data, an MCAP file whose summary counts more
//! messages than could be read, a schema spelt as ROS 1 spells it, a recording through a pipe,
//! and samples whose Allan variance leaves double precision. Each ends within seconds, with
//! exit code 2 and a message naming the file, or with 0 and the analysis (and a warning where
//! the file disagrees with itself); the memory of a run is measured where `/usr/bin/time` is.

mod common;

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// How a run ended: its exit code (None when killed at the limit), its standard error, its
/// wall time and its peak resident memory in kB (when measured).
struct Ended {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
    peak_kb: Option<u64>,
}

fn has_time() -> bool {
    Path::new("/usr/bin/time").exists()
        && Command::new("/usr/bin/time")
            .args(["-f", "%M", "true"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
}

/// Runs the binary with `args` in `dir` (standard input `input` through a pipe when given),
/// killed after `limit_s` seconds; its peak memory measured by `/usr/bin/time` when present.
fn run(dir: &Path, args: &[&str], input: Option<Vec<u8>>, limit_s: u64) -> Ended {
    let peak_file = dir.join(".peak");
    let _ = std::fs::remove_file(&peak_file);
    let measured = has_time();
    let mut command = if measured {
        let mut c = Command::new("/usr/bin/time");
        c.arg("-f")
            .arg("%M")
            .arg("-o")
            .arg(&peak_file)
            .arg(common::bin());
        c
    } else {
        Command::new(common::bin())
    };
    let start = Instant::now();
    let mut child = command
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "2")
        .stdin(if input.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let writer = input.map(|bytes| {
        let mut stdin = child.stdin.take().unwrap();
        // The reader may stop early: a broken pipe is its answer, not a failure.
        std::thread::spawn(move || drop(stdin.write_all(&bytes)))
    });
    let (status, stderr) = common::wait_limited(child, limit_s);
    if let Some(w) = writer {
        w.join().unwrap();
    }
    let seconds = start.elapsed().as_secs_f64();
    let peak_kb = std::fs::read_to_string(&peak_file)
        .ok()
        .and_then(|t| t.lines().last()?.trim().parse().ok());
    Ended {
        code: status.and_then(|s| s.code()),
        stderr,
        seconds,
        peak_kb,
    }
}

/// Expects a refusal: exit code 2 within `seconds`, no panic, every word of `words` in the
/// message.
fn assert_refused(e: &Ended, words: &[&str], seconds: f64, what: &str) {
    let msg = &e.stderr;
    assert_eq!(e.code, Some(2), "{what}: exit code (None = killed): {msg}");
    assert!(!msg.contains("panicked"), "{what}: {msg}");
    assert!(
        e.seconds < seconds,
        "{what}: {:.2} s, expected below {seconds} s",
        e.seconds
    );
    for w in words {
        assert!(msg.contains(w), "{what}: the message lacks {w:?}: {msg}");
    }
}

/// Expects the peak memory, when measured, below `mb` MB.
fn assert_peak_below(e: &Ended, mb: u64, what: &str) {
    match e.peak_kb {
        Some(kb) => assert!(
            kb < mb * 1024,
            "{what}: peak {} MB, expected below {mb}",
            kb / 1024
        ),
        None => eprintln!("{what}: /usr/bin/time is absent, the memory is not measured"),
    }
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn noise(&mut self) -> f64 {
        // The sum of 12 uniforms less 6: near-normal, variance 1.
        (0..12)
            .map(|_| {
                self.0 ^= self.0 >> 12;
                self.0 ^= self.0 << 25;
                self.0 ^= self.0 >> 27;
                (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
            })
            .sum::<f64>()
            - 6.0
    }
}

/// `sensor_msgs/msg/Imu` in CDR (little-endian): the stamp, a frame id, then the 37 doubles
/// (angular velocity at 13–15, linear acceleration at 25–27) 8-byte aligned after the header.
fn imu_cdr(t_ns: u64, gyro: [f64; 3], accel: [f64; 3]) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend(((t_ns / 1_000_000_000) as u32).to_le_bytes());
    b.extend(((t_ns % 1_000_000_000) as u32).to_le_bytes());
    let frame = b"imu_link";
    b.extend((frame.len() as u32 + 1).to_le_bytes());
    b.extend(frame);
    b.push(0);
    while (b.len() - 4) % 8 != 0 {
        b.push(0);
    }
    let mut values = [0.0; 37];
    values[13..16].copy_from_slice(&gyro);
    values[25..28].copy_from_slice(&accel);
    values.iter().for_each(|v| b.extend(v.to_le_bytes()));
    b
}

/// `sensor_msgs/Imu` serialized as ROS 1 does: header (seq, stamp, frame id), the 37 doubles.
fn imu_ros1(seq: u32, t_ns: u64, gyro: [f64; 3], accel: [f64; 3]) -> Vec<u8> {
    let mut m = Vec::new();
    let (sec, nsec) = ((t_ns / 1_000_000_000) as u32, (t_ns % 1_000_000_000) as u32);
    for w in [seq, sec, nsec, 8] {
        m.extend(w.to_le_bytes());
    }
    m.extend(b"imu_link");
    let mut values = [0.0; 37];
    values[3] = 1.0;
    values[13..16].copy_from_slice(&gyro);
    values[25..28].copy_from_slice(&accel);
    values.iter().for_each(|v| m.extend(v.to_le_bytes()));
    m
}

/// How [`write_mcap`] writes its messages.
struct McapLayout<'a> {
    schema: &'a str,
    encoding: &'a str,
    /// Bytes per chunk (`None`: the writer's default).
    chunk_size: Option<u64>,
}

const ROS2: McapLayout<'static> = McapLayout {
    schema: "sensor_msgs/msg/Imu",
    encoding: "cdr",
    chunk_size: None,
};

/// Writes a static IMU of `messages` at 100 Hz on topic `/imu` to the MCAP file `path` (white
/// noise about gravity), laid out as `layout` says.
fn write_mcap(path: &Path, messages: usize, layout: &McapLayout<'_>) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .chunk_size(layout.chunk_size)
        .create(file)
        .unwrap();
    let schema_encoding = if layout.encoding == "ros1" {
        "ros1msg"
    } else {
        "ros2msg"
    };
    let schema = w.add_schema(layout.schema, schema_encoding, b"").unwrap();
    let channel = w
        .add_channel(schema, "/imu", layout.encoding, &Default::default())
        .unwrap();
    let mut rng = Rng(31);
    for k in 0..messages {
        let t_ns = 1_700_000_000_000_000_000 + k as u64 * 10_000_000;
        let gyro = [1e-3 * rng.noise(), 1e-3 * rng.noise(), 1e-3 * rng.noise()];
        let accel = [
            0.01 * rng.noise(),
            0.01 * rng.noise(),
            9.81 + 0.01 * rng.noise(),
        ];
        let data = if layout.encoding == "ros1" {
            imu_ros1(k as u32, t_ns, gyro, accel)
        } else {
            imu_cdr(t_ns, gyro, accel)
        };
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: k as u32,
            log_time: t_ns,
            publish_time: t_ns,
        };
        w.write_to_known_channel(&header, &data).unwrap();
    }
    w.finish().unwrap();
}

/// Appends a ROS 1 bag record: its header's fields `name=value`, then its data.
fn bag_record(out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]) {
    let mut header = Vec::new();
    for (name, value) in fields {
        header.extend((name.len() as u32 + 1 + value.len() as u32).to_le_bytes());
        header.extend(name.as_bytes());
        header.push(b'=');
        header.extend(*value);
    }
    out.extend((header.len() as u32).to_le_bytes());
    out.extend(header);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(data);
}

/// The start of a ROS 1 bag: the magic line and a bag header without an index.
fn bag_start() -> Vec<u8> {
    let mut bag = b"#ROSBAG V2.0\n".to_vec();
    let header = [
        ("op", &[3u8][..]),
        ("index_pos", &[0; 8]),
        ("conn_count", &[1, 0, 0, 0]),
        ("chunk_count", &[0; 4]),
    ];
    bag_record(&mut bag, &header, &[b' '; 64]);
    bag
}

/// A ROS 1 bag of `messages` `sensor_msgs/Imu` at 100 Hz on `/imu`, in plain chunks of 500.
fn write_bag(path: &Path, messages: usize) {
    let mut bag = bag_start();
    let conn = 0u32.to_le_bytes();
    let mut kind = Vec::new();
    for f in [
        "type=sensor_msgs/Imu",
        "md5sum=6a62c6daae103f4ff57a132d6f95cec2",
    ] {
        kind.extend((f.len() as u32).to_le_bytes());
        kind.extend(f.as_bytes());
    }
    let mut rng = Rng(37);
    for first in (0..messages).step_by(500) {
        let mut chunk = Vec::new();
        let connection = [("op", &[7u8][..]), ("conn", &conn), ("topic", b"/imu")];
        bag_record(&mut chunk, &connection, &kind);
        for k in first..(first + 500).min(messages) {
            let t_ns = 1_700_000_000_000_000_000 + k as u64 * 10_000_000;
            let gyro = [1e-3 * rng.noise(), 1e-3 * rng.noise(), 1e-3 * rng.noise()];
            let accel = [
                0.01 * rng.noise(),
                0.01 * rng.noise(),
                9.81 + 0.01 * rng.noise(),
            ];
            let time = [0u8; 8];
            let fields = [("op", &[2u8][..]), ("conn", &conn), ("time", &time)];
            bag_record(&mut chunk, &fields, &imu_ros1(k as u32, t_ns, gyro, accel));
        }
        let size = (chunk.len() as u32).to_le_bytes();
        let fields = [
            ("op", &[5u8][..]),
            ("compression", b"none"),
            ("size", &size),
        ];
        bag_record(&mut bag, &fields, &chunk);
    }
    std::fs::write(path, bag).unwrap();
}

/// The bytes of a hexadecimal string.
fn unhex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
        .collect()
}

/// A bzip2 stream (one, level 9) of 10⁹ zero bytes: 722 bytes that expand 1.4 million times.
const BZ2_GIGABYTE_OF_ZEROS: &str = concat!(
    "425a68393141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f",
    "8e4000c0000008200030804d4642a025a90a80973141592653590e09e2df015f8e4000c0000008200030804d4642a025",
    "a90a8097314159265359430425f501149fc020c00000040008200030cc0529a6aaa22436009121e2ee48a70a1204b683",
    "16e0",
);

/// `allan --imu FILE --out out` in `dir`, killed after 60 s.
fn allan_imu(dir: &Path, file: &str) -> Ended {
    run(
        dir,
        &["allan", "--imu", file, "--out", "out", "-q"],
        None,
        60,
    )
}

/// The channels of `dir/out/allan.json`.
fn channels_of(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("out/allan.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["channels"].clone()
}

fn samples_of(dir: &Path) -> u64 {
    let text = std::fs::read_to_string(dir.join("out/allan.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["samples"].as_u64().unwrap()
}

#[test]
fn a_bag_chunk_declaring_more_than_its_bytes_can_hold_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut bag = bag_start();
    let at = bag.len();
    let bomb = unhex(BZ2_GIGABYTE_OF_ZEROS);
    let size = u32::MAX.to_le_bytes();
    let fields = [("op", &[5u8][..]), ("compression", b"bz2"), ("size", &size)];
    bag_record(&mut bag, &fields, &bomb);
    std::fs::write(d.join("bomb.bag"), &bag).unwrap();
    let e = allan_imu(d, "bomb.bag");
    let place = format!("the chunk at byte {at} declares 4294967295 bytes");
    let data = format!("its {} bytes of bz2 data", bomb.len());
    assert_refused(&e, &["bomb.bag", &place, &data, "at most"], 5.0, "bz2 bomb");
    assert_peak_below(&e, 100, "bz2 bomb");
    assert!(!d.join("out").exists());
}

/// Appends an MCAP record: its opcode, its length (u64) and its data.
fn mcap_record(out: &mut Vec<u8>, opcode: u8, data: &[u8]) {
    out.push(opcode);
    out.extend((data.len() as u64).to_le_bytes());
    out.extend(data);
}

/// Appends an MCAP string: its length (u32) and its bytes.
fn mcap_string(out: &mut Vec<u8>, s: &str) {
    out.extend((s.len() as u32).to_le_bytes());
    out.extend(s.as_bytes());
}

#[test]
fn an_mcap_record_longer_than_the_file_can_hold_is_refused_before_it_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A chunk (lz4) whose one record, a message, declares 512 MiB.
    let declared = 1u64 << 29;
    let mut inner = vec![0x05];
    inner.extend(declared.to_le_bytes());
    inner.extend([0u8; 64]);
    let mut encoder = lz4::EncoderBuilder::new().build(Vec::new()).unwrap();
    encoder.write_all(&inner).unwrap();
    let compressed = encoder.finish().0;
    let mut chunk = Vec::new();
    chunk.extend(0u64.to_le_bytes());
    chunk.extend(0u64.to_le_bytes());
    chunk.extend((9 + declared).to_le_bytes());
    chunk.extend(0u32.to_le_bytes());
    mcap_string(&mut chunk, "lz4");
    chunk.extend((compressed.len() as u64).to_le_bytes());
    chunk.extend(&compressed);
    let mut file = b"\x89MCAP0\r\n".to_vec();
    let mut header = Vec::new();
    mcap_string(&mut header, "ros2");
    mcap_string(&mut header, "accelcal tests");
    mcap_record(&mut file, 0x01, &header);
    mcap_record(&mut file, 0x06, &chunk);
    std::fs::write(d.join("bomb.mcap"), &file).unwrap();
    let e = allan_imu(d, "bomb.mcap");
    let words = [
        "bomb.mcap",
        "a record (opcode 0x05) declares 536870912 bytes",
        &format!("more than a file of {} bytes can hold", file.len()),
    ];
    assert_refused(&e, &words, 5.0, "MCAP record bomb");
    assert_peak_below(&e, 100, "MCAP record bomb");
}

#[test]
fn endless_devices_are_refused_at_their_first_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for flag in ["--imu", "--accel"] {
        for device in ["/dev/zero", "/dev/urandom"] {
            let what = format!("allan {flag} {device}");
            let e = run(d, &["allan", flag, device, "--out", "out"], None, 30);
            let words = [
                device,
                "first bytes",
                "neither text nor",
                "expected a CSV log",
            ];
            assert_refused(&e, &words, 2.5, &what);
            assert_peak_below(&e, 100, &what);
        }
    }
    // Nothing was spilled beside the output.
    let left: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != ".peak")
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// The offsets of the data section's top-level records of `file` with `opcode`.
fn top_level(file: &[u8], opcode: u8) -> Vec<usize> {
    let (mut at, mut found) = (8, Vec::new());
    while at + 9 <= file.len() {
        let op = file[at];
        let len = u64::from_le_bytes(file[at + 1..at + 9].try_into().unwrap()) as usize;
        if op == 0x0f {
            break;
        }
        if op == opcode {
            found.push(at);
        }
        at += 9 + len;
    }
    found
}

#[test]
fn an_mcap_whose_summary_lists_more_than_was_read_is_read_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let layout = McapLayout {
        chunk_size: Some(36_000),
        ..ROS2
    };
    write_mcap(&d.join("whole.mcap"), 1000, &layout);
    let e = allan_imu(d, "whole.mcap");
    assert_eq!(e.code, Some(0), "{}", e.stderr);
    assert!(!e.stderr.contains("warning"), "{}", e.stderr);
    assert_eq!(samples_of(d), 1000);
    let mut bytes = std::fs::read(d.join("whole.mcap")).unwrap();
    let chunks = top_level(&bytes, 0x06);
    assert!(chunks.len() >= 5, "{} chunks", chunks.len());
    // The last chunk's opcode made one no version of MCAP defines.
    bytes[*chunks.last().unwrap()] = 0x70;
    std::fs::write(d.join("damaged.mcap"), &bytes).unwrap();
    std::fs::remove_dir_all(d.join("out")).unwrap();
    let e = allan_imu(d, "damaged.mcap");
    assert_eq!(e.code, Some(0), "{}", e.stderr);
    let read = samples_of(d);
    assert!(read < 1000, "{read}");
    let warning = format!(
        "warning: damaged.mcap: its summary lists {} chunk(s) and 1000 message(s) on topic /imu; \
         {read} were read",
        chunks.len()
    );
    assert!(
        e.stderr.contains(&warning),
        "{warning:?} not in {}",
        e.stderr
    );
    assert_eq!(e.stderr.matches("warning:").count(), 1, "{}", e.stderr);
}

#[test]
fn the_ros1_spelling_of_the_imu_schema_and_ros1_messages_in_mcap_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_mcap(&d.join("ros2.mcap"), 1000, &ROS2);
    let e = allan_imu(d, "ros2.mcap");
    assert_eq!(e.code, Some(0), "{}", e.stderr);
    let expected = channels_of(d);
    let layouts = [
        ("ros1-name.mcap", "sensor_msgs/Imu", "cdr"),
        ("ros1-messages.mcap", "sensor_msgs/Imu", "ros1"),
    ];
    for (file, schema, encoding) in layouts {
        let layout = McapLayout {
            schema,
            encoding,
            chunk_size: None,
        };
        write_mcap(&d.join(file), 1000, &layout);
        std::fs::remove_dir_all(d.join("out")).unwrap();
        let e = allan_imu(d, file);
        assert_eq!(e.code, Some(0), "{file}: {}", e.stderr);
        assert_eq!(samples_of(d), 1000, "{file}");
        assert_eq!(channels_of(d), expected, "{file}: another analysis");
    }
    // An encoding it cannot decode is listed with what is accepted.
    let layout = McapLayout {
        encoding: "json",
        ..ROS2
    };
    write_mcap(&d.join("json.mcap"), 1000, &layout);
    let e = allan_imu(d, "json.mcap");
    let words = [
        "json.mcap",
        "no sensor_msgs/msg/Imu topic",
        "encoding cdr or ros1",
        "/imu (sensor_msgs/msg/Imu, encoding json)",
    ];
    assert_refused(&e, &words, 10.0, "json encoding");
}

#[test]
fn a_recording_through_a_pipe_is_read_as_the_recording_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_mcap(&d.join("imu.mcap"), 1000, &ROS2);
    write_bag(&d.join("imu.bag"), 1000);
    for file in ["imu.mcap", "imu.bag"] {
        let _ = std::fs::remove_dir_all(d.join("out"));
        let e = allan_imu(d, file);
        assert_eq!(e.code, Some(0), "{file}: {}", e.stderr);
        let expected = channels_of(d);
        std::fs::remove_dir_all(d.join("out")).unwrap();
        let bytes = std::fs::read(d.join(file)).unwrap();
        let args = ["allan", "--imu", "/dev/stdin", "--out", "out", "-q"];
        let e = run(d, &args, Some(bytes), 60);
        assert_eq!(e.code, Some(0), "{file} through a pipe: {}", e.stderr);
        assert_eq!(channels_of(d), expected, "{file} through a pipe");
        assert_eq!(samples_of(d), 1000, "{file} through a pipe");
    }
    // A topic that is not there is named as it is in a file.
    let bytes = std::fs::read(d.join("imu.mcap")).unwrap();
    let args = [
        "allan",
        "--imu",
        "/dev/stdin",
        "--topic",
        "/none",
        "--out",
        "o2",
    ];
    let e = run(d, &args, Some(bytes), 60);
    assert_refused(
        &e,
        &["/dev/stdin", "/none", "/imu (sensor_msgs/msg/Imu)"],
        10.0,
        "topic",
    );
    // Binary data through a pipe is refused at its first bytes.
    let args = ["allan", "--imu", "/dev/stdin", "--out", "o3"];
    let e = run(d, &args, Some(vec![0u8; 1 << 22]), 30);
    assert_refused(&e, &["/dev/stdin", "first bytes (00 00"], 2.5, "zeros");
}

/// Writes a CSV log of `columns` with 2 000 rows at 100 Hz, each value `value(row, column)`.
fn write_csv(path: &Path, columns: &[&str], value: impl Fn(usize, usize) -> f64) {
    let mut text = format!("t_s,{}\n", columns.join(","));
    for k in 0..2000 {
        text.push_str(&format!("{}", k as f64 * 0.01));
        for c in 0..columns.len() {
            text.push_str(&format!(",{:e}", value(k, c)));
        }
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

const SIX: [&str; 6] = [
    "ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s",
];

#[test]
fn samples_beyond_double_precision_are_refused_once_and_not_called_constant() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let noise: Vec<f64> = {
        let mut rng = Rng(41);
        (0..2000 * 6).map(|_| rng.noise()).collect()
    };
    let noise = &noise;
    let scaled = |scale: f64| move |k: usize, c: usize| scale * (1.0 + 1e-3 * noise[6 * k + c]);
    write_csv(&d.join("big.csv"), &["accel_m_s2"], scaled(1e156));
    write_csv(&d.join("big6.csv"), &SIX, scaled(1e156));
    write_csv(&d.join("tiny6.csv"), &SIX, scaled(1e-160));
    let once = |e: &Ended, words: &str, what: &str| {
        assert_eq!(e.stderr.matches(words).count(), 1, "{what}: {}", e.stderr);
        assert!(!e.stderr.contains("same number"), "{what}: {}", e.stderr);
    };
    for (flag, file) in [("--accel", "big.csv"), ("--imu", "big6.csv")] {
        let e = run(d, &["allan", flag, file, "--out", "out"], None, 30);
        let words = [file, "outside the range", "between 1e-30 and 1e30"];
        assert_refused(&e, &words, 10.0, file);
        once(&e, "outside the range", file);
    }
    let e = run(
        d,
        &["allan", "--imu", "tiny6.csv", "--out", "out"],
        None,
        30,
    );
    assert_refused(
        &e,
        &["tiny6.csv", "column ax_m_s2", "underflows"],
        10.0,
        "tiny",
    );
    once(&e, "underflows", "tiny");
    // A constant channel is still one, said once.
    write_csv(&d.join("constant.csv"), &SIX, |k, c| {
        if c == 1 {
            0.5
        } else {
            1.0 + 1e-3 * noise[6 * k + c]
        }
    });
    let e = run(
        d,
        &["allan", "--imu", "constant.csv", "--out", "out"],
        None,
        30,
    );
    let words = [
        "constant.csv",
        "column ay_m_s2",
        "every sample is the same number",
    ];
    assert_refused(&e, &words, 10.0, "constant");
    assert_eq!(e.stderr.matches("same number").count(), 1, "{}", e.stderr);
    assert!(!d.join("out").exists());
}
