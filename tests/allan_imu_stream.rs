//! `allan --imu` read as a stream or held: the accumulator against the whole-series estimator,
//! the command's file and pipe paths (streamed and held) against the one-column form (the log
//! held whole), the peak memory of a CSV file, a pipe and a ROS 1 bag four times longer, and
//! the bound `--memory` sets.

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use accelcal::allan::deviation::{mean, octave_factors, overlapping_avars, phase};
use accelcal::allan::noise_id::{block_means, identify};
use accelcal::allan::simulate::StaticLog;
use accelcal::allan::stream::{AllanStream, EXACT_MAX_M};
use accelcal::input::csv::text::{header, push_row};
use serde_json::Value;

const TAU0_S: f64 = 0.01;

fn log() -> StaticLog {
    StaticLog {
        sample_period_s: TAU0_S,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-3,
        offset_m_s2: -9.80665,
    }
}

/// Samples with the octave τ m = 2^19 beyond the exact ones (2m < n).
const LONG: usize = (1 << 20) + 50_000;

/// The stream fed in pieces of uneven size, its long τ's phase in a temporary directory.
fn streamed(y: &[f64], mean_y: f64) -> Vec<(usize, f64, Option<accelcal::allan::NoiseId>)> {
    let dir = tempfile::tempdir().unwrap();
    let mut s = AllanStream::new(mean_y, y.len(), dir.path()).unwrap();
    let sizes = [1usize, 7, 1000, 65_537, 3, 250_000];
    let mut at = 0;
    for k in 0.. {
        if at == y.len() {
            break;
        }
        let end = (at + sizes[k % sizes.len()]).min(y.len());
        s.extend(&y[at..end]);
        at = end;
    }
    let grid = s.finish().unwrap();
    // The phase's file is unlinked from its creation: nothing is left in the directory.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    grid
}

/// Every τ, within the window and beyond it (summed from the phase on disk), has the
/// whole-series estimator's bits and its noise. A stream given another mean is not
/// bit-identical (the check can fail) but agrees to 10⁻⁹; a stream told fewer samples than it
/// gets refuses the τ it kept no phase for.
#[test]
fn the_stream_is_the_whole_series_estimator() {
    let y = log().samples(LONG, 1);
    let x = phase(&y);
    let factors = octave_factors(y.len());
    let whole = overlapping_avars(&x, &factors);
    let got = streamed(&y, mean(&y));
    assert_eq!(got.len(), factors.len());
    let mut long = 0;
    for ((m, avar, noise), (&m_whole, &exact)) in got.iter().zip(factors.iter().zip(&whole)) {
        assert_eq!(*m, m_whole);
        assert_eq!(
            noise.map(|n| n.alpha),
            identify(&block_means(&x, *m)).map(|n| n.alpha),
            "m = {m}"
        );
        assert_eq!(
            avar.to_bits(),
            exact.to_bits(),
            "m = {m}: {avar} vs {exact}"
        );
        long += usize::from(*m > EXACT_MAX_M);
    }
    assert_eq!(long, 1);
    let off = streamed(&y, mean(&y) + 1e-3);
    assert!(off.iter().zip(&got).any(|(a, b)| a.1 != b.1));
    for (a, b) in off.iter().zip(&got) {
        assert!((a.1 / b.1 - 1.0).abs() < 1e-9, "m = {}", a.0);
    }
    let dir = tempfile::tempdir().unwrap();
    let mut short = AllanStream::new(mean(&y), 1 << 20, dir.path()).unwrap();
    short.extend(&y);
    assert!(short.finish().is_err());
}

/// A one-channel log's text, `rows` rows.
fn csv(rows: usize, seed: u64) -> String {
    let y = log().samples(rows, seed);
    let mut text = header(&["t_s", "az_m_s2"]);
    for (i, v) in y.iter().enumerate() {
        push_row(&mut text, &[i as f64 * TAU0_S, *v]);
    }
    text
}

/// Runs `allan --imu path` streamed (`--memory 0`: the log held nowhere), polling the child's
/// VmHWM: its allan.json and peak RSS, bytes.
fn run(path: &Path, stdin: Option<&[u8]>, out: &Path) -> (Value, u64) {
    run_with(&["--memory", "0", "--imu"], path, stdin, out)
}

