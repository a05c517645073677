//! How the three-axis ensemble is cut and folded: chunks of [`CHUNK`] realizations run side by
//! side, blocks of whole chunks each summed from zero in index order, and the blocks folded in
//! block order ([`super::ensemble::run_blocks`]). A shard runs whole blocks, so shards merged in
//! block order make the same additions in the same order as one run (`accelcal merge`,
//! docs/CLUSTER.md).

use std::ops::Range;

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
