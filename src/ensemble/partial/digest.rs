//! The digests of a partial file: SHA-256 of its header, and of each block keyed with it.

use sha2::{Digest as _, Sha256};

use super::DIGEST_BYTES;

/// The SHA-256 digest of a partial file's first two lines, which keys the digest of each block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeaderDigest([u8; DIGEST_BYTES]);

impl HeaderDigest {
    /// The digest of the magic line and the header line `json` (with its line end).
    pub(super) fn of(magic: &[u8], json: &[u8]) -> Self {
        Self(
            Sha256::new()
                .chain_update(magic)
                .chain_update(json)
                .finalize()
                .into(),
        )
    }

    /// The digest of a block's bytes `block` keyed with this header digest.
    pub(super) fn of_block(&self, block: &[u8]) -> [u8; DIGEST_BYTES] {
        Sha256::new()
            .chain_update(self.0)
            .chain_update(block)
            .finalize()
            .into()
    }

    /// The digest line, `sha256 <hex>` and its line end.
    pub(super) fn line(&self) -> String {
        let hex: String = self.0.iter().map(|b| format!("{b:02x}")).collect();
        format!("sha256 {hex}\n")
    }

    /// The digest of a digest line, if it is one.
    pub(super) fn parse_line(line: &str) -> Option<Self> {
        let hex = line.strip_prefix("sha256 ")?.strip_suffix('\n')?;
        // Lower case only: the line is compared as written, so that a changed bit is never read
        // as the same digest.
        let lower_hex = |b: u8| b.is_ascii_digit() || (b'a'..=b'f').contains(&b);
        if hex.len() != 2 * DIGEST_BYTES || !hex.bytes().all(lower_hex) {
            return None;
        }
        let mut d = [0u8; DIGEST_BYTES];
        for (i, byte) in d.iter_mut().enumerate() {
            *byte = u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok()?;
        }
        Some(Self(d))
    }
}