/// Runs `allan FLAG… path`, polling the child's VmHWM: its allan.json and peak RSS, bytes.
fn run_with(flags: &[&str], path: &Path, stdin: Option<&[u8]>, out: &Path) -> (Value, u64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .arg("allan")
        .args(flags)
        .arg(path)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .stdout(Stdio::null())
        .stdin(if stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .spawn()
        .unwrap();
    if let Some(bytes) = stdin {
        let mut pipe = child.stdin.take().unwrap();
        let bytes = bytes.to_vec();
        std::thread::spawn(move || pipe.write_all(&bytes).unwrap());
    }
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak_kb = 0u64;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        // VmHWM only grows: the last reading before the exit is the peak but for the last
        // few milliseconds, in which the command writes its files.
        if let Some(kb) = std::fs::read_to_string(&status_file).ok().and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        }) {
            peak_kb = peak_kb.max(kb);
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    assert!(
        status.success(),
        "allan {flags:?} {} failed",
        path.display()
    );
    let json = std::fs::read_to_string(out.join("allan.json")).unwrap();
    (serde_json::from_str(&json).unwrap(), peak_kb * 1024)
}

/// The file streamed (read twice), the same bytes on a pipe (copied once, then streamed) and
/// the file held (read once, the default for a log of this length) give the same allan.json,
/// and its channel is the one-column form's (the log held whole, the deviation in memory), the
/// τ beyond the window included: every number bit for bit.
#[test]
fn a_long_file_streamed_equals_the_log_held_whole() {
    let dir = tempfile::tempdir().unwrap();
    let text = csv(LONG, 2);
    let file = dir.path().join("imu.csv");
    std::fs::write(&file, &text).unwrap();
    let (streamed, _) = run(&file, None, &dir.path().join("file"));
    let (held, _) = run_with(&["--imu"], &file, None, &dir.path().join("held"));
    assert_eq!(streamed, held);
    let (piped, _) = run(
        Path::new("/dev/stdin"),
        Some(text.as_bytes()),
        &dir.path().join("pipe"),
    );
    let accel = ["--column", "az_m_s2", "--accel"];
    let (whole, _) = run_with(&accel, &file, None, &dir.path().join("whole"));
    let taus: Vec<f64> =
        serde_json::from_value(streamed["channels"]["az_m_s2"]["tau_s"].clone()).unwrap();
    let last = (taus[taus.len() - 1] / TAU0_S).round() as usize;
    assert_eq!(last, 2 * EXACT_MAX_M);
    assert_eq!(streamed, piped);
    // serde_json compares numbers as f64 with ==: bit for bit for every finite number.
    assert_eq!(streamed["channels"]["az_m_s2"], whole);
}

/// Writes a ROS 1 bag (format 2.0) of `rows` `sensor_msgs/Imu` messages at 100 Hz to `path`
/// (wiki.ros.org/Bags/Format/2.0): the bag header (no index: the reader scans for the
/// topics), then chunks of 4 096 messages, plain, each with the connection record first.
fn ros1_bag(path: &Path, rows: usize, seed: u64) {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let record = |out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]| {
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
    };
    // Gyro x, y, z then accelerometer x, y, z: the message's float64 13–15 and 25–27.
    let y: Vec<Vec<f64>> = (0..6).map(|c| log().samples(rows, seed + c)).collect();
    let mut bag = b"#ROSBAG V2.0\n".to_vec();
    let zero = 0u64.to_le_bytes();
    let op = |k: u8| [k];
    record(
        &mut bag,
        &[
            ("op", &op(3)),
            ("index_pos", &zero),
            ("conn_count", &[1, 0, 0, 0]),
            ("chunk_count", &[0; 4]),
        ],
        &[b' '; 64],
    );
    let conn = 0u32.to_le_bytes();
    let connection = |chunk: &mut Vec<u8>| {
        let mut data = Vec::new();
        for f in [
            "type=sensor_msgs/Imu",
            "md5sum=6a62c6daae103f4ff57a132d6f95cec2",
        ] {
            data.extend((f.len() as u32).to_le_bytes());
            data.extend(f.as_bytes());
        }
        record(
            chunk,
            &[("op", &op(7)), ("conn", &conn), ("topic", b"/imu")],
            &data,
        );
    };
    for c in 0..rows.div_ceil(4096) {
        let mut chunk = Vec::new();
        connection(&mut chunk);
        for i in c * 4096..((c + 1) * 4096).min(rows) {
            let (sec, nsec) = ((i / 100) as u32, ((i % 100) * 10_000_000) as u32);
            let mut m = Vec::with_capacity(16 + 37 * 8);
            for w in [i as u32, sec, nsec, 0] {
                m.extend(w.to_le_bytes());
            }
            let mut f = [0.0f64; 37];
            f[3] = 1.0;
            for (at, channel) in [13, 14, 15, 25, 26, 27].into_iter().zip(&y) {
                f[at] = channel[i];
            }
            for x in f {
                m.extend(x.to_le_bytes());
            }
            let time = (u64::from(sec) | (u64::from(nsec) << 32)).to_le_bytes();
            record(
                &mut chunk,
                &[("op", &op(2)), ("conn", &conn), ("time", &time)],
                &m,
            );
        }
        let size = (chunk.len() as u32).to_le_bytes();
        record(
            &mut bag,
            &[("op", &op(5)), ("compression", b"none"), ("size", &size)],
            &chunk,
        );
        file.write_all(&bag).unwrap();
        bag.clear();
    }
    file.flush().unwrap();
}

