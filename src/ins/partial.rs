//! A shard of the three-axis ensemble as a partial file, and the merge of every shard's file into
//! the sums of one run.
//!
//! The file is the one-axis ensemble's format ([`crate::ensemble::partial`]: magic line, JSON
//! header, its SHA-256 digest, blocks each with a digest keyed with the header's); its header
//! says `"model": "ins"` and holds the three-axis configuration. A block holds, after its index
//! and realization count, as little-endian 64-bit floats: per fix, the normalized sums
//! ([`FixSums::FLOATS`]) and Σ R a priori and a posteriori (column-major); the kept residual
//! products; the single residual pair's products (column-major); Σ e², Σ σ² and the within-95 %
//! counts at the last fix; each over the configuration's error state (15, or 21 with the scale
//! factors).

use std::io::{BufRead, Read};

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use super::blocks;
use super::ensemble::{InsSums, MEASURED, Track, empty_sums};
use super::setup::Scenario;
use super::state::Layout;
use crate::config::ins::InsConfig;
use crate::ensemble::Partition;
use crate::ensemble::partial::{
    self, HeaderDigest, PartialError, each_shard_once, first_difference, header_model,
    read_block_floats, read_header_line,
};
use crate::ensemble::{FixSums, Shard, StageSums};

/// The `model` a three-axis partial's header names.
pub const MODEL: &str = "ins";

/// What a three-axis partial file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InsPartialHeader {
    /// accelcal version that wrote it.
    pub accelcal_version: String,
    /// Always [`MODEL`].
    pub model: String,
    /// The whole three-axis configuration (seed and N included).
    pub config: InsConfig,
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
    /// Wall-clock time of the shard's realizations, s.
    pub elapsed_s: f64,
}

/// Floats of one fix's sums in a block over an error state of `N`: the normalized sums and Σ R
/// of both stages.
const fn fix_len<const N: usize>() -> usize {
    FixSums::<N>::FLOATS + 2 * N * N
}

/// The error states of the filter `config` configures.
fn states_of(config: &InsConfig) -> usize {
    config.error_states()
}

impl InsPartialHeader {
    /// The header of shard `shard` (its `blocks`) of the ensemble configured by `config`,
    /// whose sums have the fixes and residual lag of `sums`, its realizations run in `elapsed_s`.
    pub fn new<const N: usize>(
        config: &InsConfig,
        sums: &InsSums<N>,
        shard: Shard,
        blocks: std::ops::Range<u64>,
        elapsed_s: f64,
    ) -> Self {
        Self {
            accelcal_version: env!("CARGO_PKG_VERSION").to_string(),
            model: MODEL.to_string(),
            config: config.clone(),
            shard: shard.index,
            shards: shard.of,
            blocks: [blocks.start, blocks.end],
            fixes: sums.normalized.times_s.len(),
            max_lag: sums.normalized.sums.layout.max_lag(),
            elapsed_s,
        }
    }

    /// Bytes of one block without its digest: index, count and sums.
    pub fn block_bytes(&self) -> usize {
        let products =
            crate::ensemble::ResidualLayout::with_width(self.fixes, MEASURED, self.max_lag).len();
        let layout = Layout::with_states(states_of(&self.config)).unwrap_or(Layout::CORE);
        let (fix, n) = crate::with_layout!(layout, N => (fix_len::<N>(), N));
        16 + 8 * (self.fixes * fix + products + MEASURED * MEASURED + 3 * n)
    }
}

