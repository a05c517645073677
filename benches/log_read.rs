//! The log path's parts, in MB/s of accelerometer log text: reading the file's bytes, and the
//! one pass of `calibrate` (parse, check, reduce between fixes). Each figure is the median of
//! repeated runs, with the minimum and maximum. The thread count is the process's
//! (`RAYON_NUM_THREADS`).
//!
//! Run with `cargo bench --bench log_read -- --accel FILE --gps FILE [--repeats R]`
//! (`benches/log_speed.py` makes the hour-long log and runs it with 1 and 2 threads).

use std::io::Read;
use std::path::PathBuf;
use std::time::Instant;

use accelcal::calibrate::pass::{Integrated, Start, reduce};
use accelcal::input::csv::read::{LogFile, LogSource, read_gps};
use accelcal::model::BiasModel;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Runs `once` `repeats` times and prints its rate over `bytes` of text.
fn measure(label: &str, repeats: usize, bytes: u64, mut once: impl FnMut()) {
    let mut rates: Vec<f64> = (0..repeats)
        .map(|_| {
            let start = Instant::now();
            once();
            bytes as f64 / 1e6 / start.elapsed().as_secs_f64()
        })
        .collect();
    let (lo, hi) = (rates[0], rates[0]);
    let (lo, hi) = rates
        .iter()
        .fold((lo, hi), |(a, b), &r| (a.min(r), b.max(r)));
    println!(
        "{label}: {:.0} MB/s (median of {repeats}; {lo:.0}–{hi:.0})",
        median(&mut rates)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let (Some(accel), Some(gps)) = (value("--accel"), value("--gps")) else {
        eprintln!("usage: cargo bench --bench log_read -- --accel FILE --gps FILE [--repeats R]");
        return;
    };
    let repeats: usize = value("--repeats").map_or(7, |r| r.parse().expect("a count"));
    let (accel, gps) = (
        LogFile::new(&PathBuf::from(accel)),
        LogFile::new(&PathBuf::from(gps)),
    );
    let fixes = read_gps(&gps).expect("a good GPS log");
    let mut text = Vec::new();
    accel
        .open()
        .expect("readable")
        .read_to_end(&mut text)
        .expect("readable");
    let bytes = text.len() as u64;
    println!(
        "{}: {:.1} MB of text, {} fixes, {} threads",
        accel.name(),
        bytes as f64 / 1e6,
        fixes.len(),
        rayon::current_num_threads()
    );
    measure("read the bytes", repeats, bytes, || {
        let mut sink = Vec::with_capacity(text.len());
        accel.open().unwrap().read_to_end(&mut sink).unwrap();
        std::hint::black_box(sink);
    });
    let start = Integrated {
        pc_m: 0.0,
        vc_m_s: 100.0,
    };
    measure("one pass (parse, check, reduce)", repeats, bytes, || {
        let reduced = reduce(
            &accel,
            &fixes,
            (0.001, BiasModel::Constant),
            Start::Prior(start),
        )
        .expect("a good log");
        std::hint::black_box(reduced);
    });
}
