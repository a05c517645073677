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
mod merge;

use super::Engine;
use super::layout::ResidualLayout;
use super::sums::{Accumulator, FixSums, StageSums};
use crate::config::Config;
use crate::state::ErrorState;
pub use digest::HeaderDigest;
pub use merge::{Merged, merge};
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

/// Writes the header of a partial file: the magic line, the header line and its digest line.
/// Returns the header digest, which keys the digest of every block ([`write_block`]).
///
/// # Errors
/// The writer's error.
pub fn write_header(w: &mut impl Write, header: &PartialHeader) -> std::io::Result<HeaderDigest> {
    let mut json = serde_json::to_string(header).expect("a header serializes");
    json.push('\n');
    let digest = HeaderDigest::of(MAGIC.as_bytes(), json.as_bytes());
    w.write_all(MAGIC.as_bytes())?;
    w.write_all(json.as_bytes())?;
    w.write_all(digest.line().as_bytes())?;
    Ok(digest)
}

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
    let key = write_header(w, header)?;
    let mut block = vec![0u8; header.block_bytes()];
    loop {
        match read_whole(blocks, &mut block)? {
            0 => return Ok(()),
            n if n == block.len() => {}
            _ => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    "the spooled blocks end inside a block",
                ));
            }
        }
        w.write_all(&block)?;
        w.write_all(&key.of_block(&block))?;
    }
}

/// Fills `buf` from `r` as far as `r` goes; the bytes read (fewer than `buf.len()` only at the
/// end of `r`).
fn read_whole(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match r.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// Reads one line of at most `limit` bytes (its line end included) as raw bytes; `None` when
/// the line is longer or has no line end.
fn read_line_within(r: &mut impl BufRead, limit: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut line = Vec::new();
    r.take(limit).read_until(b'\n', &mut line)?;
    Ok(line.ends_with(b"\n").then_some(line))
}

/// Reads the header of a partial file named `file` and checks it against its digest.
///
/// # Errors
/// [`PartialError::Format`] when the file is not a partial file of this format;
/// [`PartialError::Damaged`] when its header does not match its digest;
/// [`PartialError::Unreadable`] when reading fails.
pub fn read_header(
    r: &mut impl BufRead,
    file: &str,
) -> Result<(PartialHeader, HeaderDigest), PartialError> {
    let format = |why: &str| PartialError::Format {
        file: file.to_string(),
        why: why.to_string(),
    };
    let unreadable = |e: std::io::Error| PartialError::Unreadable {
        file: file.to_string(),
        why: e.to_string(),
    };
    let magic = read_line_within(r, MAGIC.len() as u64).map_err(unreadable)?;
    if magic.as_deref() == Some(MAGIC_1.as_bytes()) {
        return Err(format(&format!(
            "it is of format 1, written by an earlier accelcal without digests; run its shard \
             again with this accelcal (format {FORMAT})"
        )));
    }
    if magic.as_deref() != Some(MAGIC.as_bytes()) {
        return Err(format("the first line is not `accelcal-partial 2`"));
    }
    let Some(json) = read_line_within(r, MAX_HEADER_BYTES).map_err(unreadable)? else {
        return Err(format(&format!(
            "its header line does not end within {MAX_HEADER_BYTES} bytes"
        )));
    };
    let line = read_line_within(r, 8 + 2 * DIGEST_BYTES as u64).map_err(unreadable)?;
    let said = line
        .as_deref()
        .and_then(|l| std::str::from_utf8(l).ok())
        .and_then(HeaderDigest::parse_line);
    let Some(said) = said else {
        return Err(PartialError::Damaged {
            file: file.to_string(),
            why: "the header's digest line is not `sha256 <64 lower-case hex digits>`".to_string(),
        });
    };
    let digest = HeaderDigest::of(MAGIC.as_bytes(), &json);
    if digest != said {
        return Err(PartialError::Damaged {
            file: file.to_string(),
            why: "its header does not match the digest written with it (the configuration or \
                  the shard in it was changed, or the file damaged)"
                .to_string(),
        });
    }
    let header = serde_json::from_slice(&json).map_err(|e| format(&format!("header: {e}")))?;
    Ok((header, digest))
}

/// Reads the next block of a partial file with `header` and header digest `key`, checked
/// against its digest; `None` at the end of the file. `position` is the block expected there,
/// for messages.
///
/// # Errors
/// [`PartialError::Truncated`] when the file ends inside a block; [`PartialError::Damaged`] when
/// the block does not match its digest; [`PartialError::Mismatch`] when a sum is not finite.
pub fn read_block(
    r: &mut impl Read,
    header: &PartialHeader,
    key: &HeaderDigest,
    file: &str,
    position: u64,
) -> Result<Option<(u64, Accumulator)>, PartialError> {
    let truncated = |why: String| PartialError::Truncated {
        file: file.to_string(),
        why,
    };
    let mut bytes = vec![0u8; header.block_bytes() + DIGEST_BYTES];
    let read = read_whole(r, &mut bytes).map_err(|e| PartialError::Unreadable {
        file: file.to_string(),
        why: e.to_string(),
    })?;
    // The end of the file is allowed only between blocks.
    match read {
        0 => return Ok(None),
        n if n < bytes.len() => {
            return Err(truncated(format!(
                "block {position} is cut after {n} of its {} bytes",
                bytes.len()
            )));
        }
        _ => {}
    }
    let (block, digest) = bytes.split_at(header.block_bytes());
    if key.of_block(block) != digest {
        return Err(PartialError::Damaged {
            file: file.to_string(),
            why: format!(
                "block {position} does not match the digest written with it (a changed bit, or \
                 sums made with another header)"
            ),
        });
    }
    let word = |i: usize| u64::from_le_bytes(block[8 * i..8 * i + 8].try_into().expect("8 bytes"));
    let (index, count) = (word(0), word(1));
    let floats: Vec<f64> = block[16..]
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    if let Some((i, x)) = floats.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(PartialError::Mismatch {
            file: file.to_string(),
            why: format!(
                "block {index} holds a sum that is not finite ({x} at float {i} of {}): the \
                 shard's computation overflowed, and it cannot be merged",
                floats.len()
            ),
        });
    }
    Ok(Some((index, decode_sums(header, count, &floats))))
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
