//! Seeded fuzzing of the surfaces a user can hand the tool: the one-axis sensor logs (through
//! `calibrate --accel --gps`), the three-axis recordings (through `calibrate --imu --gnss`: the
//! shipped comma2k19 minute's first 4 s; and their longitudes written another way, which must
//! calibrate to the same numbers), the IMU containers (MCAP, ROS 1 bags, through `allan
//! --imu`), the one-axis and three-axis configurations (through `ensemble`, `simulate`,
//! `sensitivity` and `report`, at tiny sizes; `three_axis.rs`), the shard partials (through
//! `merge`) and the command line.
//!
//! Every input is a mutation of a valid one by a generator seeded per case, so a finding is
//! reproduced by its surface and case number (printed, and its inputs kept under the target
//! directory). The release binary runs each input under a wall-clock limit and, where `prlimit`
//! exists, an address-space cap. Each run must end with exit code 0 or 2, without a panic; a
//! failing run must leave a pre-existing output as it was; a merge must equal the one-process
//! run or be refused.
//!
//! `ACCELCAL_FUZZ_CASES` sets the total number of inputs (default 5 000), `ACCELCAL_FUZZ_SEED`
//! the base seed. A finding that belongs to work in progress may be listed in [`KNOWN`] with its
//! reason (reported, not failed, unless `ACCELCAL_FUZZ_STRICT=1`); the list is empty.

mod common;
#[path = "fuzz/three_axis.rs"]
mod three_axis;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Wall-clock limit of one run: every input is tiny, so a run this long is a hang.
const LIMIT: Duration = Duration::from_secs(20);
/// The limit of a `report` run: whatever its configuration's size, a valid one also simulates
/// 100 static logs and the three-axis study's five ensembles of the 600 s drive (about 25 s on
/// the one thread a run gets here).
const REPORT_LIMIT: Duration = Duration::from_secs(120);

/// The limit of a run with `args`.
fn limit_of(args: &[String]) -> Duration {
    if args.first().map(String::as_str) == Some("report") {
        REPORT_LIMIT
    } else {
        LIMIT
    }
}
/// Address-space cap of one run, bytes.
const MEMORY_CAP: u64 = 2 << 30;

/// SplitMix64: a small seeded generator, so that a case is reproduced by its number.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

/// Values that have broken parsers and numerics before.
const TOKENS: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1e-300",
    "5e-324",
    "1e308",
    "1e400",
    "-1e308",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e6",
    "1e-12",
    "2.5",
    "\"x\"",
    "\"\"",
    "true",
    "1979-05-27",
    "[]",
    "{}",
    "0x10",
    "18446744073709551616",
    "\u{feff}1",
    "1\u{a0}",
    "١",
    "1_000",
    "+1",
    ".5",
    "1.",
    "1e",
    "--1",
];

/// Values of the keys that size a run: bad or small, never a long legitimate run.
const SIZE_TOKENS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "7",
    "1e-300",
    "nan",
    "inf",
    "1e400",
    "\"x\"",
    "true",
    "1979-05-27",
    "[]",
    "2.5",
    "1e12",
    "1000000000000",
    "18446744073709551616",
    "\u{feff}2",
];

/// The keys of the tiny configuration, and whether each sizes the run.
const KEYS: &[(&str, &str, bool)] = &[
    ("profile", "accel_amplitude_m_s2", false),
    ("profile", "accel_angular_freq_rad_s", false),
    ("profile", "duration_s", true),
    ("accelerometer", "sample_rate_hz", true),
    ("accelerometer", "noise_var_m2_s4", false),
    ("accelerometer", "bias_var_m2_s4", false),
    ("accelerometer", "output", false),
    ("gps", "sample_rate_hz", true),
    ("gps", "position_sigma_m", false),
    ("gps", "velocity_sigma_m_s", false),
    ("gps", "fix_at_start", false),
    ("initial", "position_mean_m", false),
    ("initial", "position_sigma_m", false),
    ("initial", "velocity_mean_m_s", false),
    ("initial", "velocity_sigma_m_s", false),
    ("filter", "accel_noise_var_m2_s4", false),
    ("filter", "bias_var_m2_s4", false),
    ("filter", "gps_position_sigma_m", false),
    ("filter", "gps_velocity_sigma_m_s", false),
    ("filter", "initial_position_sigma_m", false),
    ("filter", "initial_velocity_sigma_m_s", false),
    ("ensemble", "realizations", true),
    ("ensemble", "seed", false),
    ("ensemble", "truth", false),
    ("checks", "false_alarm_rate", false),
    ("checks", "residual_pair_s", false),
    ("checks", "residual_max_lag", true),
    ("sensitivity", "factors", false),
    ("sensitivity", "ensembles", true),
    ("sensitivity", "draws", true),
];

/// A tiny valid configuration: 2 s at 20 Hz with 5 Hz fixes, 12 realizations.
const TINY: &str = "[profile]\nduration_s = 2.0\n\n[accelerometer]\nsample_rate_hz = 20.0\n\n\
                    [gps]\nsample_rate_hz = 5.0\n\n[ensemble]\nrealizations = 12\n\n\
                    [sensitivity]\nfactors = [0.5, 2.0]\nensembles = 0\ndraws = 3\n";

/// A finite number of any magnitude, written as a value: most are accepted, so that the work
/// past parsing is fuzzed too.
fn number(rng: &mut Rng) -> String {
    let mantissa = rng.below(20_000) as f64 / 1000.0 - 10.0;
    let exponent = if rng.chance(80) {
        rng.below(13) as i32 - 6
    } else {
        rng.below(640) as i32 - 320
    };
    format!("{mantissa}e{exponent}")
}

