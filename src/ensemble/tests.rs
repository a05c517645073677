use super::*;

use crate::config::Config;
use crate::progress::{Cancel, Cancelled};
use crate::simulation::{FixState, Observer, run_realization};
use crate::state::{ErrorState, StateVector};

fn small() -> (Model, FilterSchedule) {
    let mut c = Config::default();
    c.profile.duration_s = 2.0;
    let m = Model::new(&c).unwrap();
    let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
    (m, s)
}

#[test]
fn merged_chunks_equal_one_pass_up_to_rounding() {
    let (m, s) = small();
    let e = Ensemble::new(&m, &s).with_seed(5);
    let whole = e.sums_of(0..300);
    let mut parts = e.sums_of(0..100);
    parts.merge(&e.sums_of(100..300));
    assert_eq!(whole.count, parts.count);
    // The residual products are summed in single precision within a chunk, and the two runs
    // have different chunks: each is within PRODUCT_RELATIVE_ERROR of the exact sum.
    let layout = &whole.layout;
    let diagonal = |a: usize| whole.residual_products[layout.index(a, a).unwrap()];
    for a in 0..2 * layout.fixes() {
        for b in layout.first_col(a)..=a {
            let i = layout.index(a, b).unwrap();
            let bound = 2.0 * PRODUCT_RELATIVE_ERROR * (diagonal(a) * diagonal(b)).sqrt();
            let (x, y) = (whole.residual_products[i], parts.residual_products[i]);
            assert!(
                (x - y).abs() <= bound,
                "({a}, {b}): {x} vs {y}, bound {bound}"
            );
        }
    }
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
    for (a, b) in whole.fixes.iter().zip(&parts.fixes) {
        for (x, y) in [(&a.prior, &b.prior), (&a.post, &b.post)] {
            assert!(x.e.iter().zip(y.e.iter()).all(|(p, q)| close(*p, *q)));
            assert!(x.ee.iter().zip(&y.ee).all(|(p, q)| close(*p, *q)));
            assert!(x.ex.iter().zip(y.ex.iter()).all(|(p, q)| close(*p, *q)));
            assert!(x.xx.iter().zip(y.xx.iter()).all(|(p, q)| close(*p, *q)));
            assert!(close(x.nees, y.nees));
        }
        assert!(close(a.nis, b.nis));
    }
}

#[test]
fn parallel_run_is_independent_of_the_thread_count() {
    let (m, s) = small();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let e = Ensemble::new(&m, &s).with_seed(9).with_realizations(1000);
    let a = one.install(|| e.sums(|_| {}));
    let b = three.install(|| e.sums(|_| {}));
    assert_eq!(a, b);
}

#[test]
fn streaming_moments_match_a_two_pass_computation() {
    struct Keep(Vec<FixState>);
    impl Observer for Keep {
        fn fix(&mut self, f: &FixState) {
            self.0.push(*f);
        }
    }
    let (m, s) = small();
    let n = 200u64;
    let stats = EnsembleStats::from_sums(&Ensemble::new(&m, &s).with_seed(3).sums_of(0..n), &s);
    let runs: Vec<Vec<FixState>> = (0..n)
        .map(|l| {
            let mut k = Keep(Vec::new());
            run_realization(&m, &s, 3, l, &mut k);
            k.0
        })
        .collect();
    let i = 4;
    let errs: Vec<StateVector> = runs.iter().map(|r| r[i].delta_x - r[i].post).collect();
    let mean = errs.iter().sum::<StateVector>() / n as f64;
    let var_v = errs.iter().map(|e| (e[1] - mean[1]).powi(2)).sum::<f64>() / (n as f64 - 1.0);
    let got = &stats.fixes[i].post;
    approx::assert_relative_eq!(got.mean_error[1], mean[1], max_relative = 1e-9);
    approx::assert_relative_eq!(got.ensemble_cov[1][1], var_v, max_relative = 1e-9);
    // Orthogonality (1/N) Σ (e − ē) x̂ᵀ, entry (velocity error, bias estimate).
    let xs: Vec<StateVector> = runs.iter().map(|r| r[i].post).collect();
    let (vel, bias) = (ErrorState::VELOCITY, ErrorState::BIAS);
    let ortho = errs
        .iter()
        .zip(&xs)
        .map(|(e, x)| (e[vel] - mean[vel]) * x[bias])
        .sum::<f64>()
        / n as f64;
    approx::assert_relative_eq!(got.orthogonality[vel][bias], ortho, max_relative = 1e-8);
    // NEES (1/N) Σ eᵀ P⁻¹ e with the filter's a posteriori P.
    let p_inv = s.fixes[i].p_post.try_inverse().unwrap();
    let nees = errs.iter().map(|e| e.dot(&(p_inv * e))).sum::<f64>() / n as f64;
    approx::assert_relative_eq!(got.nees_avg, nees, max_relative = 1e-8);
    let r = |l: usize, a: usize| runs[l][a / 2].residual[a % 2];
    let moment =
        |a: usize, b: usize| (0..n as usize).map(|l| r(l, a) * r(l, b)).sum::<f64>() / n as f64;
    // Single precision within a chunk: within PRODUCT_RELATIVE_ERROR (relative to the
    // diagonal moments) of the exact double-precision sum.
    let bound = PRODUCT_RELATIVE_ERROR * (moment(2, 2) * moment(7, 7)).sqrt();
    let got = stats.residual_moment(2, 7).unwrap();
    assert!(
        (got - moment(7, 2)).abs() <= bound,
        "{got} vs {}",
        moment(7, 2)
    );
    // The statement's single pair is kept in double precision.
    let [later, earlier] = m.residual_pair;
    let pair = moment(2 * earlier, 2 * later + 1);
    approx::assert_relative_eq!(stats.pair_moments[(0, 1)], pair, max_relative = 1e-9);
}

