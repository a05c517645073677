//! The merge of the partial files of an ensemble's shards: every shard exactly once, folded in
//! block order into the sums of one run.

use super::{HeaderDigest, PartialError, PartialHeader, read_block, read_header};
use crate::config::Config;
use crate::ensemble::layout::ResidualLayout;
use crate::ensemble::sums::Accumulator;
use crate::ensemble::{Engine, Partition, Shard};
use crate::model::Model;

/// The dotted path of the first field where the configurations `a` and `b` differ.
pub fn first_difference<C: serde::Serialize>(a: &C, b: &C) -> String {
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
    let value = |c: &C| serde_json::to_value(c).expect("a configuration serializes");
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
/// [`PartialError`] naming the file that is unreadable, damaged or edited (its digests),
/// truncated, of another ensemble, or a repeated shard; or a missing shard, listing which file
/// holds which shard.
pub fn merge<R: std::io::BufRead>(files: Vec<(String, R)>) -> Result<Merged, PartialError> {
    let mut opened = Vec::with_capacity(files.len());
    for (name, mut r) in files {
        let (header, key) = read_header(&mut r, &name)?;
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
    let partition = Partition::new(first.config.ensemble.realizations);
    if let Some(why) = header_agrees_with_its_configuration(&first) {
        return Err(mismatch(&first_name, why));
    }
    for o in &opened {
        if let Some(why) = same_ensemble(&o.header, &first, &first_name)
            .or_else(|| shard_of_partition(&o.header, &partition))
        {
            return Err(mismatch(&o.name, why));
        }
    }
    opened.sort_by_key(|o| o.header.shard);
    every_shard_once(&opened, first.shards)?;
    let layout = ResidualLayout::new(first.fixes, first.max_lag);
    let mut sums = Accumulator::new(&layout, first.pair);
    let mut elapsed_s = 0.0;
    for o in opened {
        let same_sums = (o.header.fixes, o.header.max_lag, o.header.pair)
            == (first.fixes, first.max_lag, first.pair);
        elapsed_s += fold_shard(o, &partition, same_sums, &mut sums)?;
    }
    Ok(Merged {
        config: first.config,
        sums,
        elapsed_s,
        engine: first.engine,
    })
}

/// A partial file whose header is read.
struct Opened<R> {
    name: String,
    header: PartialHeader,
    /// The header's digest, which keys its blocks'.
    key: HeaderDigest,
    r: R,
}

pub(super) fn mismatch(file: &str, why: String) -> PartialError {
    PartialError::Mismatch {
        file: file.to_string(),
        why,
    }
}

/// Why the shard `h` is not of the ensemble of `first` (the header of `first_name`), if it is not.
fn same_ensemble(h: &PartialHeader, first: &PartialHeader, first_name: &str) -> Option<String> {
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
        Some(format!("another ensemble: {what}"))
    } else if h.engine != first.engine {
        Some(format!(
            "simulated by the {} engine, {first_name} by the {} engine",
            h.engine, first.engine
        ))
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
    } else {
        None
    }
}

/// Why the header `h` does not describe the sums its configuration makes, if it does not: the
/// configuration must be valid and give the header's fixes, residual lag and residual pair (the
/// shape of every block), so that an edited configuration is never reported over data made with
/// another.
fn header_agrees_with_its_configuration(h: &PartialHeader) -> Option<String> {
    let model = match Model::new(&h.config) {
        Ok(model) => model,
        Err(e) => return Some(format!("the configuration in its header is not valid: {e}")),
    };
    let layout = ResidualLayout::new(model.timeline.fixes(), model.residual_max_lag());
    let made = (layout.fixes(), layout.max_lag(), model.residual_pair);
    let said = (h.fixes, h.max_lag, h.pair);
    (made != said).then(|| {
        let lag = |l: Option<usize>| l.map_or("every pair".to_string(), |l| l.to_string());
        format!(
            "its header is inconsistent: its configuration makes {} fixes, residual lag {} and \
             residual pair {:?}, but the header says {} fixes, residual lag {} and pair {:?}",
            made.0,
            lag(made.1),
            made.2,
            said.0,
            lag(said.1),
            said.2
        )
    })
}

/// Why the shard numbers of `h` are not a shard k of m of `partition`, 1 ≤ k ≤ m ≤ its blocks,
/// if they are not.
fn shard_of_partition(h: &PartialHeader, partition: &Partition) -> Option<String> {
    let (k, m) = (h.shard, h.shards);
    (!(1 <= k && k <= m && m <= partition.blocks)).then(|| {
        format!(
            "its header says shard {k}/{m}, but a shard k/m has 1 ≤ k ≤ m ≤ {} (the blocks of \
             N = {})",
            partition.blocks, partition.realizations
        )
    })
}

/// Checks that the files `opened`, sorted by shard, hold each of the `shards` shards once.
fn every_shard_once<R>(opened: &[Opened<R>], shards: u64) -> Result<(), PartialError> {
    let given: Vec<(&str, u64)> = opened
        .iter()
        .map(|o| (o.name.as_str(), o.header.shard))
        .collect();
    each_shard_once(&given, shards)
}

/// Checks that the files `given` (name, shard k), sorted by shard, hold each of the `shards`
/// shards once.
///
/// # Errors
/// [`PartialError::Mismatch`] naming a shard given twice; [`PartialError::Missing`] naming the
/// first shard missing and listing which file holds which shard.
pub fn each_shard_once(given: &[(&str, u64)], shards: u64) -> Result<(), PartialError> {
    for pair in given.windows(2) {
        if pair[0].1 == pair[1].1 {
            return Err(mismatch(
                pair[1].0,
                format!(
                    "shard {}/{shards} is given twice (also {})",
                    pair[1].1, pair[0].0
                ),
            ));
        }
    }
    match (1..=shards).find(|k| !given.iter().any(|g| g.1 == *k)) {
        Some(missing) => Err(PartialError::Missing {
            shard: missing,
            shards,
            given: given
                .iter()
                .map(|(name, k)| format!("{name} (shard {k}/{shards})"))
                .collect::<Vec<_>>()
                .join(", "),
        }),
        None => Ok(()),
    }
}

/// Adds the blocks of the shard `o` to `sums`, in block order, checking that they are the blocks
/// of its shard of `partition`, each with its realizations, and that its sums have the same
/// shape as the others' (`same_sums`); its run time.
fn fold_shard<R: std::io::BufRead>(
    o: Opened<R>,
    partition: &Partition,
    same_sums: bool,
    sums: &mut Accumulator,
) -> Result<f64, PartialError> {
    let Opened {
        name,
        header,
        key,
        mut r,
    } = o;
    let expected = partition.shard_blocks(Shard {
        index: header.shard,
        of: header.shards,
    });
    if header.blocks != [expected.start, expected.end] || !same_sums {
        return Err(mismatch(
            &name,
            "its blocks are not those of its shard".to_string(),
        ));
    }
    for b in expected.clone() {
        let Some((index, block)) = read_block(&mut r, &header, &key, &name, b)? else {
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
    if read_block(&mut r, &header, &key, &name, expected.end)?.is_some() {
        return Err(mismatch(
            &name,
            "more blocks than its shard holds".to_string(),
        ));
    }
    Ok(header.elapsed_s)
}