/// Block `index`'s bytes without their digest: index, realization count, sums.
pub fn encode_block<const N: usize>(index: u64, sums: &InsSums<N>) -> Vec<u8> {
    let acc = &sums.normalized.sums;
    let mut floats = Vec::new();
    for (f, r) in acc.fixes.iter().zip(&sums.normalized.correlation) {
        f.prior.write_floats(&mut floats);
        f.post.write_floats(&mut floats);
        floats.push(f.nis);
        floats.extend(r[0].iter().chain(r[1].iter()));
    }
    floats.extend(&acc.residual_products);
    floats.extend(acc.pair_products.iter());
    floats.extend(sums.sq_error.iter().chain(sums.variance.iter()));
    // Counts below 2⁵³ are exact as floats.
    floats.extend(sums.within_95.iter().map(|&w| w as f64));
    let mut bytes = Vec::with_capacity(16 + 8 * floats.len());
    bytes.extend_from_slice(&index.to_le_bytes());
    bytes.extend_from_slice(&acc.count.to_le_bytes());
    for x in floats {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    bytes
}

/// Writes a whole partial file: `header`, then the blocks of `blocks`, a stream of
/// [`encode_block`] outputs, each with its digest.
///
/// # Errors
/// The reader's or the writer's error.
pub fn write_partial(
    w: &mut impl std::io::Write,
    header: &InsPartialHeader,
    blocks: &mut impl Read,
) -> std::io::Result<()> {
    partial::write_blocks(w, header, header.block_bytes(), blocks)
}

/// The sums of a block of `count` realizations from its `floats`, in [`encode_block`]'s order,
/// into `sums` (the ensemble's empty sums).
fn decode_block<const N: usize>(mut sums: InsSums<N>, count: u64, floats: &[f64]) -> InsSums<N> {
    let mut rest = floats;
    let mut take = |len: usize| {
        let (head, tail) = rest.split_at(len);
        rest = tail;
        head
    };
    let stage = StageSums::<N>::FLOATS;
    let n = &mut sums.normalized;
    n.sums.count = count;
    for (f, r) in n.sums.fixes.iter_mut().zip(&mut n.correlation) {
        f.prior = StageSums::from_floats(take(stage));
        f.post = StageSums::from_floats(take(stage));
        f.nis = take(1)[0];
        r[0] = SMatrix::from_column_slice(take(N * N));
        r[1] = SMatrix::from_column_slice(take(N * N));
    }
    let products = n.sums.residual_products.len();
    n.sums.residual_products.copy_from_slice(take(products));
    n.sums.pair_products = SMatrix::from_column_slice(take(MEASURED * MEASURED));
    sums.sq_error = SVector::from_column_slice(take(N));
    sums.variance = SVector::from_column_slice(take(N));
    for (w, x) in sums.within_95.iter_mut().zip(take(N)) {
        *w = *x as u64;
    }
    sums
}

/// The merged sums of every shard of one three-axis ensemble over `N` error states.
pub struct InsMerged<const N: usize> {
    /// The ensemble's configuration.
    pub config: InsConfig,
    /// The scenario it configures.
    pub scenario: Scenario,
    /// The sums of the whole ensemble, folded in block order.
    pub sums: InsSums<N>,
    /// The shards' run times added up, s.
    pub elapsed_s: f64,
}

/// The partial files of one three-axis ensemble, their headers read: [`Shards::layout`] says
/// which error state [`Shards::merge`] folds them over.
pub struct Shards<R> {
    opened: Vec<Opened<R>>,
    first: InsPartialHeader,
    first_name: String,
    scenario: Scenario,
}

/// A three-axis partial file whose header is read.
struct Opened<R> {
    name: String,
    header: InsPartialHeader,
    key: HeaderDigest,
    r: R,
}

fn mismatch(file: &str, why: String) -> PartialError {
    PartialError::Mismatch {
        file: file.to_string(),
        why,
    }
}

/// Reads the headers of the three-axis partial files `files` (name and reader, any order).
///
/// # Errors
/// [`PartialError`] naming the file that is unreadable, damaged or not a three-axis partial, or
/// whose configuration is not valid.
pub fn open<R: BufRead>(files: Vec<(String, R)>) -> Result<Shards<R>, PartialError> {
    let mut opened = Vec::with_capacity(files.len());
    for (name, mut r) in files {
        let (json, key) = read_header_line(&mut r, &name)?;
        let model = header_model(&json);
        if model != MODEL {
            return Err(mismatch(
                &name,
                format!("a partial of the {model} model, not of the three-axis ensemble (ins)"),
            ));
        }
        let header = serde_json::from_slice(&json).map_err(|e| PartialError::Format {
            file: name.clone(),
            why: format!("header: {e}"),
        })?;
        opened.push(Opened {
            name,
            header,
            key,
            r,
        });
    }
    let Some(first) = opened.first() else {
        return Err(mismatch("(none)", "no partial file given".to_string()));
    };
    let (first_name, first) = (first.name.clone(), first.header.clone());
    let scenario = Scenario::from_config(&first.config).map_err(|e| {
        mismatch(
            &first_name,
            format!("the configuration in its header is not valid: {e}"),
        )
    })?;
    Ok(Shards {
        opened,
        first,
        first_name,
        scenario,
    })
}

impl<R: BufRead> Shards<R> {
    /// The error state the ensemble's configuration names.
    pub fn layout(&self) -> Layout {
        self.scenario.layout()
    }

    /// Checks that the files are every shard of one ensemble exactly once and folds their
    /// blocks in block order, over `N` error states ([`Shards::layout`]'s size:
    /// [`with_layout!`](crate::with_layout)).
    ///
    /// # Errors
    /// [`PartialError`] naming the file that is damaged or edited (its digests), truncated, of
    /// another ensemble, or a repeated shard; or a missing shard, listing which file holds
    /// which shard; or a size `N` other than the configuration's.
    pub fn merge<const N: usize>(self) -> Result<InsMerged<N>, PartialError> {
        if N != self.layout().dim() {
            return Err(mismatch(
                &self.first_name,
                format!(
                    "its configuration names {} error states, not {N}",
                    self.layout().dim()
                ),
            ));
        }
        let (sums, elapsed_s) =
            fold::<R, N>(self.opened, &self.scenario, &self.first, &self.first_name)?;
        Ok(InsMerged {
            config: self.first.config,
            scenario: self.scenario,
            sums,
            elapsed_s,
        })
    }
}

/// The shards `opened`, checked against the first's header `first` (of `first_name`), folded
/// in block order into the sums of `scenario`'s ensemble over `N` error states; the shards' run
/// times added up.
fn fold<R: BufRead, const N: usize>(
    mut opened: Vec<Opened<R>>,
    scenario: &Scenario,
    first: &InsPartialHeader,
    first_name: &str,
) -> Result<(InsSums<N>, f64), PartialError> {
    let track = Track::of(scenario);
    let empty = empty_sums::<N>(scenario, &track);
    let made = InsPartialHeader::new(&first.config, &empty, Shard::WHOLE, 0..0, 0.0);
    if (made.fixes, made.max_lag) != (first.fixes, first.max_lag) {
        return Err(mismatch(
            first_name,
            format!(
                "its header is inconsistent: its configuration makes {} fixes and residual lag \
                 {:?}, the header says {} and {:?}",
                made.fixes, made.max_lag, first.fixes, first.max_lag
            ),
        ));
    }
    let blocks = blocks::partition(scenario.realizations);
    for o in &opened {
        if let Some(why) = differs(&o.header, first, first_name, &blocks) {
            return Err(mismatch(&o.name, why));
        }
    }
    opened.sort_by_key(|o| o.header.shard);
    let given: Vec<(&str, u64)> = opened
        .iter()
        .map(|o| (o.name.as_str(), o.header.shard))
        .collect();
    each_shard_once(&given, first.shards)?;
    let mut sums = empty.clone();
    let mut elapsed_s = 0.0;
    for o in opened {
        elapsed_s += fold_shard(o, &blocks, &empty, &mut sums)?;
    }
    Ok((sums, elapsed_s))
}

/// Why the shard `h` is not of the ensemble of `first` (the header of `first_name`), cut as
/// `blocks`, if it is not.
fn differs(
    h: &InsPartialHeader,
    first: &InsPartialHeader,
    first_name: &str,
    blocks: &Partition,
) -> Option<String> {
    let (c, f) = (&h.config.ensemble, &first.config.ensemble);
    if h.config != first.config {
        let what = if c.seed != f.seed {
            format!("seed {} differs from {first_name}'s {}", c.seed, f.seed)
        } else if c.realizations != f.realizations {
            format!(
                "N = {} differs from {first_name}'s {}",
                c.realizations, f.realizations
            )
        } else {
            format!(
                "its configuration differs from {first_name}'s at `{}`",
                first_difference(&h.config, &first.config)
            )
        };
        Some(format!("another ensemble: {what}"))
    } else if h.shards != first.shards {
        Some(format!(
            "shard {}/{} of another split than {first_name}'s /{}",
            h.shard, h.shards, first.shards
        ))
    } else if h.accelcal_version != first.accelcal_version {
        Some(format!(
            "written by accelcal {}, {first_name} by {}",
            h.accelcal_version, first.accelcal_version
        ))
    } else if !(1 <= h.shard && h.shard <= h.shards && h.shards <= blocks.blocks) {
        Some(format!(
            "its header says shard {}/{}, but a shard k/m has 1 ≤ k ≤ m ≤ {} (the blocks of \
             N = {})",
            h.shard, h.shards, blocks.blocks, blocks.realizations
        ))
    } else if (h.fixes, h.max_lag) != (first.fixes, first.max_lag) {
        Some("its header is inconsistent with its configuration".to_string())
    } else {
        None
    }
}

/// Adds the blocks of the shard `o` to `sums`, in block order, checking that they are the blocks
/// of its shard of `blocks`, each with its realizations; its run time.
fn fold_shard<R: BufRead, const N: usize>(
    o: Opened<R>,
    blocks: &Partition,
    empty: &InsSums<N>,
    sums: &mut InsSums<N>,
) -> Result<f64, PartialError> {
    let Opened {
        name,
        header,
        key,
        mut r,
    } = o;
    let expected = blocks.shard_blocks(Shard {
        index: header.shard,
        of: header.shards,
    });
    if header.blocks != [expected.start, expected.end] {
        return Err(mismatch(
            &name,
            "its blocks are not those of its shard".to_string(),
        ));
    }
    let bytes = header.block_bytes();
    for b in expected.clone() {
        let Some((index, count, floats)) = read_block_floats(&mut r, bytes, &key, &name, b)? else {
            return Err(PartialError::Truncated {
                file: name,
                why: format!("block {b} is missing"),
            });
        };
        let want = blocks.block_realizations(b);
        if index != b || count != want.end - want.start {
            return Err(mismatch(
                &name,
                format!(
                    "block {index} with {count} realizations where block {b} with {} belongs",
                    want.end - want.start
                ),
            ));
        }
        sums.merge(&decode_block(empty.clone(), count, &floats));
    }
    if read_block_floats(&mut r, bytes, &key, &name, expected.end)?.is_some() {
        return Err(mismatch(
            &name,
            "more blocks than its shard holds".to_string(),
        ));
    }
    Ok(header.elapsed_s)
}