/// `--memory` is the bound of what a log held takes: the 1.1·10⁶-row one-channel file (24
/// bytes a row held: 25 MB) held by default peaks above those 25 MB (the control: a log held is
/// seen; its streamed run peaks at 17 MB), and with `--memory 8` its peak stays below them and
/// within the 8 MB it may hold and 4 MB of spread of the streamed run's (measured: 17.4 MB
/// streamed, 21.4 MB with `--memory 8`, 34.4 MB held).
fn budget_is_kept(file: &Path, streamed_peak: u64, dir: &Path) {
    let (_, held_peak) = run_with(&["--imu"], file, None, &dir.join("held"));
    let (_, capped_peak) = run_with(&["--memory", "8", "--imu"], file, None, &dir.join("cap"));
    eprintln!("held {held_peak} B, --memory 8 {capped_peak} B, streamed {streamed_peak} B");
    let log_bytes = 24 * LONG as u64;
    assert!(
        held_peak > log_bytes,
        "held {held_peak} B: the log takes {log_bytes} B"
    );
    assert!(
        capped_peak < log_bytes && capped_peak < streamed_peak + (12 << 20),
        "--memory 8: {capped_peak} B, streamed {streamed_peak} B, the log {log_bytes} B"
    );
}

/// Peak memory does not follow the log's length, streamed (`--memory 0`): from 1.1·10⁶ to
/// 4.4·10⁶ rows a CSV file, the same bytes on a pipe (copied once to a temporary file, read twice from it) and a ROS 1 bag of as
/// many messages (six channels, read a chunk at a time; 0.39 and 1.56 GB on disk for the test's
/// time) each grow by less than a quarter of the 79 MB that holding one channel's samples and
/// their stamps (16 bytes a row) and its phase (8) would add: 20 MB, above the bag's run-to-run
/// spread (its peak at the shorter length measured 56.0 and 63.2 MB in two runs of one build).
/// The negative control, the one-column form on the same pipe (it holds the log), grows by more
/// than the 79 MB: the measurement sees a log held whole.
#[test]
fn peak_memory_does_not_follow_the_length() {
    let dir = tempfile::tempdir().unwrap();
    let mut peaks = Vec::new();
    // Both lengths have τ beyond the window (their phase on disk): the same regime, 4× apart.
    for (k, rows) in [LONG, 4 * LONG].into_iter().enumerate() {
        let text = csv(rows, 3 + k as u64);
        let file = dir.path().join(format!("imu{rows}.csv"));
        std::fs::write(&file, &text).unwrap();
        let (_, file_peak) = run(&file, None, &dir.path().join(format!("f{rows}")));
        if k == 0 {
            budget_is_kept(&file, file_peak, dir.path());
        }
        let stdin = Path::new("/dev/stdin");
        let out = dir.path().join(format!("p{rows}"));
        let (_, pipe_peak) = run(stdin, Some(text.as_bytes()), &out);
        let out = dir.path().join(format!("a{rows}"));
        let accel = ["--column", "az_m_s2", "--accel"];
        let (_, whole_peak) = run_with(&accel, stdin, Some(text.as_bytes()), &out);
        std::fs::remove_file(&file).unwrap();
        let bag = dir.path().join(format!("imu{rows}.bag"));
        ros1_bag(&bag, rows, 5 + k as u64);
        let (_, bag_peak) = run(&bag, None, &dir.path().join(format!("b{rows}")));
        std::fs::remove_file(&bag).unwrap();
        eprintln!(
            "{rows} rows: file {file_peak} B, pipe {pipe_peak} B, one-column pipe {whole_peak} B; \
             ROS 1 bag {bag_peak} B"
        );
        peaks.push([file_peak, pipe_peak, bag_peak, whole_peak]);
    }
    let held = 3.0 * LONG as f64 * 24.0;
    for (j, what) in ["file", "pipe", "ROS 1 bag"].into_iter().enumerate() {
        let grown = peaks[1][j] as f64 - peaks[0][j] as f64;
        assert!(
            grown < held / 4.0,
            "the {what}'s peak grew by {grown} B: {peaks:?}"
        );
    }
    assert!(
        peaks[1][3] as f64 - peaks[0][3] as f64 > held,
        "the one-column form on a pipe should grow by at least {held} B: {peaks:?}"
    );
}
