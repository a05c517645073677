//! Partial sums of a shard of an ensemble, as a file, and their merge.
//!
//! A partial file holds the sums of the blocks of one shard (see [`super::Partition`]): a line
//! `accelcal-partial 1`, a JSON header line describing the ensemble and the shard, then for every
//! block its index and its sums as little-endian 64-bit floats, in a fixed order. Floats are
//! stored bit for bit, so merging the shards in block order gives the sums of one run, number for
//! number.

use std::io::{Read, Write};

use serde::{Deserialize, Serialize};

use super::Engine;
use super::layout::ResidualLayout;
use super::sums::{Accumulator, FixSums, StageSums};
use crate::config::Config;
use crate::state::ErrorState;
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

/// Floats of one fix's sums.
const FIX_LEN: usize = 2 * <StageSums>::FLOATS + 1;

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
        Vec::with_capacity(acc.fixes.len() * FIX_LEN + acc.residual_products.len() + MEAS * MEAS);
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
    let len = header.fixes * FIX_LEN + layout.len() + 4;
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
            prior: <StageSums>::from_floats(&v[..<StageSums>::FLOATS]),
            post: <StageSums>::from_floats(&v[<StageSums>::FLOATS..2 * <StageSums>::FLOATS]),
            nis: v[2 * <StageSums>::FLOATS],
        };
    }
    let products = header.fixes * FIX_LEN;
    acc.residual_products
        .copy_from_slice(&floats[products..products + layout.len()]);
    let pair = &floats[products + layout.len()..];
    acc.pair_products = SMatrix::from_row_slice(&pair[..MEAS * MEAS]);
    Ok(Some((index, acc)))
}

/// The dotted path of the first field where `a` and `b` differ.
fn first_difference(a: &Config, b: &Config) -> String {
    fn walk(a: &serde_json::Value, b: &serde_json::Value, path: &str) -> Option<String> {
        match (a, b) {
            (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                keys.into_iter().find_map(|k| {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    match (x.get(k), y.get(k)) {
                        (Some(u), Some(v)) => walk(u, v, &p),
                        _ => Some(p),
                    }
                })
            }
            _ => (a != b).then(|| path.to_string()),
        }
    }
    let value = |c: &Config| serde_json::to_value(c).expect("a configuration serializes");
    walk(&value(a), &value(b), "").unwrap_or_default()
}

/// The merged sums of every shard of one ensemble.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The ensemble's configuration.
    pub config: Config,
    /// The sums of the whole ensemble, folded in block order.
    pub sums: Accumulator,
    /// The shards' run times added up, s.
    pub elapsed_s: f64,
    /// The engine that simulated the realizations.
    pub engine: Engine,
}

/// Reads the partial files `files` (name and reader, any order), checks that they are every
/// shard of one ensemble exactly once, and folds their blocks in block order.
///
/// # Errors
/// [`PartialError`] naming the file that is unreadable, truncated, of another ensemble, or a
/// repeated shard; or, naming the first file, a missing shard.
pub fn merge<R: std::io::BufRead>(files: Vec<(String, R)>) -> Result<Merged, PartialError> {
    let mut opened = Vec::with_capacity(files.len());
    for (name, mut r) in files {
        let header = read_header(&mut r, &name)?;
        opened.push((name, header, r));
    }
    let Some((first_name, first, _)) = opened.first() else {
        return Err(PartialError::Mismatch {
            file: "(none)".to_string(),
            why: "no partial file given".to_string(),
        });
    };
    let (first_name, first) = (first_name.clone(), first.clone());
    let mismatch = |file: &str, why: String| PartialError::Mismatch {
        file: file.to_string(),
        why,
    };
    for (name, h, _) in &opened {
        if h.config != first.config {
            let what = if h.config.ensemble.seed != first.config.ensemble.seed {
                format!(
                    "seed {} differs from {first_name}'s {}",
                    h.config.ensemble.seed, first.config.ensemble.seed
                )
            } else if h.config.ensemble.realizations != first.config.ensemble.realizations {
                format!(
                    "N = {} differs from {first_name}'s {}",
                    h.config.ensemble.realizations, first.config.ensemble.realizations
                )
            } else {
                format!(
                    "its configuration differs from {first_name}'s at `{}`",
                    first_difference(&h.config, &first.config)
                )
            };
            return Err(mismatch(name, format!("another ensemble: {what}")));
        }
        if h.engine != first.engine {
            return Err(mismatch(
                name,
                format!(
                    "simulated by the {} engine, {first_name} by the {} engine",
                    h.engine, first.engine
                ),
            ));
        }
        if h.shards != first.shards {
            return Err(mismatch(
                name,
                format!(
                    "shard {}/{} of another split than {first_name}'s /{}",
                    h.shard, h.shards, first.shards
                ),
            ));
        }
        if h.accelcal_version != first.accelcal_version {
            return Err(mismatch(
                name,
                format!(
                    "written by accelcal {}, {first_name} by {}",
                    h.accelcal_version, first.accelcal_version
                ),
            ));
        }
    }
    opened.sort_by_key(|(_, h, _)| h.shard);
    for pair in opened.windows(2) {
        if pair[0].1.shard == pair[1].1.shard {
            return Err(mismatch(
                &pair[1].0,
                format!(
                    "shard {}/{} is given twice (also {})",
                    pair[1].1.shard, first.shards, pair[0].0
                ),
            ));
        }
    }
    let present: Vec<u64> = opened.iter().map(|(_, h, _)| h.shard).collect();
    if let Some(missing) = (1..=first.shards).find(|k| !present.contains(k)) {
        return Err(mismatch(
            &first_name,
            format!("shard {missing}/{} is missing", first.shards),
        ));
    }
    let n = first.config.ensemble.realizations;
    let partition = super::Partition::new(n);
    let layout = ResidualLayout::new(first.fixes, first.max_lag);
    let mut sums = Accumulator::new(&layout, first.pair);
    let mut elapsed_s = 0.0;
    for (name, h, mut r) in opened {
        let expected = partition.shard_blocks(h.shard, h.shards);
        if h.blocks != [expected.start, expected.end]
            || (h.fixes, h.max_lag, h.pair) != (first.fixes, first.max_lag, first.pair)
        {
            return Err(mismatch(
                &name,
                "its blocks are not those of its shard".to_string(),
            ));
        }
        for b in expected {
            let Some((index, block)) = read_block(&mut r, &h, &name)? else {
                return Err(PartialError::Truncated {
                    file: name,
                    why: format!("block {b} is missing"),
                });
            };
            let count = partition.realizations_in(&(b..b + 1));
            if index != b || block.count != count {
                return Err(mismatch(
                    &name,
                    format!(
                        "block {index} with {} realizations where block {b} with {count} belongs",
                        block.count
                    ),
                ));
            }
            sums.merge(&block);
        }
        if read_block(&mut r, &h, &name)?.is_some() {
            return Err(mismatch(
                &name,
                "more blocks than its shard holds".to_string(),
            ));
        }
        elapsed_s += h.elapsed_s;
    }
    Ok(Merged {
        config: first.config,
        sums,
        elapsed_s,
        engine: first.engine,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::ensemble::accumulate;
    use crate::filter::FilterSchedule;
    use crate::model::Model;

    #[test]
    fn blocks_read_back_bit_for_bit() {
        let mut c = Config::default();
        c.profile.duration_s = 2.0;
        c.checks.residual_max_lag = Some(3);
        let m = Model::new(&c).unwrap();
        let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
        let acc = accumulate(&m, &s, 3, 0..20);
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
