//! How the three-axis ensemble is cut and folded: chunks of [`CHUNK`] realizations run side by
//! side, blocks of whole chunks each summed from zero in index order, and the blocks folded in
//! block order. A shard runs whole blocks, so shards merged in block order make the same
//! additions in the same order as one run (`accelcal merge`, docs/CLUSTER.md).

use std::ops::Range;

use rayon::prelude::*;

use super::ensemble::{InsSums, Normalized, RealizationError, Track, empty_sums, realization};
use super::setup::Study;
use crate::ensemble::Shard;

/// Realizations run side by side before they are folded into the sums, in index order (each
/// holds its normalized fixes until then: 2.5 MB for the default drive).
pub const CHUNK: u64 = 16;

/// Largest number of blocks. A block's sums of the default drive take 11 MB in a partial file,
/// so the partials of a whole ensemble stay within 32 blocks' (350 MB), whatever N is.
pub const MAX_BLOCKS: u64 = 32;

/// How the N realizations of a three-axis ensemble are grouped, by N alone: chunks of
/// [`CHUNK`] consecutive indices, B = ⌈C / P⌉ blocks of P = ⌈C / [`MAX_BLOCKS`]⌉ consecutive
/// chunks each (C chunks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Blocks {
    /// Realizations N.
    pub realizations: u64,
    /// Chunks C = ⌈N / CHUNK⌉.
    pub chunks: u64,
    /// Chunks per block P.
    pub chunks_per_block: u64,
    /// Blocks B, at most [`MAX_BLOCKS`].
    pub blocks: u64,
}

impl Blocks {
    /// The blocks of `n` realizations.
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

    /// The realization indices of block `b`.
    pub fn realizations_of(&self, b: u64) -> Range<u64> {
        let per_block = self.chunks_per_block * CHUNK;
        (b * per_block).min(self.realizations)..((b + 1) * per_block).min(self.realizations)
    }

    /// The blocks of `shard` k of m: blocks ⌊(k − 1)·B/m⌋ up to ⌊k·B/m⌋.
    pub fn of_shard(&self, shard: Shard) -> Range<u64> {
        let Shard { index: k, of: m } = shard;
        (k - 1) * self.blocks / m..k * self.blocks / m
    }
}

/// The sums of each block of `range` of an ensemble of `study` cut as `blocks`, handed to
/// `on_block` in block order; `progress` is told how many realizations are done after every
/// chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn run_blocks(
    study: &Study,
    track: &Track,
    blocks: &Blocks,
    range: Range<u64>,
    mut progress: impl FnMut(u64),
    mut on_block: impl FnMut(u64, &InsSums),
) -> Result<(), RealizationError> {
    let mut done = 0;
    for b in range {
        let mut sums = empty_sums(study, track);
        let indices = blocks.realizations_of(b);
        let mut first = indices.start;
        while first < indices.end {
            let last = (first + CHUNK).min(indices.end);
            let chunk: Vec<Result<Normalized, RealizationError>> = (first..last)
                .into_par_iter()
                .map(|l| realization(study, track, l))
                .collect();
            for r in chunk {
                sums.add(&r?);
            }
            done += last - first;
            first = last;
            progress(done);
        }
        on_block(b, &sums);
    }
    Ok(())
}

/// The sums of the whole ensemble of `realizations` realizations of `study`: its blocks folded
/// in block order; `progress` is told how many are done after every chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn sums(
    study: &Study,
    track: &Track,
    realizations: u64,
    progress: impl FnMut(u64),
) -> Result<InsSums, RealizationError> {
    let blocks = Blocks::new(realizations);
    let mut total = empty_sums(study, track);
    run_blocks(study, track, &blocks, 0..blocks.blocks, progress, |_, s| {
        total.merge(s);
    })?;
    Ok(total)
}
