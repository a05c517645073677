//! The frame of a partial file of any model: the magic line, the header line and its digest,
//! and blocks of index, count and sums, each with its digest keyed with the header's.

use std::io::{BufRead, Read, Write};

use serde::Serialize;

use super::{DIGEST_BYTES, FORMAT, HeaderDigest, MAGIC, MAGIC_1, MAX_HEADER_BYTES, PartialError};

/// Writes the header of a partial file: the magic line, the header line and its digest line.
/// Returns the header digest, which keys the digest of every block ([`super::write_block`]).
/// The header is [`super::PartialHeader`] for the one-axis ensemble; the three-axis ensemble
/// writes its own, with `"model": "ins"` ([`header_model`]).
///
/// # Errors
/// The writer's error.
pub fn write_header(w: &mut impl Write, header: &impl Serialize) -> std::io::Result<HeaderDigest> {
    let mut json = serde_json::to_string(header).expect("a header serializes");
    json.push('\n');
    let digest = HeaderDigest::of(MAGIC.as_bytes(), json.as_bytes());
    w.write_all(MAGIC.as_bytes())?;
    w.write_all(json.as_bytes())?;
    w.write_all(digest.line().as_bytes())?;
    Ok(digest)
}

/// Writes a partial file of any model: `header`, then the blocks of `blocks`, each of
/// `block_bytes` bytes (index, count, sums), with its digest.
///
/// # Errors
/// As [`super::write_partial`].
pub fn write_blocks(
    w: &mut impl Write,
    header: &impl Serialize,
    block_bytes: usize,
    blocks: &mut impl Read,
) -> std::io::Result<()> {
    let key = write_header(w, header)?;
    let mut block = vec![0u8; block_bytes];
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

/// The model a partial file's header line `json` belongs to: `"ins"` for the three-axis
/// ensemble's (its `model` field), `"accelerometer"` for the one-axis ensemble's (no such field).
pub fn header_model(json: &[u8]) -> String {
    serde_json::from_slice::<serde_json::Value>(json)
        .ok()
        .and_then(|v| v.get("model")?.as_str().map(str::to_string))
        .unwrap_or_else(|| ONE_AXIS.to_string())
}

/// The model a one-axis ensemble's header stands for ([`header_model`]).
pub const ONE_AXIS: &str = "accelerometer";

/// Reads the first three lines of a partial file named `file`: the header line, checked against
/// its digest, and the digest.
///
/// # Errors
/// [`PartialError::Format`] when the file is not a partial file of this format;
/// [`PartialError::Damaged`] when its header does not match its digest;
/// [`PartialError::Unreadable`] when reading fails.
pub fn read_header_line(
    r: &mut impl BufRead,
    file: &str,
) -> Result<(Vec<u8>, HeaderDigest), PartialError> {
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
    Ok((json, digest))
}

/// Reads the next block of `block_bytes` bytes (index, count, sums) of a partial file with
/// header digest `key`, checked against its digest: its index, its realization count and its
/// sums; `None` at the end of the file. `position` is the block expected there, for messages.
///
/// # Errors
/// [`PartialError::Truncated`] when the file ends inside a block; [`PartialError::Damaged`] when
/// the block does not match its digest; [`PartialError::Mismatch`] when a sum is not finite.
pub fn read_block_floats(
    r: &mut impl Read,
    block_bytes: usize,
    key: &HeaderDigest,
    file: &str,
    position: u64,
) -> Result<Option<(u64, u64, Vec<f64>)>, PartialError> {
    let truncated = |why: String| PartialError::Truncated {
        file: file.to_string(),
        why,
    };
    let mut bytes = vec![0u8; block_bytes + DIGEST_BYTES];
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
    let (block, digest) = bytes.split_at(block_bytes);
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
    Ok(Some((index, count, floats)))
}
