//! The Monte Carlo ensemble: N realizations simulated in parallel and summed as they are
//! produced into the running sums ([`Accumulator`]) that the statistics ([`EnsembleStats`]) and the
//! checks read. Memory does not grow with N.
//!
//! [`Ensemble`] is the one way to run an ensemble: built from the model and the filter schedule,
//! then given, where the defaults (the model's configuration, the per-sample engine, the whole
//! ensemble) do not fit, a truth, an engine, a number of realizations, a seed or a shard; it
//! returns the statistics ([`Ensemble::run`]), the sums ([`Ensemble::sums`]) or each block's sums
//! in block order ([`Ensemble::blocks`], for a shard's partial file), and reports progress to a
//! callback.
//!
//! How the work is cut, by N alone ([`Partition`]): chunks of [`CHUNK`] consecutive realizations,
//! whose lane groups pass every fix together (`engine`), and at most [`MAX_BLOCKS`] blocks of
//! consecutive chunks. One worker per thread sums a block, chunk after chunk, into one
//! [`Accumulator`] (`workers`); finished blocks are handed over in block order, folded into the
//! total or written to a partial file. A block's sums depend on its realizations alone, so one
//! run gives the same numbers on any number of threads, and shards merged in block order give the
//! numbers of one run.
//!
//! The files: `engine` sums a block with either engine, `kernel` (per-sample) and `epoch` simulate
//! lane groups, `lane_sums` adds a fix across lanes, `tiles` adds the residual products in single
//! precision, `layout` says which residual products are kept, `normalized` sums realizations that each have
//! their own covariance (an extended Kalman filter's), `sums` and `stats` hold the sums and
//! the statistics made of them, `workers` runs the blocks in parallel, `partial` writes and merges
//! shards.

mod engine;
pub mod epoch;
pub mod kernel;
mod lane_sums;
mod layout;
pub mod linear;
pub mod normalized;
pub mod partial;
mod stats;
mod sums;
mod tiles;
mod workers;

use std::borrow::Cow;
use std::ops::Range;
use std::time::Instant;

use crate::config::TruthModel;
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::progress::{Cancel, Cancelled};
pub use engine::Engine;
use engine::Prepared;
use epoch::EpochPlan;
pub use lane_sums::LaneFix;
pub use layout::ResidualLayout;
pub use stats::{EnsembleStats, FixStats, StageStats, StageView, Statistics};
pub use sums::{Accumulator, FixSums, StageSums};
pub use tiles::{PASS, PRODUCT_RELATIVE_ERROR};

/// Realizations of a chunk: its lane groups of [`LANES`](crate::lanes::LANES) pass every fix
/// together, so that the per-lane sums of a fix are added across lanes once per chunk
/// (`lane_sums`). It is also the unit [`Partition`] cuts blocks from: changing it changes the
/// order of every sum, and so the last bits of the statistics.
pub const CHUNK: u64 = 64;

/// Largest number of blocks an ensemble is folded in. Blocks are the unit of sharding.
pub const MAX_BLOCKS: u64 = 256;

/// How the N realizations of an ensemble are grouped, by N alone: chunks of [`CHUNK`]
/// consecutive indices; blocks of consecutive chunks, each summed chunk after chunk in a fixed
/// order (see `engine`); the ensemble is the fold of its blocks in order. A
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
    /// Realizations per chunk ([`CHUNK`] here; the three-axis ensemble's are smaller).
    pub chunk: u64,
}

impl Partition {
    /// The partition of `n` realizations.
    pub fn new(n: u64) -> Self {
        Self::with_sizes(n, CHUNK, MAX_BLOCKS)
    }

    /// The partition of `n` realizations into chunks of `chunk` and at most `max_blocks`
    /// blocks.
    pub fn with_sizes(n: u64, chunk: u64, max_blocks: u64) -> Self {
        let chunks = n.div_ceil(chunk);
        let chunks_per_block = chunks.div_ceil(max_blocks).max(1);
        Self {
            realizations: n,
            chunks,
            chunks_per_block,
            blocks: chunks.div_ceil(chunks_per_block),
            chunk,
        }
    }

    /// The chunks of block `b`.
    pub fn block_chunks(&self, b: u64) -> Range<u64> {
        b * self.chunks_per_block..((b + 1) * self.chunks_per_block).min(self.chunks)
    }