/// A panic in one block (here in the caller's `on_block`) reaches the caller instead of leaving
/// the other workers waiting for the lost block.
#[test]
fn a_panicking_block_ends_the_run_with_the_panic() {
    let (m, s) = small();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            two.install(|| {
                // 40 blocks of one chunk: far more than the window of blocks in flight.
                Ensemble::new(&m, &s)
                    .with_engine(Engine::Epoch)
                    .with_seed(1)
                    .with_realizations(40 * CHUNK)
                    .blocks(
                        |_| {},
                        |b, _| {
                            assert!(b != 0, "a failing block");
                        },
                    )
            })
        }));
        tx.send(result.is_err()).unwrap();
    });
    let panicked = rx
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the run returned");
    assert!(panicked);
}

/// The shards of an ensemble, folded in shard order, give its sums number for number; a shard
/// runs its own blocks only.
#[test]
fn shards_fold_to_the_whole_ensemble() {
    let (m, s) = small();
    // 40 chunks: 40 blocks of one chunk, cut into three uneven shards.
    let e = Ensemble::new(&m, &s)
        .with_engine(Engine::Epoch)
        .with_seed(4)
        .with_realizations(40 * CHUNK - 5);
    let whole = e.sums(|_| {});
    let mut folded = e.empty_sums();
    let mut blocks = Vec::new();
    for k in 1..=3 {
        let shard = e.clone().with_shard(Shard { index: k, of: 3 });
        shard.blocks(
            |_| {},
            |b, acc| {
                blocks.push(b);
                folded.merge(acc);
            },
        );
    }
    assert_eq!(blocks, (0..40).collect::<Vec<_>>());
    assert_eq!(folded, whole);
    assert_eq!(whole.count, 40 * CHUNK - 5);
}

/// `with_truth` simulates the other truth: the same sums as an ensemble of the model with that
/// truth, and not those of the model's own.
#[test]
fn with_truth_runs_the_other_truth() {
    let (m, s) = small();
    let euler = m.with_truth(crate::config::TruthModel::Euler);
    for engine in [Engine::Sample, Engine::Epoch] {
        let of_model = Ensemble::new(&euler, &s).with_engine(engine).with_seed(2);
        let switched = Ensemble::new(&m, &s)
            .with_engine(engine)
            .with_seed(2)
            .with_truth(crate::config::TruthModel::Euler);
        let own = Ensemble::new(&m, &s).with_engine(engine).with_seed(2);
        let range = 0..100;
        assert_eq!(
            switched.sums_of(range.clone()),
            of_model.sums_of(range.clone())
        );
        assert_ne!(own.sums_of(range.clone()), of_model.sums_of(range));
    }
}

/// A raised [`Cancel`] stops the run: raised from the progress callback after the first block,
/// no block is started afterwards beyond those already claimed (one per thread at most), and the
/// call ends with `Cancelled`; a flag never raised gives the whole run's sums (the control).
#[test]
fn a_raised_cancel_stops_the_run_within_a_block_per_thread() {
    let (m, s) = small();
    let e = Ensemble::new(&m, &s)
        .with_engine(Engine::Epoch)
        .with_seed(3)
        .with_realizations(200 * CHUNK);
    let blocks = e.partition().blocks;
    assert!(blocks >= 100, "{blocks} blocks: too few to see the stop");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let cancel = Cancel::new();
    let mut done = 0;
    let stopped = pool.install(|| {
        e.try_sums(&cancel, |d| {
            done = d;
            cancel.cancel();
        })
    });
    assert_eq!(stopped, Err(Cancelled));
    // The block handed over first and, per thread, the one it was summing and a finished one
    // waiting for its turn (BLOCKS_AHEAD_PER_THREAD = 2).
    let block = e.partition().block_realizations(0).end;
    assert!(done <= 5 * block, "{done} realizations after the flag");

    let never = Cancel::new();
    let whole = pool.install(|| e.try_sums(&never, |_| {}));
    assert_eq!(whole, Ok(pool.install(|| e.sums(|_| {}))));
    assert_eq!(Cancel::new().check(), Ok(()));
}
