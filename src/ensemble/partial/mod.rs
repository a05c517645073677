//! Partial sums of a shard of an ensemble, as a file, and their merge.
//!
//! A partial file holds the sums of the blocks of one shard (see [`super::Partition`]):
//!
//! 1. the line `accelcal-partial 2`;
//! 2. a JSON header line describing the ensemble and the shard ([`PartialHeader`]);
//! 3. the line `sha256 <64 hex digits>`: the SHA-256 digest of lines 1 and 2, the *header
//!    digest*;
//! 4. for every block of the shard: its index and its realization count as little-endian 64-bit
//!    integers, its sums as little-endian 64-bit floats in a fixed order, then the 32-byte
//!    SHA-256 digest of the header digest followed by those bytes.
//!
//! Floats are stored bit for bit, so merging the shards in block order gives the sums of one run,
//! number for number ([`merge()`]). The digests make any damage (one changed bit anywhere) or an
//! edit of the header a refusal rather than wrong numbers: each block's digest is keyed with the
//! header digest, so a header edited and given a new digest of its own no longer matches any
//! block, and the configuration it reports stays bound to the data made with it. A digest is a
//! check against accidents and casual edits, not a signature: whoever recomputes every digest on
//! purpose can forge a file.

use std::io::{BufRead, Read, Write};

use serde::{Deserialize, Serialize};

mod digest;
mod frame;
mod merge;

use super::Engine;
use super::layout::ResidualLayout;
use super::sums::{Accumulator, FixSums, StageSums};
use crate::config::Config;
use crate::state::ErrorState;
pub use digest::HeaderDigest;
pub use frame::{
    ONE_AXIS, header_model, read_block_floats, read_header_line, write_blocks, write_header,
};
pub use merge::{Merged, each_shard_once, first_difference, merge};
use nalgebra::SMatrix;

const MEAS: usize = ErrorState::MEAS;

/// The version of the partial file format this accelcal writes and reads.
pub const FORMAT: u32 = 2;

/// The first line of every partial file.
pub const MAGIC: &str = "accelcal-partial 2\n";

/// The first line of a partial file of the first format, whose blocks had no digests.
const MAGIC_1: &str = "accelcal-partial 1\n";

/// The longest header line read, bytes: a configuration is a few kilobytes, and an input that is
/// not a partial file (a device such as `/dev/zero`) must not be read without bound.
pub const MAX_HEADER_BYTES: u64 = 1 << 20;

/// Bytes of a SHA-256 digest.
pub const DIGEST_BYTES: usize = 32;

/// What a partial file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialHeader {
    /// accelcal version that wrote it.
    pub accelcal_version: String,
    /// The whole configuration of the ensemble (seed, N, case included).
    pub config: Config,
    /// Shard k, counted from 1.
    pub shard: u64,
    /// Number of shards m.
    pub shards: u64,
    /// The blocks of this shard, [first, end).
    pub blocks: [u64; 2],
    /// Fixes per realization.
    pub fixes: usize,
    /// The residual lag kept (`None`: every pair).
    pub max_lag: Option<usize>,
    /// The fix indices [m, i] of the single residual pair.
    pub pair: [usize; 2],
    /// Wall-clock time of the shard's realizations, s.
    pub elapsed_s: f64,
    /// The engine that simulated the realizations (files without it were written by the
    /// per-sample engine).
    #[serde(default)]
    pub engine: Engine,
}

impl PartialHeader {
    /// Floats of the sums of one block: per fix, the a priori and a posteriori stages' sums and
    /// Σ NIS; the kept residual products; the single residual pair's products.
    fn block_floats(&self) -> usize {
        let layout = ResidualLayout::new(self.fixes, self.max_lag);
        self.fixes * FIX_LEN + layout.len() + PAIR_LEN
    }

    /// Bytes of one block without its digest: index, count and sums.
    pub fn block_bytes(&self) -> usize {
        16 + 8 * self.block_floats()
    }
}

/// A partial file that cannot be read or does not belong with the others.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    /// The file cannot be opened or read.
    #[error("{file}: cannot read: {why}")]
    Unreadable {
        /// The file.
        file: String,
        /// The operating system's error.
        why: String,
    },
    /// The file is not a partial file of this version.
    #[error("{file}: not an accelcal partial file (format {FORMAT}): {why}")]
    Format {
        /// The file.
        file: String,
        /// What is wrong.
        why: String,
    },
    /// A part of the file does not match its digest: changed since it was written.
    #[error("{file}: damaged or edited: {why}")]
    Damaged {
        /// The file.
        file: String,
        /// Which part does not match.
        why: String,
    },
    /// The file ends before its last block.
    #[error("{file}: truncated: {why}")]
    Truncated {
        /// The file.
        file: String,
        /// What is missing.
        why: String,
    },
    /// The file belongs to another ensemble, or repeats a shard, or holds values that are not
    /// sums.
    #[error("{file}: {why}")]
    Mismatch {
        /// The file.
        file: String,
        /// What differs.
        why: String,
    },
    /// No file holds a shard.
    #[error("shard {shard}/{shards} is missing: the files given hold {given}")]
    Missing {
        /// The shard k missing.
        shard: u64,
        /// The number of shards m.
        shards: u64,
        /// Which file holds which shard.
        given: String,
    },
}

