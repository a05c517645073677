//! `allan --imu` read as a stream: the accumulator against the whole-series estimator, the
//! command's file path (streamed) against its pipe path (read whole), and the peak memory of
//! a log four times longer.

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use accelcal::allan::deviation::{mean, octave_factors, overlapping_avars, phase};
use accelcal::allan::noise_id::{block_means, identify};
use accelcal::allan::simulate::StaticLog;
use accelcal::allan::stream::{AllanStream, EXACT_MAX_M};
use accelcal::logs::write::{header, push_row};
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

/// Runs `allan --imu path`, polling the child's VmHWM: its allan.json and peak RSS, bytes.
fn run(path: &Path, stdin: Option<&[u8]>, out: &Path) -> (Value, u64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .args(["allan", "--imu"])
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
    assert!(status.success(), "allan --imu {} failed", path.display());
    let json = std::fs::read_to_string(out.join("allan.json")).unwrap();
    (serde_json::from_str(&json).unwrap(), peak_kb * 1024)
}

/// The file (streamed, read twice) and the same bytes on a pipe (read whole) give the same
/// allan.json, byte for byte, the τ beyond the window included.
#[test]
fn a_long_file_streamed_equals_the_pipe_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let text = csv(LONG, 2);
    let file = dir.path().join("imu.csv");
    std::fs::write(&file, &text).unwrap();
    let (streamed, _) = run(&file, None, &dir.path().join("file"));
    let (whole, _) = run(
        Path::new("/dev/stdin"),
        Some(text.as_bytes()),
        &dir.path().join("pipe"),
    );
    let taus: Vec<f64> =
        serde_json::from_value(streamed["channels"]["az_m_s2"]["tau_s"].clone()).unwrap();
    let last = (taus[taus.len() - 1] / TAU0_S).round() as usize;
    assert_eq!(last, 2 * EXACT_MAX_M);
    assert_eq!(streamed, whole);
}

/// Peak memory of the streamed path does not follow the log's length: from 10⁶ to 4·10⁶ rows
/// it grows by less than 8 MB, where holding the samples and their stamps (16 bytes a row) and
/// the phase (8) would add 72 MB. The whole-series path on a pipe (the negative control) does
/// grow by more than that.
#[test]
fn peak_memory_does_not_follow_the_length() {
    let dir = tempfile::tempdir().unwrap();
    let mut peaks = Vec::new();
    for (k, rows) in [1_000_000usize, 4_000_000].into_iter().enumerate() {
        let text = csv(rows, 3 + k as u64);
        let file = dir.path().join(format!("imu{rows}.csv"));
        std::fs::write(&file, &text).unwrap();
        let (_, file_peak) = run(&file, None, &dir.path().join(format!("f{rows}")));
        let (_, pipe_peak) = run(
            Path::new("/dev/stdin"),
            Some(text.as_bytes()),
            &dir.path().join(format!("p{rows}")),
        );
        eprintln!("{rows} rows: streamed {file_peak} B, whole {pipe_peak} B");
        peaks.push((file_peak, pipe_peak));
    }
    let grown = peaks[1].0 as f64 - peaks[0].0 as f64;
    let held = 3_000_000.0 * 24.0;
    assert!(grown < 8e6, "streamed peak grew by {grown} B");
    assert!(
        peaks[1].1 as f64 - peaks[0].1 as f64 > held,
        "the whole-series path should grow by at least {held} B: {peaks:?}"
    );
}
