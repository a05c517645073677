//! The Monte Carlo ensemble: N realizations run in parallel and accumulated as they are produced.
//!
//! Memory does not grow with N: realizations are grouped into chunks of [`CHUNK`] consecutive
//! indices and blocks of consecutive chunks; each block is summed into its own [`Accumulator`]
//! by one worker, chunk after chunk, and the blocks are merged into the total in block order.
//! The boundaries depend on N alone, so the result is bit-for-bit the same on one thread or
//! many.

mod engine;
pub mod epoch;
pub mod kernel;
mod lane_sums;
mod layout;
pub mod linear;
pub mod partial;
mod stats;
mod sums;
mod tiles;

use std::time::Instant;

use crate::filter::FilterSchedule;
use crate::model::Model;
pub use engine::{Engine, Prepared, Scratch, accumulate, accumulate_into, accumulate_with};
pub use lane_sums::LaneFix;
pub use layout::ResidualLayout;
pub use stats::{EnsembleStats, FixStats, StageStats, StageView, Statistics};
pub use sums::{Accumulator, FixSums, StageSums};
pub use tiles::{PASS, PRODUCT_RELATIVE_ERROR};

/// Realizations summed sequentially into one accumulator before it is merged.
pub const CHUNK: u64 = 64;

/// Memory the chunk accumulators in flight may take together, bytes.
const WINDOW_BYTES: u64 = 256 << 20;

/// The residual layout of `model`'s ensemble.
pub fn layout_of(model: &Model) -> ResidualLayout {
    ResidualLayout::new(model.timeline.fixes(), model.residual_max_lag())
}

/// Largest number of blocks an ensemble is folded in. Blocks are the unit of sharding.
pub const MAX_BLOCKS: u64 = 256;

/// How the N realizations of an ensemble are grouped, by N alone: chunks of [`CHUNK`]
/// consecutive indices; blocks of consecutive chunks, each summed chunk after chunk in a fixed
/// order (see [`accumulate_into`]); the ensemble is the fold of its blocks in order. A
/// shard runs whole blocks, so shards merged in block order give the sums of one run, number
/// for number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Realizations N.
    pub realizations: u64,
    /// Chunks, ⌈N / CHUNK⌉.
    pub chunks: u64,
    /// Chunks per block, ⌈chunks / MAX_BLOCKS⌉.
    pub chunks_per_block: u64,
    /// Blocks, at most [`MAX_BLOCKS`].
    pub blocks: u64,
}

impl Partition {
    /// The partition of `n` realizations.
    pub fn new(n: u64) -> Self {
        let chunks = n.div_ceil(CHUNK);
        let chunks_per_block = chunks.div_ceil(MAX_BLOCKS).max(1);
        Self {
            realizations: n,
            chunks,
            chunks_per_block,
            blocks: chunks.div_ceil(chunks_per_block),
        }
    }

    /// The chunks of block `b`.
    pub fn block_chunks(&self, b: u64) -> std::ops::Range<u64> {
        b * self.chunks_per_block..((b + 1) * self.chunks_per_block).min(self.chunks)
    }

    /// The realization indices of chunk `c`.
    pub fn chunk_realizations(&self, c: u64) -> std::ops::Range<u64> {
        c * CHUNK..((c + 1) * CHUNK).min(self.realizations)
    }

    /// The realizations of blocks `blocks`.
    pub fn realizations_in(&self, blocks: &std::ops::Range<u64>) -> u64 {
        if blocks.is_empty() {
            return 0;
        }
        let first = self.block_chunks(blocks.start).start;
        let last = self.block_chunks(blocks.end - 1).end;
        self.chunk_realizations(last - 1).end - self.chunk_realizations(first).start
    }

    /// The blocks of shard `k` of `m`, k counted from 1: blocks ⌊(k − 1)·B/m⌋ up to ⌊k·B/m⌋.
    pub fn shard_blocks(&self, k: u64, m: u64) -> std::ops::Range<u64> {
        (k - 1) * self.blocks / m..k * self.blocks / m
    }
}

/// Finished blocks waiting for their turn, and the callbacks that take them in block order.
struct Emitter<P, B> {
    /// The next block to hand over.
    next: u64,
    waiting: std::collections::BTreeMap<u64, Accumulator>,
    /// Sums handed over, kept for the next blocks: a block overwrites every number of them.
    spare: Vec<Accumulator>,
    done: u64,
    /// A worker panicked: the others stop instead of waiting for its block.
    failed: bool,
    progress: P,
    on_block: B,
}

/// Set in each worker: if the worker panics, it marks the run failed, lets no further block be
/// taken and wakes the waiting workers, so that every worker ends and `rayon::broadcast` hands
/// the panic to the caller (rather than the others waiting forever for the lost block).
struct Abort<'a, P, B> {
    emitter: &'a std::sync::Mutex<Emitter<P, B>>,
    turn: &'a std::sync::Condvar,
    claimed: &'a std::sync::atomic::AtomicU64,
    end: u64,
}

impl<P, B> Drop for Abort<'_, P, B> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.claimed
                .store(self.end, std::sync::atomic::Ordering::SeqCst);
            self.emitter
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .failed = true;
            self.turn.notify_all();
        }
    }
}

