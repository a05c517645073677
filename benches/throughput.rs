//! Ensemble throughput, in realizations per second, for the default configuration (200 Hz for
//! 30 s, 150 GPS fixes, every statistic of the checks). Prints the median of repeated runs, with
//! the minimum and maximum, and the same for the bare simulation kernel with no statistics, so
//! the cost of the statistics shows as a ratio.
//!
//! Run with `cargo bench --bench throughput` (options: `-- --realizations N --repeats R`).

use std::hint::black_box;
use std::time::Instant;

use accelcal::config::{Config, TruthModel};
use accelcal::ensemble;
use accelcal::filter::FilterSchedule;
use accelcal::model::Model;
use accelcal::simulation::{FixState, Observer, run_realization};
use rayon::prelude::*;

/// Keeps nothing but what stops the optimizer from removing the work.
struct Discard(f64);

impl Observer for Discard {
    fn fix(&mut self, f: &FixState) {
        self.0 += f.post[2];
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn measure(label: &str, repeats: usize, n: u64, mut once: impl FnMut()) -> f64 {
    once(); // warm-up
    let mut rates: Vec<f64> = (0..repeats)
        .map(|_| {
            let t = Instant::now();
            once();
            n as f64 / t.elapsed().as_secs_f64()
        })
        .collect();
    let (lo, hi) = (
        rates.iter().cloned().fold(f64::INFINITY, f64::min),
        rates.iter().cloned().fold(0.0, f64::max),
    );
    let med = median(&mut rates);
    println!(
        "{label:<38} median {med:>9.0} realizations/s   (min {lo:.0}, max {hi:.0}, {repeats} runs of {n})"
    );
    med
}

fn arg(name: &str, default: u64) -> u64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let n = arg("--realizations", 10_000);
    let repeats = arg("--repeats", 9) as usize;
    println!("threads: {}", rayon::current_num_threads());
    let config = Config::default();
    let base = Model::new(&config).expect("default configuration is valid");
    let schedule =
        FilterSchedule::new(&base.timeline, &base.filter_stats).expect("positive definite");
    for truth in TruthModel::ALL {
        let model = base.with_truth(truth);
        let full = measure(
            &format!("ensemble with statistics ({truth})"),
            repeats,
            n,
            || {
                black_box(ensemble::run(&model, &schedule, 1, n, |_| {}));
            },
        );
        let bare = measure(
            &format!("simulation kernel only ({truth})"),
            repeats,
            n,
            || {
                let s: f64 = (0..n)
                    .into_par_iter()
                    .map(|l| {
                        let mut d = Discard(0.0);
                        run_realization(&model, &schedule, 1, l, &mut d);
                        d.0
                    })
                    .sum();
                black_box(s);
            },
        );
        println!(
            "{:<38} {:.2}",
            "ratio statistics / kernel only",
            full / bare
        );
    }
}