/// A hostile token or, as often, a plain number.
fn value(rng: &mut Rng) -> String {
    if rng.chance(50) {
        number(rng)
    } else {
        rng.pick(TOKENS).to_string()
    }
}

/// Mutates `text` in place by one of the generic mutations: a byte, a line, a cut.
fn mutate_bytes(rng: &mut Rng, text: &mut Vec<u8>) {
    if text.is_empty() {
        text.extend_from_slice(rng.pick(TOKENS).as_bytes());
        return;
    }
    let at = rng.below(text.len());
    match rng.below(9) {
        0 => text[at] ^= 1 << rng.below(8),
        1 => text[at] = *rng.pick(b"\r\n\0\t =,#[]\"'.-e9\x7f\xff"),
        2 => {
            let end = (at + 1 + rng.below(40)).min(text.len());
            text.drain(at..end);
        }
        3 => text.truncate(at),
        4 => {
            let token = rng.pick(TOKENS).as_bytes().to_vec();
            text.splice(at..at, token);
        }
        5 => {
            // Every line end as CR alone, or as CR LF.
            let s = String::from_utf8_lossy(text).into_owned();
            let ends = if rng.chance(50) { "\r" } else { "\r\n" };
            *text = s.replace('\n', ends).into_bytes();
        }
        6 => {
            // A line duplicated.
            let s = String::from_utf8_lossy(text).into_owned();
            let lines: Vec<&str> = s.lines().collect();
            let line = lines[rng.below(lines.len())];
            *text = format!("{s}{line}\n").into_bytes();
        }
        7 => text.splice(at..at, "\u{feff}".bytes()).for_each(drop),
        _ => text.extend(std::iter::repeat_n(b'9', 1 + rng.below(400))),
    }
}

/// A configuration: the tiny one with a key set to a hostile value, a line added, or bytes
/// mutated.
fn fuzz_config(rng: &mut Rng) -> Vec<u8> {
    let mut text = TINY.to_string();
    let mutations = if rng.chance(60) { 1 } else { 2 + rng.below(2) };
    for _ in 0..mutations {
        match rng.below(4) {
            0 | 1 => {
                let &(table, key, sizes) = rng.pick(KEYS);
                let value = if sizes {
                    rng.pick(SIZE_TOKENS).to_string()
                } else {
                    value(rng)
                };
                text = set_key(&text, table, key, &value);
            }
            2 => {
                let extra = [
                    "[gps]\n",
                    "bogus = 1\n",
                    "[filter]\nunknown_key = 2\n",
                    "[ensemble]\nrealizations = 13\n",
                    "[[profile]]\n",
                    "x.y.z = 1\n",
                    "[checks]\nresidual_pair_s = [0.4, 1.2]\n",
                    "[checks]\nresidual_pair_s = [1.2, 0.4, 9]\n",
                ];
                let line: &&str = rng.pick(&extra[..]);
                text.push_str(line);
            }
            _ => {
                let mut bytes = text.into_bytes();
                mutate_bytes(rng, &mut bytes);
                return bytes;
            }
        }
    }
    text.into_bytes()
}

/// `text` with `key` of `[table]` set to `value` (the table added when missing).
fn set_key(text: &str, table: &str, key: &str, value: &str) -> String {
    let header = format!("[{table}]\n");
    let line = format!("{key} = {value}\n");
    match text.find(&header) {
        Some(at) => {
            let body = at + header.len();
            let section_end = text[body..]
                .find("\n[")
                .map_or(text.len(), |i| body + i + 1);
            let section = &text[body..section_end];
            let replaced = match section
                .lines()
                .position(|l| l.starts_with(&format!("{key} =")))
            {
                Some(i) => section
                    .lines()
                    .enumerate()
                    .map(|(j, l)| {
                        if i == j {
                            line.clone()
                        } else {
                            format!("{l}\n")
                        }
                    })
                    .collect(),
                None => format!("{line}{section}"),
            };
            format!("{}{replaced}{}", &text[..body], &text[section_end..])
        }
        None => format!("{text}\n{header}{line}"),
    }
}

/// A run's end: its exit code (None when killed or signalled), whether the time limit killed
/// it, and its standard error.
struct Ended {
    code: Option<i32>,
    hung: bool,
    /// The limit it ran under.
    limit: Duration,
    stderr: String,
}

/// Runs the binary with `args` in `dir` under the time limit and, where `prlimit` exists, the
/// memory cap.
fn run_capped(dir: &Path, args: &[String], capped: bool) -> Ended {
    let mut command = if capped {
        let mut c = Command::new("prlimit");
        c.arg(format!("--as={MEMORY_CAP}"))
            .arg("--core=0")
            .arg("--")
            .arg(common::bin());
        c
    } else {
        Command::new(common::bin())
    };
    let err_path = dir.join(".stderr");
    let err_file = std::fs::File::create(&err_path).unwrap();
    let mut child = command
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file)
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    let limit = limit_of(args);
    let (code, hung) = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break (status.code(), false);
        }
        if start.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            break (None, true);
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let bytes = std::fs::read(&err_path).unwrap_or_default();
    Ended {
        code,
        hung,
        limit,
        stderr: String::from_utf8_lossy(&bytes[..bytes.len().min(4000)]).into_owned(),
    }
}

/// What is wrong with `ended`, if anything: an exit code other than 0 and 2, a panic, a hang.
fn fault(ended: &Ended) -> Option<String> {
    if ended.hung {
        return Some(format!("no end within {} s", ended.limit.as_secs()));
    }
    if ended.stderr.contains("panicked") {
        return Some("panic".into());
    }
    match ended.code {
        Some(0 | 2) => None,
        Some(c) => Some(format!("exit code {c}")),
        None => Some("killed by a signal (memory cap?)".into()),
    }
}