/// Runs blocks `blocks` of the `n` realizations of `model` under `seed` in parallel with the
/// engine `prepared`, and hands each block's sums to `on_block` as it is finished, in block
/// order. `progress` is called with the number of realizations of these blocks finished so far.
///
/// Each block is summed by one thread, chunk after chunk (see [`accumulate_into`]): its sums
/// depend on the block's realizations alone, never on the thread count. One worker per thread
/// takes the next block as it finishes one; finished blocks are handed over in block order, and
/// a worker waits rather than run more than a window of blocks ahead of the oldest unfinished
/// one, so that at most about WINDOW_BYTES of sums are alive at once.
#[allow(clippy::too_many_arguments)]
pub fn run_blocks_prepared(
    prepared: &Prepared,
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    n: u64,
    blocks: std::ops::Range<u64>,
    progress: impl FnMut(u64) + Send,
    on_block: impl FnMut(u64, &Accumulator) + Send,
) {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::{Condvar, Mutex};

    let partition = Partition::new(n);
    let layout = layout_of(model);
    let acc_bytes = 8 * (2 * layout.len() + 51 * layout.fixes()).max(1) as u64;
    let threads = rayon::current_num_threads() as u64;
    let window = (2 * threads)
        .min((WINDOW_BYTES / acc_bytes).max(threads))
        .max(1);
    let claimed = AtomicU64::new(blocks.start);
    let emitter = Mutex::new(Emitter {
        next: blocks.start,
        waiting: Default::default(),
        spare: Vec::new(),
        done: 0,
        failed: false,
        progress,
        on_block,
    });
    let turn = Condvar::new();
    let lock = || emitter.lock().unwrap_or_else(|e| e.into_inner());
    let worker = || {
        let _abort = Abort {
            emitter: &emitter,
            turn: &turn,
            claimed: &claimed,
            end: blocks.end,
        };
        let mut scratch = Scratch::default();
        loop {
            let b = claimed.fetch_add(1, Ordering::Relaxed);
            if b >= blocks.end {
                return;
            }
            // Every block before b is claimed by a running worker, so the wait ends (or a
            // worker failed, and the run with it).
            let mut e = turn
                .wait_while(lock(), |e| !e.failed && b >= e.next + window)
                .unwrap_or_else(|e| e.into_inner());
            if e.failed {
                return;
            }
            let mut acc = e
                .spare
                .pop()
                .unwrap_or_else(|| Accumulator::new(&layout, model.residual_pair));
            drop(e);
            let chunks = partition.block_chunks(b);
            let range = partition.chunk_realizations(chunks.start).start
                ..partition.chunk_realizations(chunks.end - 1).end;
            accumulate_into(
                prepared,
                model,
                schedule,
                seed,
                range,
                &mut acc,
                &mut scratch,
            );
            let mut e = lock();
            if e.failed {
                return;
            }
            e.waiting.insert(b, acc);
            let mut advanced = false;
            loop {
                let next = e.next;
                let Some(acc) = e.waiting.remove(&next) else {
                    break;
                };
                e.done += acc.count;
                (e.on_block)(next, &acc);
                e.spare.push(acc);
                e.next += 1;
                advanced = true;
            }
            if advanced {
                let done = e.done;
                (e.progress)(done);
                drop(e);
                turn.notify_all();
            }
        }
    };
    rayon::broadcast(|_| worker());
}

/// Runs `n` realizations of `model` under `seed` in parallel and returns their sums, the fold
/// of every block in order. `progress` is called with the number of realizations finished so
/// far.
pub fn run(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    n: u64,
    progress: impl FnMut(u64) + Send,
) -> Accumulator {
    run_with(Engine::Sample, model, schedule, seed, n, progress)
}

/// [`run`] with the engine `engine`.
pub fn run_with(
    engine: Engine,
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    n: u64,
    progress: impl FnMut(u64) + Send,
) -> Accumulator {
    let prepared = Prepared::new(engine, model, schedule);
    run_prepared(&prepared, model, schedule, seed, n, progress)
}

/// [`run`] with the engine `prepared`.
pub fn run_prepared(
    prepared: &Prepared,
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    n: u64,
    progress: impl FnMut(u64) + Send,
) -> Accumulator {
    let mut total = Accumulator::new(&layout_of(model), model.residual_pair);
    run_blocks_prepared(
        prepared,
        model,
        schedule,
        seed,
        n,
        0..Partition::new(n).blocks,
        progress,
        |_, block| total.merge(block),
    );
    total
}

/// A finished ensemble: its statistics and how fast it ran.
#[derive(Clone, Debug)]
pub struct EnsembleRun {
    /// The ensemble statistics.
    pub stats: EnsembleStats,
    /// Wall-clock time of the realizations, s.
    pub elapsed_s: f64,
    /// The engine that simulated the realizations.
    pub engine: Engine,
}

impl EnsembleRun {
    /// Realizations per second.
    pub fn realizations_per_s(&self) -> f64 {
        self.stats.realizations as f64 / self.elapsed_s
    }
}

/// Runs the ensemble of `model` with its configured size and seed.
pub fn run_model(
    model: &Model,
    schedule: &FilterSchedule,
    progress: impl FnMut(u64) + Send,
) -> EnsembleRun {
    run_model_with(Engine::Sample, model, schedule, progress)
}

/// [`run_model`] with the engine `engine`.
pub fn run_model_with(
    engine: Engine,
    model: &Model,
    schedule: &FilterSchedule,
    progress: impl FnMut(u64) + Send,
) -> EnsembleRun {
    let e = &model.config.ensemble;
    let start = Instant::now();
    let acc = run_with(engine, model, schedule, e.seed, e.realizations, progress);
    let elapsed_s = start.elapsed().as_secs_f64();
    EnsembleRun {
        stats: EnsembleStats::from_sums(&acc, schedule),
        elapsed_s,
        engine,
    }
}

#[cfg(test)]
mod tests;