/// Floats of one stage's sums.
const STAGE_LEN: usize = <StageSums>::FLOATS;
/// Floats of one fix's sums: the a priori stage's, the a posteriori stage's, Σ NIS.
const FIX_LEN: usize = <FixSums>::FLOATS;
/// Floats of the single residual pair's products.
const PAIR_LEN: usize = MEAS * MEAS;

/// Block `index`'s bytes without their digest: index, realization count, sums.
pub fn encode_block(index: u64, acc: &Accumulator) -> Vec<u8> {
    let mut floats =
        Vec::with_capacity(acc.fixes.len() * FIX_LEN + acc.residual_products.len() + PAIR_LEN);
    for f in &acc.fixes {
        f.prior.write_floats(&mut floats);
        f.post.write_floats(&mut floats);
        floats.push(f.nis);
    }
    floats.extend(&acc.residual_products);
    // Row-major (j, k).
    floats.extend(acc.pair_products.transpose().iter());
    let mut bytes = Vec::with_capacity(16 + 8 * floats.len());
    bytes.extend_from_slice(&index.to_le_bytes());
    bytes.extend_from_slice(&acc.count.to_le_bytes());
    for x in floats {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    bytes
}

/// Writes block `index`'s sums and their digest keyed with the header digest `key`.
///
/// # Errors
/// The writer's error.
pub fn write_block(
    w: &mut impl Write,
    key: &HeaderDigest,
    index: u64,
    acc: &Accumulator,
) -> std::io::Result<()> {
    let bytes = encode_block(index, acc);
    w.write_all(&bytes)?;
    w.write_all(&key.of_block(&bytes))
}

/// Writes a whole partial file: `header`, then the blocks of `blocks`, a stream of
/// [`encode_block`] outputs (spooled while the shard ran, before its header was known), each with
/// its digest.
///
/// # Errors
/// The reader's or the writer's error; [`std::io::ErrorKind::InvalidData`] when `blocks` does
/// not hold whole blocks of `header`'s size.
pub fn write_partial(
    w: &mut impl Write,
    header: &PartialHeader,
    blocks: &mut impl Read,
) -> std::io::Result<()> {
    write_blocks(w, header, header.block_bytes(), blocks)
}

/// Reads the header of a one-axis partial file named `file` and checks it against its digest.
///
/// # Errors
/// As [`read_header_line`]; [`PartialError::Mismatch`] when it is a three-axis partial.
pub fn read_header(
    r: &mut impl BufRead,
    file: &str,
) -> Result<(PartialHeader, HeaderDigest), PartialError> {
    let (json, digest) = read_header_line(r, file)?;
    let model = header_model(&json);
    if model != ONE_AXIS {
        return Err(PartialError::Mismatch {
            file: file.to_string(),
            why: format!("a partial of the {model} model, not of the one-axis ensemble"),
        });
    }
    let header = serde_json::from_slice(&json).map_err(|e| PartialError::Format {
        file: file.to_string(),
        why: format!("header: {e}"),
    })?;
    Ok((header, digest))
}

/// Reads the next block of a partial file with `header` and header digest `key`, checked
/// against its digest; `None` at the end of the file. `position` is the block expected there,
/// for messages.
///
/// # Errors
/// As [`read_block_floats`].
pub fn read_block(
    r: &mut impl Read,
    header: &PartialHeader,
    key: &HeaderDigest,
    file: &str,
    position: u64,
) -> Result<Option<(u64, Accumulator)>, PartialError> {
    Ok(
        read_block_floats(r, header.block_bytes(), key, file, position)?
            .map(|(index, count, floats)| (index, decode_sums(header, count, &floats))),
    )
}

/// The sums of a block of `count` realizations from its `floats`, in the order of
/// [`encode_block`].
fn decode_sums(header: &PartialHeader, count: u64, floats: &[f64]) -> Accumulator {
    let layout = ResidualLayout::new(header.fixes, header.max_lag);
    let mut acc = Accumulator::new(&layout, header.pair);
    acc.count = count;
    for (i, f) in acc.fixes.iter_mut().enumerate() {
        let v = &floats[i * FIX_LEN..(i + 1) * FIX_LEN];
        *f = FixSums {
            prior: StageSums::from_floats(&v[..STAGE_LEN]),
            post: StageSums::from_floats(&v[STAGE_LEN..2 * STAGE_LEN]),
            nis: v[2 * STAGE_LEN],
        };
    }
    let products = header.fixes * FIX_LEN;
    acc.residual_products
        .copy_from_slice(&floats[products..products + layout.len()]);
    let pair = &floats[products + layout.len()..];
    acc.pair_products = SMatrix::from_row_slice(&pair[..PAIR_LEN]);
    acc
}

#[cfg(test)]
mod tests;