/// The surfaces fuzzed, with the share of the inputs each gets, in per mille.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Surface {
    Logs,
    Imu,
    Bag,
    Config,
    ThreeAxisConfig,
    Meridian,
    Partials,
    CommandLine,
}

const SURFACES: [(Surface, usize); 8] = [
    (Surface::Logs, 200),
    (Surface::Imu, 100),
    (Surface::Bag, 80),
    (Surface::Config, 200),
    (Surface::ThreeAxisConfig, 60),
    (Surface::Meridian, 10),
    (Surface::Partials, 160),
    (Surface::CommandLine, 190),
];

/// A finding: which input, what went wrong, and where its inputs are kept.
struct Finding {
    surface: Surface,
    case: usize,
    args: Vec<String>,
    what: String,
    known: Option<&'static str>,
}

/// Findings that belong to work done elsewhere at the same time, with the reason: a predicate
/// on (surface, arguments, what) and why it is not failed yet. Empty this list (or set
/// `ACCELCAL_FUZZ_STRICT=1`) once that work is merged.
type Known = (fn(Surface, &[String], &str) -> bool, &'static str);
const KNOWN: &[Known] = &[];

/// The shared inputs a worker mutates: the tiny configuration, its logs, two shard partials and
/// the one-process ensemble they must merge to.
struct Base {
    dir: PathBuf,
    accel: Vec<u8>,
    gps: Vec<u8>,
    /// The shipped three-axis recording cut to its first [`IMU_SECONDS`]: IMU and GNSS logs.
    imu: Vec<u8>,
    gnss: Vec<u8>,
    partials: [Vec<u8>; 2],
    one: serde_json::Value,
    /// A static IMU as MCAP files of ROS 2 `Imu` messages, chunked (with CRCs) and not, and as
    /// ROS 1 bags with plain, lz4 and bz2 chunks.
    bags: [Vec<u8>; 5],
    /// The three-axis files of `config --model ins` and `--model car`, sized to seconds.
    three_axis: [String; 2],
    /// The summary of the unmutated three-axis recording's calibration.
    imu_summary: serde_json::Value,
}

fn base(dir: &Path) -> Base {
    std::fs::write(dir.join("tiny.toml"), TINY).unwrap();
    let ok = |args: &[&str]| {
        let out = common::run_in(dir, args, Some(1));
        assert!(out.status.success(), "{args:?}: {out:?}");
    };
    ok(&["simulate", "-q", "--config", "tiny.toml", "--logs", "logs"]);
    for k in 1..=2 {
        let shard = format!("{k}/2");
        let file = format!("p{k}.bin");
        ok(&[
            "ensemble",
            "-q",
            "--config",
            "tiny.toml",
            "--realizations",
            "128",
            "--shard",
            &shard,
            "--partial",
            &file,
        ]);
    }
    ok(&[
        "ensemble",
        "-q",
        "--config",
        "tiny.toml",
        "--realizations",
        "128",
        "--json",
        "one.json",
    ]);
    let read = |p: &str| std::fs::read(dir.join(p)).unwrap();
    let (imu, gnss) = (first_seconds("imu.csv"), first_seconds("gnss.csv"));
    std::fs::write(dir.join("imu.csv"), &imu).unwrap();
    std::fs::write(dir.join("gnss.csv"), &gnss).unwrap();
    ok(&CALIBRATE_IMU);
    let summary = std::fs::read_to_string(dir.join("cal3/summary.json")).unwrap();
    Base {
        three_axis: ["ins", "car"].map(|m| three_axis::tiny_three_axis(dir, m)),
        imu_summary: serde_json::from_str(&summary).unwrap(),
        dir: dir.to_path_buf(),
        accel: read("logs/accelerometer.csv"),
        gps: read("logs/gps.csv"),
        imu,
        gnss,
        partials: [read("p1.bin"), read("p2.bin")],
        one: common::summary_without_timing(&dir.join("one.json")),
        bags: [
            "bag-true.mcap",
            "bag-false.mcap",
            "none.bag",
            "lz4.bag",
            "bz2.bag",
        ]
        .map(|name| {
            let path = dir.join(name);
            match name.strip_suffix(".bag") {
                Some(compression) => imu_ros1(&path, BAG_MESSAGES, compression),
                None => imu_mcap(&path, BAG_MESSAGES, name == "bag-true.mcap"),
            }
            let out = common::run_in(
                dir,
                &["allan", "-q", "--imu", path.to_str().unwrap()],
                Some(1),
            );
            assert!(out.status.success(), "the unmutated bag {name}: {out:?}");
            read(name)
        }),
    }
}

/// Messages in the bags the bag surface mutates: 30 s at 100 Hz.
const BAG_MESSAGES: usize = 3_000;

/// `sensor_msgs/msg/Imu` in CDR (little-endian): the stamp, a frame id, then the 37 doubles
/// (orientation, its covariance, angular velocity at 13–15, its covariance, linear
/// acceleration at 25–27, its covariance) at the 8-byte alignment after the 4-byte header.
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

/// Writes a static IMU of `messages` at 100 Hz to the MCAP file `path` (white noise about gravity).
fn imu_mcap(path: &Path, messages: usize, chunked: bool) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .use_chunks(chunked)
        .create(file)
        .unwrap();
    let schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
    let channel = w
        .add_channel(schema, "/imu", "cdr", &std::collections::BTreeMap::new())
        .unwrap();
    let mut rng = Rng::new(31);
    let mut noise = || {
        (0..12)
            .map(|_| rng.below(1 << 20) as f64 / f64::from(1 << 20))
            .sum::<f64>()
            - 6.0
    };
    for k in 0..messages {
        let t_ns = 1_700_000_000_000_000_000 + k as u64 * 10_000_000;
        let gyro = [1e-3 * noise(), 1e-3 * noise(), 1e-3 * noise()];
        let accel = [0.01 * noise(), 0.01 * noise(), 9.81 + 0.01 * noise()];
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: k as u32,
            log_time: t_ns,
            publish_time: t_ns,
        };
        w.write_to_known_channel(&header, &imu_cdr(t_ns, gyro, accel))
            .unwrap();
    }
    w.finish().unwrap();
}

