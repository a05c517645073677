//! How the three-axis ensemble is cut and folded: chunks of [`CHUNK`] realizations run side by
//! side, blocks of whole chunks each summed from zero in index order, and the blocks folded in
//! block order ([`super::ensemble::run_blocks`]). A shard runs whole blocks, so shards merged in
//! block order make the same additions in the same order as one run (`accelcal merge`,
//! docs/CLUSTER.md).

use crate::ensemble::Partition;

/// Realizations run side by side before they are folded into the sums, in index order (each
/// holds its normalized fixes until then: 2.5 MB for the default drive).
pub const CHUNK: u64 = 16;

/// Largest number of blocks. A block's sums of the default drive take 11 MB in a partial file,
/// so the partials of a whole ensemble stay within 32 blocks' (350 MB), whatever N is.
pub const MAX_BLOCKS: u64 = 32;

/// How the N realizations of a three-axis ensemble are grouped, by N alone: chunks of
/// [`CHUNK`] consecutive indices, B = ⌈C / P⌉ blocks of P = ⌈C / [`MAX_BLOCKS`]⌉ consecutive
/// chunks each (C chunks) — the one-axis ensemble's [`Partition`] with these sizes.
pub fn partition(n: u64) -> Partition {
    Partition::with_sizes(n, CHUNK, MAX_BLOCKS)
}
