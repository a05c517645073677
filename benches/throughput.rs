//! Ensemble throughput, in realizations per second, for the default configuration (200 Hz for
//! 30 s, 150 GPS fixes, every statistic of the checks). Each figure is the median of repeated
//! runs, with the minimum and maximum:
//!
//! - the random-number bound: only the 6 303 standard normal draws a realization needs
//!   (3 initial values, 6 000 accelerometer noises, 2 per fix), in lane groups;
//! - the bare per-sample kernel (simulation and filter, no statistics);
//! - the full per-sample ensemble (`Ensemble::new(…).sums(…)`, the per-sample engine);
//! - the full epoch ensemble (`with_engine(Engine::Epoch)`), and its own random-number bound (603 normals:
//!   3 initial values, 2 per GPS interval, 2 per fix);
//!
//! and their ratios, so the remaining gap shows. `--numpy R` adds each figure's ratio to a numpy
//! rate R measured in the same session (`python3 benches/numpy_reference.py`).
//!
//! Run with `cargo bench --bench throughput` (options: `-- --realizations N --repeats R
//! --numpy R --truth analytic|euler --bias-random-walk K`; defaults N = 100 000, R = 9, a constant
//! bias; `--bias-random-walk K` makes the truth's and the filter's bias a random walk of K
//! m/s²/√s).

use std::hint::black_box;
use std::time::Instant;

use accelcal::config::{BiasModelKind, Config, TruthModel};
use accelcal::ensemble::{Engine, Ensemble, kernel};
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

/// What the command line asks for.
struct Options {
    /// Realizations per run.
    n: u64,
    repeats: usize,
    /// The numpy reference's rate, realizations/s, measured in the same session.
    numpy: Option<f64>,
    truth: TruthModel,
    /// K of a random-walk bias (truth and filter), m/s²/√s; `None`: a constant bias.
    random_walk: Option<f64>,
}

impl Options {
    fn parse() -> Self {
        Self {
            n: arg("--realizations")
                .and_then(|v| v.parse().ok())
                .unwrap_or(100_000),
            repeats: arg("--repeats").and_then(|v| v.parse().ok()).unwrap_or(9),
            numpy: arg("--numpy").and_then(|v| v.parse().ok()),
            truth: match arg("--truth").as_deref() {
                Some("euler") => TruthModel::Euler,
                _ => TruthModel::Analytic,
            },
            random_walk: arg("--bias-random-walk").and_then(|v| v.parse().ok()),
        }
    }

    /// The median rate of `once`, a run of `n` realizations, labelled `label`.
    fn measure(&self, label: &str, once: impl FnMut()) -> f64 {
        measure(label, self.repeats, self.n, self.numpy, once)
    }
}

/// The rate of drawing `draws` standard normals for each of `n` realizations.
fn random_numbers(o: &Options, key: u64, draws: usize) -> f64 {
    o.measure(&format!("random numbers only ({draws} normals)"), || {
        let s: f64 = groups(o.n)
            .map(|(first, _)| normals_sum(key, first, draws))
            .sum();
        black_box(s);
    })
}

fn main() {
    let o = Options::parse();
    println!(
        "threads: {}, truth: {}, bias: {}",
        rayon::current_num_threads(),
        o.truth,
        o.random_walk
            .map_or("constant".to_string(), |k| format!("random walk, K = {k}"))
    );
    let mut config = Config::default();
    if let Some(k) = o.random_walk {
        config.accelerometer.bias_model = BiasModelKind::RandomWalk;
        config.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(k);
    }
    let model = Model::new(&config)
        .expect("default configuration is valid")
        .with_truth(o.truth);
    let schedule =
        FilterSchedule::new(&model.timeline, &model.filter_stats).expect("positive definite");
    let key = stream_key(1, model.case());
    let rng = random_numbers(
        &o,
        key,
        3 + model.timeline.steps + 2 * model.timeline.fixes(),
    );
    let bare = o.measure("per-sample kernel, no statistics", || {
        let s: f64 = groups(o.n)
            .map(|(first, active)| kernel::bare_group(&model, &schedule, key, first, active))
            .sum();
        black_box(s);
    });
    let sample = Ensemble::new(&model, &schedule)
        .with_seed(1)
        .with_realizations(o.n);
    let full = o.measure("per-sample ensemble", || {
        black_box(sample.sums(|_| {}));
    });
    let epoch_rng = random_numbers(&o, key, 3 + 4 * model.timeline.fixes());
    let epoch_ensemble = sample.clone().with_engine(Engine::Epoch);
    let epoch = o.measure("epoch ensemble", || {
        black_box(epoch_ensemble.sums(|_| {}));
    });
    for (what, ratio) in [
        ("kernel / random numbers", bare / rng),
        ("per-sample ensemble / kernel", full / bare),
        ("epoch / per-sample ensemble", epoch / full),
        ("epoch / its random numbers", epoch / epoch_rng),
    ] {
        println!("{:<34} {ratio:.2}", format!("ratio {what}"));
    }
}