/// Appends a ROS 1 bag record: its header's fields `name=value`, then its data.
fn record(out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]) {
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

/// A ROS 1 serialized `sensor_msgs/Imu`: header (seq, stamp, frame id), then the 37 doubles
/// with white noise about gravity in the angular velocity (13–15) and acceleration (25–27).
fn ros1_imu(rng: &mut Rng, seq: u32, sec: u32, nsec: u32) -> Vec<u8> {
    let mut noise = || {
        (0..12)
            .map(|_| rng.below(1 << 20) as f64 / f64::from(1 << 20))
            .sum::<f64>()
            - 6.0
    };
    let mut m = Vec::new();
    for w in [seq, sec, nsec, 8] {
        m.extend(w.to_le_bytes());
    }
    m.extend(b"imu_link");
    let mut values = [0.0; 37];
    values[3] = 1.0;
    for at in [13, 14, 15] {
        values[at] = 1e-3 * noise();
    }
    for at in [25, 26, 27] {
        values[at] = 0.01 * noise() + if at == 27 { 9.81 } else { 0.0 };
    }
    values.iter().for_each(|v| m.extend(v.to_le_bytes()));
    m
}

/// Writes a static IMU of `messages` at 100 Hz as a ROS 1 bag (format 2.0,
/// wiki.ros.org/Bags/Format/2.0) to `path`: the bag header without an index, then chunks of
/// 500 `sensor_msgs/Imu` messages (ROS 1 serialization) compressed with `compression` — none,
/// lz4 (LZ4 frames, as roslz4 writes) or bz2 —, each with the connection record first.
fn imu_ros1(path: &Path, messages: usize, compression: &str) {
    use std::io::Write as _;
    let mut bag = b"#ROSBAG V2.0\n".to_vec();
    let header = [
        ("op", &[3u8][..]),
        ("index_pos", &[0; 8]),
        ("conn_count", &[1, 0, 0, 0]),
        ("chunk_count", &[0; 4]),
    ];
    record(&mut bag, &header, &[b' '; 64]);
    let mut rng = Rng::new(37);
    let conn = 0u32.to_le_bytes();
    let mut kind = Vec::new();
    for f in [
        "type=sensor_msgs/Imu",
        "md5sum=6a62c6daae103f4ff57a132d6f95cec2",
    ] {
        kind.extend((f.len() as u32).to_le_bytes());
        kind.extend(f.as_bytes());
    }
    for first in (0..messages).step_by(500) {
        let mut chunk = Vec::new();
        record(
            &mut chunk,
            &[("op", &[7]), ("conn", &conn), ("topic", b"/imu")],
            &kind,
        );
        for k in first..(first + 500).min(messages) {
            let (sec, nsec) = (
                1_700_000_000 + (k / 100) as u32,
                (k % 100) as u32 * 10_000_000,
            );
            let m = ros1_imu(&mut rng, k as u32, sec, nsec);
            let time = (u64::from(sec) | u64::from(nsec) << 32).to_le_bytes();
            record(
                &mut chunk,
                &[("op", &[2]), ("conn", &conn), ("time", &time)],
                &m,
            );
        }
        let size = (chunk.len() as u32).to_le_bytes();
        let data = match compression {
            "lz4" => {
                let mut e = lz4::EncoderBuilder::new().build(Vec::new()).unwrap();
                e.write_all(&chunk).unwrap();
                e.finish().0
            }
            "bz2" => {
                let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
                e.write_all(&chunk).unwrap();
                e.finish().unwrap()
            }
            _ => chunk,
        };
        let fields = [
            ("op", &[5u8][..]),
            ("compression", compression.as_bytes()),
            ("size", &size),
        ];
        record(&mut bag, &fields, &data);
    }
    std::fs::write(path, bag).unwrap();
}

/// One bag case: an MCAP file or a ROS 1 bag with bytes flipped, overwritten, deleted,
/// duplicated or cut, through `allan --imu`.
fn case_bag(rng: &mut Rng, base: &Base, dir: &Path) -> (Vec<String>, Vec<&'static str>) {
    let which = rng.below(base.bags.len());
    let mut bag = base.bags[which].clone();
    for _ in 0..1 + rng.below(3) {
        let at = rng.below(bag.len());
        match rng.below(6) {
            0 => bag[at] ^= 1 << rng.below(8),
            1 => bag[at] = *rng.pick(&[0u8, 0xff, 0x7f, 0x80, 0x01]),
            2 => {
                let end = (at + 1 + rng.below(64)).min(bag.len());
                bag.drain(at..end);
            }
            3 => bag.truncate(at),
            4 => {
                let end = (at + 1 + rng.below(400)).min(bag.len());
                let copy = bag[at..end].to_vec();
                bag.splice(at..at, copy);
            }
            _ => {
                // A double of a message set to NaN, ±∞ or a huge value.
                let v = *rng.pick(&[f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300, -0.0]);
                let end = (at + 8).min(bag.len());
                let bytes = v.to_le_bytes();
                bag[at..end].copy_from_slice(&bytes[..end - at]);
            }
        }
    }
    let name = if which < 2 { "imu.mcap" } else { "imu.bag" };
    std::fs::write(dir.join(name), bag).unwrap();
    let args = ["allan", "-q", "--imu", name, "--out", "allan3"]
        .map(String::from)
        .to_vec();
    (
        args,
        vec!["allan3/allan.json", "allan3/imu.yaml", "allan3/noise.toml"],
    )
}

/// The length of the three-axis recording the IMU surface mutates, s: 400 IMU rows and 40
/// fixes, the vehicle already above the heading's speed, so that the unmutated run calibrates
/// (exit 0) in a few hundredths of a second.
const IMU_SECONDS: f64 = 4.0;

/// The shipped comma2k19 three-axis log `name` with its rows up to [`IMU_SECONDS`].
fn first_seconds(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19_3d")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        let t: f64 = line.split(',').next().unwrap().parse().unwrap_or(0.0);
        if k == 0 || t <= IMU_SECONDS {
            out += line;
            out.push('\n');
        }
    }
    out.into_bytes()
}

