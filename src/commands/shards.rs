//! What the shards of both ensembles share on the command line: `--shard K/M` and the partial
//! files given to `merge`.

use accelcal::ensemble::{Shard, partial};
use accelcal::error::ConfigError;

/// "K/M" as shard K of M, with 1 ≤ K ≤ M ≤ `blocks`, the blocks of `realizations`.
pub(super) fn parse_shard(
    text: &str,
    blocks: u64,
    realizations: u64,
) -> Result<Shard, ConfigError> {
    let expected = format!(
        "must be K/M with whole numbers 1 ≤ K ≤ M ≤ {blocks} (the blocks of N = {realizations})"
    );
    let parsed = text
        .split_once('/')
        .and_then(|(k, m)| Some((k.trim().parse::<u64>().ok()?, m.trim().parse::<u64>().ok()?)));
    match parsed {
        Some((k, m)) if 1 <= k && k <= m && m <= blocks => Ok(Shard { index: k, of: m }),
        _ => Err(ConfigError::invalid("--shard", text, expected)),
    }
}

/// The partial files `paths`, opened, each with its name.
pub(super) fn open_partials(
    paths: &[std::path::PathBuf],
) -> Result<Vec<(String, std::io::BufReader<std::fs::File>)>, partial::PartialError> {
    let mut files = Vec::with_capacity(paths.len());
    for path in paths {
        let name = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|e| partial::PartialError::Unreadable {
            file: name.clone(),
            why: e.to_string(),
        })?;
        files.push((name, std::io::BufReader::new(file)));
    }
    Ok(files)
}