    /// The realization indices of chunk `c`.
    pub fn chunk_realizations(&self, c: u64) -> Range<u64> {
        c * self.chunk..((c + 1) * self.chunk).min(self.realizations)
    }

    /// The realization indices of block `b`.
    pub fn block_realizations(&self, b: u64) -> Range<u64> {
        let chunks = self.block_chunks(b);
        self.chunk_realizations(chunks.start).start..self.chunk_realizations(chunks.end - 1).end
    }

    /// The realizations of blocks `blocks`.
    pub fn realizations_in(&self, blocks: &Range<u64>) -> u64 {
        if blocks.is_empty() {
            return 0;
        }
        let first = self.block_chunks(blocks.start).start;
        let last = self.block_chunks(blocks.end - 1).end;
        self.chunk_realizations(last - 1).end - self.chunk_realizations(first).start
    }

    /// The blocks of `shard` k of m: blocks ⌊(k − 1)·B/m⌋ up to ⌊k·B/m⌋ of the B blocks.
    pub fn shard_blocks(&self, shard: Shard) -> Range<u64> {
        let Shard { index: k, of: m } = shard;
        (k - 1) * self.blocks / m..k * self.blocks / m
    }
}

/// Shard k of m of an ensemble: the k-th of m runs of consecutive blocks, whose partial sums,
/// merged in block order, give the sums of one run (see [`Partition::shard_blocks`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// k, counted from 1.
    pub index: u64,
    /// m, the number of shards.
    pub of: u64,
}

impl Shard {
    /// The whole ensemble, shard 1 of 1.
    pub const WHOLE: Shard = Shard { index: 1, of: 1 };
}

/// One ensemble to run: the model and its truth, the filter schedule, the engine, the number of
/// realizations N, the seed and the shard. [`Ensemble::new`] takes N and the seed from the model's
/// configuration, the per-sample engine and the whole ensemble; the `with_` methods change them.
///
/// ```
/// # use accelcal::{config::Config, model::Model, filter::FilterSchedule};
/// use accelcal::ensemble::{Engine, Ensemble};
/// let mut config = Config::default();
/// config.profile.duration_s = 2.0;
/// let model = Model::new(&config).unwrap();
/// let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats).unwrap();
/// let run = Ensemble::new(&model, &schedule)
///     .with_engine(Engine::Epoch)
///     .with_realizations(200)
///     .with_seed(7)
///     .run(|_done| {});
/// assert_eq!(run.stats.realizations, 200);
/// ```
#[derive(Clone, Debug)]
pub struct Ensemble<'a> {
    model: Cow<'a, Model>,
    schedule: &'a FilterSchedule,
    prepared: Prepared,
    seed: u64,
    realizations: u64,
    shard: Shard,
}

impl<'a> Ensemble<'a> {
    /// The ensemble of `model` (its truth, N and seed) filtered with `schedule`, with the
    /// per-sample engine, whole.
    pub fn new(model: &'a Model, schedule: &'a FilterSchedule) -> Self {
        let e = &model.config.ensemble;
        Self {
            seed: e.seed,
            realizations: e.realizations,
            model: Cow::Borrowed(model),
            schedule,
            prepared: Prepared::Sample,
            shard: Shard::WHOLE,
        }
    }

    /// The same ensemble with the truth `truth` (the filter and its schedule unchanged).
    pub fn with_truth(mut self, truth: TruthModel) -> Self {
        self.model = Cow::Owned(self.model.with_truth(truth));
        // The epoch engine's plan holds the truth's noise-free error: made again.
        let engine = self.engine();
        self.with_engine(engine)
    }

    /// The same ensemble simulated by `engine`.
    pub fn with_engine(mut self, engine: Engine) -> Self {
        self.prepared = Prepared::new(engine, &self.model, self.schedule);
        self
    }

    /// The same ensemble simulated by the epoch engine with `plan` in place of the model's own (a
    /// deliberately wrong plan shows that the engines' comparison can fail).
    pub fn with_epoch_plan(mut self, plan: EpochPlan) -> Self {
        self.prepared = Prepared::Epoch(plan);
        self
    }

    /// The same ensemble with `n` realizations.
    pub fn with_realizations(mut self, n: u64) -> Self {
        self.realizations = n;
        self
    }