/// A sentinel in each output a failing run must not touch.
const SENTINEL: &[u8] = b"sentinel: a failing run must leave this file as it was\n";

fn plant(dir: &Path, outputs: &[&str]) {
    for o in outputs {
        let p = dir.join(o);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(p, SENTINEL).unwrap();
    }
}

/// The outputs of `outputs` a failing run changed.
fn clobbered(dir: &Path, outputs: &[&str]) -> Vec<String> {
    outputs
        .iter()
        .filter(|o| std::fs::read(dir.join(o)).ok().as_deref() != Some(SENTINEL))
        .map(|o| o.to_string())
        .collect()
}

/// One log-reader case: the tiny logs with one or both mutated, through `calibrate`.
fn case_logs(rng: &mut Rng, base: &Base, dir: &Path) -> (Vec<String>, Vec<&'static str>) {
    let mut accel = base.accel.clone();
    let mut gps = base.gps.clone();
    let mutations = if rng.chance(60) { 1 } else { 2 + rng.below(2) };
    for _ in 0..mutations {
        let target = if rng.chance(55) { &mut accel } else { &mut gps };
        if rng.chance(50) {
            mutate_bytes(rng, target);
        } else {
            mutate_field(rng, target);
        }
    }
    std::fs::write(dir.join("a.csv"), accel).unwrap();
    std::fs::write(dir.join("g.csv"), gps).unwrap();
    let args = [
        "calibrate",
        "-q",
        "--config",
        "../tiny.toml",
        "--accel",
        "a.csv",
    ];
    let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    args.extend(["--gps", "g.csv", "--out", "cal"].map(String::from));
    (args, vec!["cal/summary.json"])
}

/// One three-axis case: the 4 s recording with one or both logs mutated (the generic mutations,
/// a hostile field, or a change of layout: the rates' header renamed to increments, one column
/// renamed, dropped or added, rows swapped), the IMU log sometimes gzipped, sometimes with a
/// small configuration naming the axes, through `calibrate --imu --gnss`.
fn case_imu(rng: &mut Rng, base: &Base, dir: &Path) -> (Vec<String>, Vec<&'static str>) {
    let mut imu = base.imu.clone();
    let mut gnss = base.gnss.clone();
    let mutations = if rng.chance(60) { 1 } else { 2 + rng.below(2) };
    for _ in 0..mutations {
        let target = if rng.chance(55) { &mut imu } else { &mut gnss };
        match rng.below(5) {
            0 | 1 => mutate_bytes(rng, target),
            2 | 3 => mutate_field(rng, target),
            _ => mutate_layout(rng, target),
        }
    }
    let gzipped = rng.chance(10);
    if gzipped {
        use std::io::Write as _;
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(&imu).unwrap();
        imu = gz.finish().unwrap();
    }
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("gnss.csv"), gnss).unwrap();
    let mut args: Vec<String> = ["calibrate", "-q", "--imu", "imu.csv", "--gnss", "gnss.csv"]
        .map(String::from)
        .to_vec();
    if rng.chance(15) {
        let axes = rng.pick(&["\"frd\"", "\"flu\"", "\"xyz\"", "1"]);
        let config = format!("model = \"ins\"\n[imu]\naxes = {axes}\n");
        std::fs::write(dir.join("imu.toml"), config).unwrap();
        args.extend(["--config", "imu.toml"].map(String::from));
    }
    args.extend(["--out", "cal3"].map(String::from));
    (args, vec!["cal3/summary.json", "cal3/estimates.csv"])
}

/// The calibration of the three-axis recording `imu.csv`, `gnss.csv` into `cal3`.
const CALIBRATE_IMU: [&str; 8] = [
    "calibrate",
    "-q",
    "--imu",
    "imu.csv",
    "--gnss",
    "gnss.csv",
    "--out",
    "cal3",
];

/// One meridian case: the unmutated recording with its longitudes written another way.
fn case_meridian(rng: &mut Rng, base: &Base, dir: &Path) -> (Vec<String>, Vec<&'static str>) {
    std::fs::write(dir.join("imu.csv"), &base.imu).unwrap();
    let gnss = three_axis::same_meridians(rng, &base.gnss);
    std::fs::write(dir.join("gnss.csv"), gnss).unwrap();
    (
        CALIBRATE_IMU.map(String::from).to_vec(),
        vec!["cal3/summary.json", "cal3/estimates.csv"],
    )
}

