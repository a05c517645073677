//! Reading and rewriting partial files as the format describes them (src/ensemble/partial),
//! to damage or forge them in tests.

use std::path::Path;

use sha2::{Digest, Sha256};

/// The bytes of a partial file split into its header (three lines) and its blocks with their
/// digests.
pub struct Parts {
    /// The magic line and the header line.
    pub lines: Vec<u8>,
    /// The header as JSON.
    pub header: serde_json::Value,
    /// Each block's bytes (index, count, sums) without its digest.
    pub blocks: Vec<Vec<u8>>,
}

/// Bytes of a SHA-256 digest.
pub const DIGEST: usize = 32;

/// Offset just after the `n`-th line end of `bytes`.
fn after_line(bytes: &[u8], n: usize) -> usize {
    let mut at = 0;
    for _ in 0..n {
        at += bytes[at..].iter().position(|&b| b == b'\n').unwrap() + 1;
    }
    at
}

/// The length of the header part of a partial file: its first three lines.
pub fn header_len(bytes: &[u8]) -> usize {
    after_line(bytes, 3)
}

/// Splits the partial file `bytes`.
pub fn split(bytes: &[u8]) -> Parts {
    let lines_end = after_line(bytes, 2);
    let header: serde_json::Value =
        serde_json::from_slice(&bytes[after_line(bytes, 1)..lines_end]).unwrap();
    let count = header["blocks"][1].as_u64().unwrap() - header["blocks"][0].as_u64().unwrap();
    let body = &bytes[header_len(bytes)..];
    let each = body.len() / count as usize;
    assert_eq!(each * count as usize, body.len(), "whole blocks");
    let blocks = body
        .chunks_exact(each)
        .map(|b| b[..each - DIGEST].to_vec())
        .collect();
    Parts {
        lines: bytes[..lines_end].to_vec(),
        header,
        blocks,
    }
}

/// The partial file of `parts`, with every digest computed as the format says.
pub fn join(parts: &Parts) -> Vec<u8> {
    let key: [u8; 32] = Sha256::digest(&parts.lines).into();
    let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
    let mut out = parts.lines.clone();
    out.extend_from_slice(format!("sha256 {hex}\n").as_bytes());
    for b in &parts.blocks {
        out.extend_from_slice(b);
        let d: [u8; 32] = Sha256::new()
            .chain_update(key)
            .chain_update(b)
            .finalize()
            .into();
        out.extend_from_slice(&d);
    }
    out
}

/// Replaces `from` by `to` in the header line of the partial `path`; with `redigest`, writes
/// the header's digest anew (but not the blocks'), as someone editing it on purpose would.
pub fn edit_header(path: &Path, from: &str, to: &str, redigest: bool) {
    let bytes = std::fs::read(path).unwrap();
    let (start, end) = (after_line(&bytes, 1), after_line(&bytes, 2));
    let line = std::str::from_utf8(&bytes[start..end]).unwrap();
    assert!(line.contains(from), "{line}");
    let edited = line.replacen(from, to, 1);
    let lines = [&bytes[..start], edited.as_bytes()].concat();
    let out = if redigest {
        let key: [u8; 32] = Sha256::digest(&lines).into();
        let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
        [
            &lines,
            format!("sha256 {hex}\n").as_bytes(),
            &bytes[header_len(&bytes)..],
        ]
        .concat()
    } else {
        [&lines, &bytes[end..]].concat()
    };
    std::fs::write(path, out).unwrap();
}
