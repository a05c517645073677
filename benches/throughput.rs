//! Ensemble throughput, in realizations per second, for the default configuration (200 Hz for
//! 30 s, 150 GPS fixes, every statistic of the checks). Each figure is the median of repeated
//! runs, with the minimum and maximum:
//!
//! - the random-number bound: only the 6 303 standard normal draws a realization needs
//!   (3 initial values, 6 000 accelerometer noises, 2 per fix), in lane groups;
//! - the bare per-sample kernel (simulation and filter, no statistics);
//! - the full per-sample ensemble (`ensemble::run_with(Engine::Sample, …)`);
//! - the full epoch ensemble (`Engine::Epoch`), and its own random-number bound (603 normals:
//!   3 initial values, 2 per GPS interval, 2 per fix);
//!
//! and their ratios, so the remaining gap shows. `--numpy R` adds each figure's ratio to a numpy
//! rate R measured in the same session (`python3 benches/numpy_reference.py`).
//!
//! Run with `cargo bench --bench throughput` (options: `-- --realizations N --repeats R
//! --numpy R --truth analytic|euler`; defaults N = 100 000, R = 9).

use std::hint::black_box;
use std::time::Instant;

use accelcal::config::{Config, TruthModel};
use accelcal::ensemble::{self, Engine, kernel};
use accelcal::filter::FilterSchedule;
use accelcal::lanes::LANES;
use accelcal::model::Model;
use accelcal::random::normals_sum;
use accelcal::simulation::stream_key;
use rayon::prelude::*;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn measure(label: &str, repeats: usize, n: u64, numpy: Option<f64>, mut once: impl FnMut()) -> f64 {
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
    let vs = numpy.map_or(String::new(), |r| format!("  {:>6.1}× numpy", med / r));
    println!(
        "{label:<34} median {med:>9.0} realizations/s (min {lo:.0}, max {hi:.0}; {repeats} runs of {n}){vs}"
    );
    med
}

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .cloned()
}

/// Lane groups covering realizations 0..n, in parallel.
fn groups(n: u64) -> impl ParallelIterator<Item = (u64, usize)> {
    (0..n.div_ceil(LANES as u64)).into_par_iter().map(move |g| {
        (
            g * LANES as u64,
            (n - g * LANES as u64).min(LANES as u64) as usize,
        )
    })
}

fn main() {
    let n: u64 = arg("--realizations")
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000);
    let repeats: usize = arg("--repeats").and_then(|v| v.parse().ok()).unwrap_or(9);
    let numpy: Option<f64> = arg("--numpy").and_then(|v| v.parse().ok());
    let truth = match arg("--truth").as_deref() {
        Some("euler") => TruthModel::Euler,
        _ => TruthModel::Analytic,
    };
    println!("threads: {}, truth: {truth}", rayon::current_num_threads());
    let config = Config::default();
    let model = Model::new(&config)
        .expect("default configuration is valid")
        .with_truth(truth);
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
    let key = stream_key(1, model.case());
    let draws = 3 + model.timeline.steps + 2 * model.timeline.fixes();
    let rng = measure(
        &format!("random numbers only ({draws} normals)"),
        repeats,
        n,
        numpy,
        || {
            let s: f64 = groups(n)
                .map(|(first, _)| normals_sum(key, first, draws))
                .sum();
            black_box(s);
        },
    );
    let bare = measure(
        "per-sample kernel, no statistics",
        repeats,
        n,
        numpy,
        || {
            let s: f64 = groups(n)
                .map(|(first, active)| kernel::bare_group(&model, &schedule, key, first, active))
                .sum();
            black_box(s);
        },
    );
    let full = measure("per-sample ensemble", repeats, n, numpy, || {
        black_box(ensemble::run_with(
            Engine::Sample,
            &model,
            &schedule,
            1,
            n,
            |_| {},
        ));
    });
    let epoch_draws = 3 + 4 * model.timeline.fixes();
    let epoch_rng = measure(
        &format!("random numbers only ({epoch_draws} normals)"),
        repeats,
        n,
        numpy,
        || {
            let s: f64 = groups(n)
                .map(|(first, _)| normals_sum(key, first, epoch_draws))
                .sum();
            black_box(s);
        },
    );
    let epoch = measure("epoch ensemble", repeats, n, numpy, || {
        black_box(ensemble::run_with(
            Engine::Epoch,
            &model,
            &schedule,
            1,
            n,
            |_| {},
        ));
    });
    println!("{:<34} {:.2}", "ratio kernel / random numbers", bare / rng);
    println!(
        "{:<34} {:.2}",
        "ratio per-sample ensemble / kernel",
        full / bare
    );
    println!(
        "{:<34} {:.2}",
        "ratio epoch / per-sample ensemble",
        epoch / full
    );
    println!(
        "{:<34} {:.2}",
        "ratio epoch / its random numbers",
        epoch / epoch_rng
    );
}