/// A change of a log's layout: its header's rate columns renamed to increments (a valid
/// layout whose numbers are now wrong by the step), one column renamed to another of either
/// layout, a column dropped or added on every line, or two rows swapped.
fn mutate_layout(rng: &mut Rng, text: &mut Vec<u8>) {
    let s = String::from_utf8_lossy(text).into_owned();
    let mut lines: Vec<String> = s.lines().map(String::from).collect();
    if lines.len() < 3 {
        return;
    }
    const NAMES: &[&str] = &[
        "t_s",
        "ax_m_s2",
        "gz_rad_s",
        "dvx_m_s",
        "dthz_rad",
        "lat_deg",
        "vd_m_s",
        "sigma_n_m",
        "sigma_vn_m_s",
        "",
    ];
    match rng.below(5) {
        0 => {
            lines[0] = lines[0]
                .replace("ax_m_s2", "dvx_m_s")
                .replace("ay_m_s2", "dvy_m_s")
                .replace("az_m_s2", "dvz_m_s")
                .replace("gx_rad_s", "dthx_rad")
                .replace("gy_rad_s", "dthy_rad")
                .replace("gz_rad_s", "dthz_rad");
        }
        1 => {
            let mut cols: Vec<&str> = lines[0].split(',').collect();
            let c = rng.below(cols.len());
            cols[c] = *rng.pick(NAMES);
            lines[0] = cols.join(",");
        }
        2 => {
            let c = rng.below(lines[0].split(',').count());
            for l in &mut lines {
                let mut f: Vec<&str> = l.split(',').collect();
                if c < f.len() {
                    f.remove(c);
                }
                *l = f.join(",");
            }
        }
        3 => {
            let name = rng.pick(NAMES).to_string();
            lines[0] += &format!(",{name}");
            for l in lines.iter_mut().skip(1) {
                *l += ",1.0";
            }
        }
        _ => {
            let (i, j) = (
                1 + rng.below(lines.len() - 1),
                1 + rng.below(lines.len() - 1),
            );
            lines.swap(i, j);
        }
    }
    *text = (lines.join("\n") + "\n").into_bytes();
}

/// One comma-separated field of a log replaced by a hostile value.
fn mutate_field(rng: &mut Rng, text: &mut Vec<u8>) {
    let s = String::from_utf8_lossy(text).into_owned();
    let mut lines: Vec<String> = s.lines().map(String::from).collect();
    if lines.is_empty() {
        return;
    }
    let i = rng.below(lines.len());
    let mut fields: Vec<String> = lines[i].split(',').map(String::from).collect();
    let f = rng.below(fields.len());
    fields[f] = value(rng);
    lines[i] = fields.join(",");
    *text = (lines.join("\n") + "\n").into_bytes();
}

/// One configuration case, through one of the commands that read a configuration.
fn case_config(
    rng: &mut Rng,
    dir: &Path,
    reports: &Mutex<usize>,
) -> (Vec<String>, Vec<&'static str>) {
    std::fs::write(dir.join("c.toml"), fuzz_config(rng)).unwrap();
    let with = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    // A report simulates 100 static logs whatever its size: a few of them only.
    let report = rng.chance(2) && {
        let mut n = reports.lock().unwrap();
        *n += 1;
        *n <= 8
    };
    if report {
        return (
            with(&["report", "-q", "--config", "c.toml", "--out", "rep"]),
            vec!["rep/index.html"],
        );
    }
    match rng.below(10) {
        0..=5 => (
            with(&["ensemble", "-q", "--config", "c.toml", "--json", "e.json"]),
            vec!["e.json"],
        ),
        6..=8 => (
            with(&["simulate", "-q", "--config", "c.toml", "--csv", "s.csv"]),
            vec!["s.csv"],
        ),
        _ => (
            with(&[
                "sensitivity",
                "-q",
                "--config",
                "c.toml",
                "--json",
                "x.json",
            ]),
            vec!["x.json"],
        ),
    }
}

/// One merge case: the two partials, one or both damaged, reordered or repeated.
fn case_partials(rng: &mut Rng, base: &Base, dir: &Path) -> (Vec<String>, Vec<&'static str>) {
    let mut files = base.partials.clone();
    for _ in 0..1 + rng.below(2) {
        let f = &mut files[rng.below(2)];
        if rng.chance(30) {
            // A number of the JSON header edited.
            let s = String::from_utf8_lossy(f).into_owned();
            let digits: Vec<usize> = s
                .char_indices()
                .take_while(|&(i, _)| i < s.find('\n').unwrap_or(0) + 2000)
                .filter(|(_, c)| c.is_ascii_digit())
                .map(|(i, _)| i)
                .collect();
            if let Some(&at) = digits.get(rng.below(digits.len().max(1))) {
                f[at] = b'0' + rng.below(10) as u8;
            }
        } else {
            mutate_bytes(rng, f);
        }
    }
    std::fs::write(dir.join("q1.bin"), &files[0]).unwrap();
    std::fs::write(dir.join("q2.bin"), &files[1]).unwrap();
    const ORDERS: [&[&str]; 5] = [
        &["q1.bin", "q2.bin"],
        &["q2.bin", "q1.bin"],
        &["q1.bin", "q1.bin"],
        &["q1.bin"],
        &["q1.bin", "q2.bin", "q2.bin"],
    ];
    let order = *rng.pick(&ORDERS);
    let mut args: Vec<String> = vec!["merge".into(), "-q".into()];
    args.extend(order.iter().map(|s| s.to_string()));
    args.extend(["--json".into(), "m.json".into()]);
    (args, vec!["m.json"])
}