    /// The same ensemble under `seed`.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Only `shard` of the ensemble.
    ///
    /// # Panics
    /// Unless 1 ≤ k ≤ m.
    pub fn with_shard(mut self, shard: Shard) -> Self {
        assert!(
            1 <= shard.index && shard.index <= shard.of,
            "shard {}/{} is not k/m with 1 ≤ k ≤ m",
            shard.index,
            shard.of
        );
        self.shard = shard;
        self
    }

    /// The simulated model (with the truth of [`Ensemble::with_truth`]).
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The filter's schedule.
    pub fn schedule(&self) -> &FilterSchedule {
        self.schedule
    }

    /// The engine.
    pub fn engine(&self) -> Engine {
        self.prepared.engine()
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// How the N realizations are cut into chunks and blocks.
    pub fn partition(&self) -> Partition {
        Partition::new(self.realizations)
    }

    /// The blocks this ensemble runs: its shard's.
    pub fn block_range(&self) -> Range<u64> {
        self.partition().shard_blocks(self.shard)
    }

    /// Which residual products the sums keep.
    pub fn layout(&self) -> ResidualLayout {
        ResidualLayout::new(self.model.timeline.fixes(), self.model.residual_max_lag())
    }

    /// Empty sums of this ensemble.
    fn empty_sums(&self) -> Accumulator {
        Accumulator::new(&self.layout(), self.model.residual_pair)
    }

    /// Runs the blocks of the shard in parallel and hands each block's sums to `on_block` with its
    /// index, in block order. `progress` is called with the number of realizations of the shard
    /// finished so far.
    pub fn blocks(
        &self,
        progress: impl FnMut(u64) + Send,
        on_block: impl FnMut(u64, &Accumulator) + Send,
    ) {
        // Without a flag nothing stops the run.
        let _ = workers::run_blocks(self, None, progress, on_block);
    }

    /// The sums of the shard's realizations, the fold of its blocks in block order; `progress` as
    /// in [`Ensemble::blocks`].
    pub fn sums(&self, progress: impl FnMut(u64) + Send) -> Accumulator {
        let mut total = self.empty_sums();
        self.blocks(progress, |_, block| total.merge(block));
        total
    }

    /// [`Ensemble::sums`] that stops when `cancel` is raised: no block starts after it, so the
    /// call returns within one block's time.
    ///
    /// # Errors
    /// [`Cancelled`] when `cancel` was raised before the last block was summed.
    pub fn try_sums(
        &self,
        cancel: &Cancel,
        progress: impl FnMut(u64) + Send,
    ) -> Result<Accumulator, Cancelled> {
        let mut total = self.empty_sums();
        workers::run_blocks(self, Some(cancel), progress, |_, block| total.merge(block))?;
        Ok(total)
    }

    /// The statistics of the shard's realizations and how fast they ran; `progress` as in
    /// [`Ensemble::blocks`].
    pub fn run(&self, progress: impl FnMut(u64) + Send) -> EnsembleRun {
        let start = Instant::now();
        let sums = self.sums(progress);
        self.finish_run(&sums, start)
    }

    /// [`Ensemble::run`] that stops when `cancel` is raised, as [`Ensemble::try_sums`].
    ///
    /// # Errors
    /// [`Cancelled`] when `cancel` was raised before the last block was summed.
    pub fn try_run(
        &self,
        cancel: &Cancel,
        progress: impl FnMut(u64) + Send,
    ) -> Result<EnsembleRun, Cancelled> {
        let start = Instant::now();
        let sums = self.try_sums(cancel, progress)?;
        Ok(self.finish_run(&sums, start))
    }

    fn finish_run(&self, sums: &Accumulator, start: Instant) -> EnsembleRun {
        let elapsed_s = start.elapsed().as_secs_f64();
        EnsembleRun {
            stats: EnsembleStats::from_sums(sums, self.schedule),
            elapsed_s,
            engine: self.engine(),
        }
    }

    /// The sums of realizations `range` in one piece, on this thread.
    #[cfg(test)]
    fn sums_of(&self, range: Range<u64>) -> Accumulator {
        let mut sums = self.empty_sums();
        engine::accumulate_into(self, range, &mut sums, &mut engine::Scratch::default());
        sums
    }
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

#[cfg(test)]
mod tests;
