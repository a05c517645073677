//! Speed of `accelcal allan` on a synthetic static log (white noise plus a random walk of the
//! bias, 100 Hz): the whole command on the CSV, the whole analysis in memory, and the deviation
//! alone (cumulative sums, octave τ), each the median of repeated runs with the minimum and
//! maximum. It also writes the samples as raw little-endian f64 (`samples.f64`) for
//! `benches/allan_oadev.py`, which times allantools' `oadev` on the same numbers.
//!
//! Run with `cargo build --release && cargo bench --bench allan` (options: `-- --samples N
//! --repeats R --dir DIR`; defaults N = 10 000 000, R = 5, DIR = target/allan-bench).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use accelcal::allan::simulate::StaticLog;
use accelcal::allan::{analyse, deviation};
use accelcal::input::csv::read::LogFile;
use accelcal::input::csv::static_log::read_static_log;
use accelcal::input::csv::text::{header, push_row};

const LOG: StaticLog = StaticLog {
    sample_period_s: 0.01,
    velocity_random_walk_m_s_per_sqrt_s: 2e-3,
    acceleration_random_walk_m_s2_per_sqrt_s: 1e-4,
    offset_m_s2: 9.80665,
};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// This process's CPU time and its waited-for children's, s (Linux: /proc/self/stat, fields
/// utime, stime, cutime, cstime in ticks of 1/100 s).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .skip(11)
        .take(4)
        .map(|v| v.parse().unwrap_or(0.0))
        .collect();
    f.iter().sum::<f64>() / 100.0
}

/// Medians of `f`'s wall time and CPU time (all threads, children included) over `repeats`
/// runs, with the wall time's minimum and maximum, s.
fn time(repeats: usize, mut f: impl FnMut()) -> (f64, f64, f64, f64) {
    let (mut wall, mut cpu): (Vec<f64>, Vec<f64>) = (0..repeats)
        .map(|_| {
            let (start, c0) = (Instant::now(), cpu_s());
            f();
            (start.elapsed().as_secs_f64(), cpu_s() - c0)
        })
        .unzip();
    wall.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    (
        wall[wall.len() / 2],
        wall[0],
        wall[wall.len() - 1],
        cpu[cpu.len() / 2],
    )
}

fn write_inputs(dir: &Path, y: &[f64]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let csv = dir.join("static.csv");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&csv).unwrap());
    out.write_all(header(&["t_s", "accel_m_s2"]).as_bytes())
        .unwrap();
    let mut row = String::new();
    for (i, v) in y.iter().enumerate() {
        row.clear();
        push_row(&mut row, &[i as f64 * LOG.sample_period_s, *v]);
        out.write_all(row.as_bytes()).unwrap();
    }
    out.flush().unwrap();
    let raw: Vec<u8> = y.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("samples.f64"), raw).unwrap();
    csv
}

fn report(label: &str, (median, min, max, cpu): (f64, f64, f64, f64)) {
    println!(
        "{label:<48} wall median {median:6.3} s (min {min:.3}, max {max:.3}); CPU median {cpu:6.2} s"
    );
}

fn main() {
    let samples: usize = arg("--samples").map_or(10_000_000, |s| s.parse().unwrap());
    let repeats: usize = arg("--repeats").map_or(5, |s| s.parse().unwrap());
    let dir = PathBuf::from(arg("--dir").unwrap_or_else(|| "target/allan-bench".to_string()));
    let y = LOG.samples(samples, 1);
    let csv = write_inputs(&dir, &y);
    println!(
        "{samples} samples at {} Hz, {} threads; inputs in {}",
        1.0 / LOG.sample_period_s,
        rayon::current_num_threads(),
        dir.display()
    );
    let factors = deviation::octave_factors(samples);
    let source = LogFile::new(&csv);
    report(
        "reading the CSV (log reader, step checks)",
        time(repeats, || {
            std::hint::black_box(read_static_log(&source, "accel_m_s2").unwrap());
        }),
    );
    report(
        "phase (mean, cumulative sum)",
        time(repeats, || {
            std::hint::black_box(deviation::phase(&y));
        }),
    );
    report(
        &format!("deviation in memory ({} octave τ)", factors.len()),
        time(repeats, || {
            std::hint::black_box(deviation::oadev(&y, &factors));
        }),
    );
    report(
        "analysis in memory (+ noise, EDF, fit)",
        time(repeats, || {
            std::hint::black_box(analyse(&y, LOG.sample_period_s, 0.683).unwrap());
        }),
    );
    let exe = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/release/accelcal");
    let exe = std::env::var_os("CARGO_TARGET_DIR")
        .map_or(exe, |d| PathBuf::from(d).join("release/accelcal"));
    report(
        "accelcal allan on the CSV (whole process)",
        time(repeats, || {
            let status = Command::new(&exe)
                .args(["allan", "--quiet", "--accel"])
                .arg(&csv)
                .arg("--out")
                .arg(dir.join("out"))
                .stdout(std::process::Stdio::null())
                .status()
                .expect("run target/release/accelcal (cargo build --release first)");
            assert!(status.success());
        }),
    );
}