/// Subcommands, options and values of the command lines.
const SUB: &[&str] = &[
    "ensemble",
    "simulate",
    "merge",
    "sensitivity",
    "calibrate",
    "allan",
    "config",
    "bogus",
    "report",
    "--version",
    "--help",
    "-h",
    "",
];
const FLAGS: &[&str] = &[
    "--config",
    "--seed",
    "--quiet",
    "-q",
    "--realizations",
    "--truth",
    "--accelerometer-output",
    "--json",
    "--shard",
    "--partial",
    "--engine",
    "--csv",
    "--logs",
    "--realization",
    "--factors",
    "--parameters",
    "--ensembles",
    "--draws",
    "--accel",
    "--gps",
    "--imu",
    "--gnss",
    "--out",
    "--column",
    "--confidence",
    "--help",
    "--bogus",
    "-x",
    "--",
];
const VALUES: &[&str] = &[
    "../tiny.toml",
    "tiny.toml",
    "/dev/null",
    "/dev/zero",
    "..",
    "",
    "-",
    "1/2",
    "2/1",
    "0/0",
    "1/0",
    "3",
    "0",
    "-1",
    "1e9",
    "18446744073709551616",
    "euler",
    "analytic",
    "epoch",
    "sample",
    "interval_mean",
    "accel_noise_var_m2_s4",
    "nope",
    "0.5,2",
    "nan",
    "1.5",
    "../logs/accelerometer.csv",
    "../logs/gps.csv",
    "imu.csv",
    "gnss.csv",
    concat!(env!("CARGO_MANIFEST_DIR"), "/examples/comma2k19_3d/imu.csv"),
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/comma2k19_3d/gnss.csv"
    ),
    "../p1.bin",
    "out.json",
    "out/dir",
    "\u{feff}",
    "é",
    "accel_m_s2",
    "0.683",
    "2",
    "7",
];

/// One command line: a subcommand and a few options with hostile or plain values.
fn case_command_line(rng: &mut Rng) -> (Vec<String>, Vec<&'static str>) {
    let sub = *rng.pick(SUB);
    let mut args: Vec<String> = vec![sub.to_string()];
    for _ in 0..rng.below(6) {
        args.push(rng.pick(FLAGS).to_string());
        if rng.chance(75) {
            args.push(rng.pick(VALUES).to_string());
        }
    }
    // Commands that run the model run the tiny one, so that a valid line ends quickly; a
    // report (100 static logs whatever its size) only when it is refused before it starts.
    if matches!(sub, "ensemble" | "simulate" | "sensitivity" | "report" | "") {
        args.extend(["--config".into(), "../tiny.toml".into()]);
    }
    if matches!(sub, "report" | "") {
        args.extend(["--realizations".into(), "0".into()]);
    }
    if sub.is_empty() {
        args.remove(0);
    }
    (args, vec!["out.json"])
}

/// What the runs ended with, per surface and command: (exit 0, exit 2, other); and the reports
/// run so far.
#[derive(Default)]
struct Tally {
    ends: Mutex<std::collections::BTreeMap<String, [usize; 3]>>,
    reports: Mutex<usize>,
}

impl Tally {
    fn count(&self, surface: Surface, args: &[String], code: Option<i32>) {
        let command = args.first().map_or("", String::as_str);
        let key = format!("{surface:?} {command}");
        let slot = match code {
            Some(0) => 0,
            Some(2) => 1,
            _ => 2,
        };
        self.ends.lock().unwrap().entry(key).or_default()[slot] += 1;
    }

    fn table(&self) -> String {
        let mut t = String::from("  surface and command: exit 0, exit 2, other\n");
        for (k, [ok, refused, other]) in self.ends.lock().unwrap().iter() {
            let _ = writeln!(t, "    {k}: {ok}, {refused}, {other}");
        }
        t
    }
}

/// Runs case `case` of `surface` in `dir` and returns what is wrong with it, if anything.
fn run_case(
    surface: Surface,
    case: usize,
    base: &Base,
    dir: &Path,
    tally: &Tally,
) -> Option<Finding> {
    let seed = env_u64("ACCELCAL_FUZZ_SEED", 22) ^ ((surface as u64) << 48) ^ case as u64;
    let rng = &mut Rng::new(seed);
    let (args, outputs) = match surface {
        Surface::Logs => case_logs(rng, base, dir),
        Surface::Imu => case_imu(rng, base, dir),
        Surface::Bag => case_bag(rng, base, dir),
        Surface::Config => case_config(rng, dir, &tally.reports),
        Surface::ThreeAxisConfig => three_axis::case_three_axis_config(rng, &base.three_axis, dir),
        Surface::Meridian => case_meridian(rng, base, dir),
        Surface::Partials => case_partials(rng, base, dir),
        Surface::CommandLine => case_command_line(rng),
    };
    plant(dir, &outputs);
    let ended = run_capped(dir, &args, which_prlimit());
    tally.count(surface, &args, ended.code);
    let mut what = fault(&ended);
    if what.is_none() && ended.code != Some(0) {
        let changed = clobbered(dir, &outputs);
        if !changed.is_empty() {
            what = Some(format!("a failing run changed {changed:?}"));
        }
    }
    if what.is_none() && surface == Surface::Meridian {
        let summary = std::fs::read_to_string(dir.join("cal3/summary.json")).unwrap_or_default();
        let d = serde_json::from_str(&summary).map_or(f64::INFINITY, |s| {
            three_axis::bias_difference(&s, &base.imu_summary)
        });
        // The same drive: the same biases but for the longitudes' rounding (10⁻¹⁰°, 10 µm).
        if ended.code != Some(0) || d.is_nan() || d >= 1e-6 {
            what = Some(format!(
                "the same meridians calibrate otherwise (biases {d:.1e} apart)"
            ));
        }
    }
    if what.is_none() && surface == Surface::Partials && ended.code == Some(0) {
        let merged = common::summary_without_timing(&dir.join("m.json"));
        if merged != base.one {
            what = Some("merge exit 0 with numbers unlike the one-process run".into());
        }
    }
    let what = what?;
    let what = format!("{what}: {}", ended.stderr.lines().last().unwrap_or(""));
    let known = KNOWN
        .iter()
        .find(|(matches, _)| matches(surface, &args, &what))
        .map(|(_, why)| *why);
    keep(surface, case, dir);
    Some(Finding {
        surface,
        case,
        args,
        what,
        known,
    })
}

