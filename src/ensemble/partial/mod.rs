//! Partial sums of a shard of an ensemble, as a file, and their merge.
//!
//! A partial file holds the sums of the blocks of one shard (see [`super::Partition`]): a line
//! `accelcal-partial 1`, a JSON header line describing the ensemble and the shard, then for every
//! block its index and its sums as little-endian 64-bit floats, in a fixed order. Floats are
//! stored bit for bit, so merging the shards in block order gives the sums of one run, number for
//! number ([`merge()`]).

use std::io::{Read, Write};

use serde::{Deserialize, Serialize};

mod merge;

use super::Engine;
use super::layout::ResidualLayout;
use super::sums::{Accumulator, FixSums, StageSums};
use crate::config::Config;
use crate::state::ErrorState;
pub use merge::{Merged, merge};
use nalgebra::SMatrix;

const MEAS: usize = ErrorState::MEAS;

/// The first line of every partial file.
pub const MAGIC: &str = "accelcal-partial 1\n";

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

/// A partial file that cannot be read or does not belong with the others.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    /// The file is not a partial file of this version.
    #[error("{file}: not an accelcal partial file (version 1): {why}")]
    Format {
        /// The file.
        file: String,
        /// What is wrong.
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
    /// The file belongs to another ensemble, or repeats or misses a shard.
    #[error("{file}: {why}")]
    Mismatch {
        /// The file.
        file: String,
        /// What differs.
        why: String,
    },
}

/// Floats of one stage's sums.
const STAGE_LEN: usize = <StageSums>::FLOATS;
/// Floats of one fix's sums: the a priori stage's, the a posteriori stage's, Σ NIS.
const FIX_LEN: usize = <FixSums>::FLOATS;
/// Floats of the single residual pair's products.
const PAIR_LEN: usize = MEAS * MEAS;

/// Writes the header of a partial file.
///
/// # Errors
/// The writer's error.
pub fn write_header(w: &mut impl Write, header: &PartialHeader) -> std::io::Result<()> {
    w.write_all(MAGIC.as_bytes())?;
    let json = serde_json::to_string(header).expect("a header serializes");
    w.write_all(json.as_bytes())?;
    w.write_all(b"\n")
}

/// Writes block `index`'s sums.
///
/// # Errors
/// The writer's error.
pub fn write_block(w: &mut impl Write, index: u64, acc: &Accumulator) -> std::io::Result<()> {
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
    w.write_all(&index.to_le_bytes())?;
    w.write_all(&acc.count.to_le_bytes())?;
    let mut bytes = Vec::with_capacity(8 * floats.len());
    for x in floats {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    w.write_all(&bytes)
}

/// Reads the header of a partial file named `file`.
///
/// # Errors
/// [`PartialError::Format`] when the file is not a partial file.
pub fn read_header(
    r: &mut impl std::io::BufRead,
    file: &str,
) -> Result<PartialHeader, PartialError> {
    let format = |why: String| PartialError::Format {
        file: file.to_string(),
        why,
    };
    let mut magic = String::new();
    r.read_line(&mut magic).map_err(|e| format(e.to_string()))?;
    if magic != MAGIC {
        return Err(format(
            "the first line is not `accelcal-partial 1`".to_string(),
        ));
    }
    let mut json = String::new();
    r.read_line(&mut json).map_err(|e| format(e.to_string()))?;
    serde_json::from_str(&json).map_err(|e| format(format!("header: {e}")))
}

/// Reads the next block of a partial file with `header`; `None` at the end of the file.
///
/// # Errors
/// [`PartialError::Truncated`] when the file ends inside a block.
pub fn read_block(
    r: &mut impl Read,
    header: &PartialHeader,
    file: &str,
) -> Result<Option<(u64, Accumulator)>, PartialError> {
    let truncated = |why: &str| PartialError::Truncated {
        file: file.to_string(),
        why: why.to_string(),
    };
    let mut word = [0u8; 8];
    // The end of the file is allowed only between blocks.
    match r.read(&mut word[..1]) {
        Ok(0) => return Ok(None),
        Ok(_) => {}
        Err(e) => return Err(truncated(&e.to_string())),
    }
    r.read_exact(&mut word[1..])
        .map_err(|_| truncated("a block index is cut"))?;
    let index = u64::from_le_bytes(word);
    r.read_exact(&mut word)
        .map_err(|_| truncated("a block count is cut"))?;
    let count = u64::from_le_bytes(word);
    let layout = ResidualLayout::new(header.fixes, header.max_lag);
    let len = header.fixes * FIX_LEN + layout.len() + PAIR_LEN;
    let mut bytes = vec![0u8; 8 * len];
    r.read_exact(&mut bytes)
        .map_err(|_| truncated(&format!("block {index} is cut")))?;
    let floats: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
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
    Ok(Some((index, acc)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::ensemble::Ensemble;
    use crate::filter::FilterSchedule;
    use crate::model::Model;

    #[test]
    fn blocks_read_back_bit_for_bit() {
        let mut c = Config::default();
        c.profile.duration_s = 2.0;
        c.checks.residual_max_lag = Some(3);
        let m = Model::new(&c).unwrap();
        let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
        let acc = Ensemble::new(&m, &s).with_seed(3).sums_of(0..20);
        let header = PartialHeader {
            accelcal_version: "test".to_string(),
            config: c.clone(),
            shard: 1,
            shards: 1,
            blocks: [0, 1],
            fixes: m.timeline.fixes(),
            max_lag: Some(3),
            pair: m.residual_pair,
            elapsed_s: 0.5,
            engine: Engine::Sample,
        };
        let mut bytes = Vec::new();
        write_header(&mut bytes, &header).unwrap();
        write_block(&mut bytes, 7, &acc).unwrap();
        let mut r = std::io::BufReader::new(&bytes[..]);
        assert_eq!(read_header(&mut r, "f").unwrap(), header);
        let (index, back) = read_block(&mut r, &header, "f").unwrap().unwrap();
        assert_eq!((index, &back), (7, &acc));
        assert!(read_block(&mut r, &header, "f").unwrap().is_none());
        // A file cut inside a block is an error, not a short ensemble.
        let mut r = std::io::BufReader::new(&bytes[..bytes.len() - 3]);
        read_header(&mut r, "f").unwrap();
        assert!(matches!(
            read_block(&mut r, &header, "f"),
            Err(PartialError::Truncated { .. })
        ));
    }
}