/// Copies the inputs of a finding to the target directory, to reproduce it by hand.
fn keep(surface: Surface, case: usize, dir: &Path) {
    let to = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz/{surface:?}-{case}"));
    let _ = std::fs::create_dir_all(&to);
    for f in [
        "a.csv", "g.csv", "imu.csv", "gnss.csv", "imu.toml", "c.toml", "q1.bin", "q2.bin",
    ] {
        let _ = std::fs::copy(dir.join(f), to.join(f));
    }
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn which_prlimit() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| {
        Command::new("prlimit")
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    })
}

#[test]
fn thousands_of_hostile_inputs_end_in_0_or_2_and_clobber_nothing() {
    let total = env_u64("ACCELCAL_FUZZ_CASES", 5_000) as usize;
    let root = tempfile::tempdir().unwrap();
    let base = base(root.path());
    let jobs: Vec<(Surface, usize)> = SURFACES
        .iter()
        .flat_map(|&(s, per_mille)| (0..total * per_mille / 1000).map(move |i| (s, i)))
        .collect();
    let findings = Mutex::new(Vec::new());
    let tally = Tally::default();
    let start = Instant::now();
    let workers = 2;
    std::thread::scope(|scope| {
        for w in 0..workers {
            let (jobs, base, findings, tally) = (&jobs, &base, &findings, &tally);
            scope.spawn(move || {
                let dir = base.dir.join(format!("w{w}"));
                std::fs::create_dir_all(&dir).unwrap();
                for &(surface, case) in jobs.iter().skip(w).step_by(workers) {
                    if let Some(f) = run_case(surface, case, base, &dir, tally) {
                        findings.lock().unwrap().push(f);
                    }
                }
            });
        }
    });
    let findings = findings.into_inner().unwrap();
    let strict = std::env::var("ACCELCAL_FUZZ_STRICT").is_ok_and(|v| v == "1");
    let mut text = format!(
        "{} inputs in {:.0} s ({} with prlimit's {} GiB cap); {} findings\n",
        jobs.len(),
        start.elapsed().as_secs_f64(),
        if which_prlimit() { "each" } else { "none" },
        MEMORY_CAP >> 30,
        findings.len()
    ) + &tally.table();
    for f in &findings {
        let tag = f.known.map_or("NEW".to_string(), |k| format!("known: {k}"));
        let _ = writeln!(
            text,
            "  {:?} case {} [{tag}]: {}\n    accelcal {}",
            f.surface,
            f.case,
            f.what,
            f.args.join(" ")
        );
    }
    let log = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz/findings.txt");
    let _ = std::fs::create_dir_all(log.parent().unwrap());
    let _ = std::fs::write(&log, &text);
    eprintln!("{text}(also in {})", log.display());
    let failing = findings
        .iter()
        .filter(|f| strict || f.known.is_none())
        .count();
    assert_eq!(failing, 0, "{text}");
    // The three-axis surface reaches both ends: some mutated recordings still calibrate, most
    // are refused (a surface whose every input is refused at the header tests one line).
    let ends = tally.ends.lock().unwrap();
    let [ok, refused, _] = ends.get("Imu calibrate").copied().unwrap_or_default();
    assert!(
        ok > 0 && refused > 0,
        "the IMU surface: {ok} exit 0, {refused} exit 2"
    );
    drop(ends);
    assert!(
        jobs.len() >= total * 99 / 100,
        "every share of the inputs ran"
    );
}

#[test]
fn the_judge_fails_what_it_must() {
    let ended = |code, hung, stderr: &str| Ended {
        code,
        hung,
        limit: LIMIT,
        stderr: stderr.to_string(),
    };
    // A report gets its own, longer limit; every other command the short one.
    let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(limit_of(&args(&["report", "-q"])), REPORT_LIMIT);
    assert_eq!(limit_of(&args(&["ensemble", "-q"])), LIMIT);
    assert!(fault(&ended(Some(0), false, "")).is_none());
    assert!(fault(&ended(Some(2), false, "error: bad")).is_none());
    assert!(fault(&ended(Some(101), false, "")).is_some());
    assert!(fault(&ended(Some(2), false, "thread 'main' panicked at")).is_some());
    assert!(fault(&ended(Some(1), false, "error: x")).is_some());
    assert!(fault(&ended(None, true, "")).is_some());
    assert!(
        fault(&ended(None, false, "")).is_some(),
        "killed by a signal"
    );
    // A changed sentinel is seen, an untouched one is not.
    let dir = tempfile::tempdir().unwrap();
    plant(dir.path(), &["a/out.json", "b.csv"]);
    assert!(clobbered(dir.path(), &["a/out.json", "b.csv"]).is_empty());
    std::fs::write(dir.path().join("b.csv"), "changed").unwrap();
    assert_eq!(clobbered(dir.path(), &["a/out.json", "b.csv"]), ["b.csv"]);
    // Keys are set in their table, or their table is added.
    let text = set_key(TINY, "ensemble", "realizations", "99");
    assert!(text.contains("realizations = 99\n") && !text.contains("realizations = 12"));
    assert!(
        set_key(TINY, "checks", "false_alarm_rate", "0.1")
            .ends_with("[checks]\nfalse_alarm_rate = 0.1\n")
    );
}
