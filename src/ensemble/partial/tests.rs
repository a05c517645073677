//! Partial files written and read back: bit for bit, and every change refused.

use super::*;
use crate::config::Config;
use crate::ensemble::Ensemble;
use crate::filter::FilterSchedule;
use crate::model::Model;

/// A header and the sums of one block of a short ensemble.
fn small() -> (PartialHeader, Accumulator) {
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
    (header, acc)
}

/// Reads every block of the partial file `bytes`.
fn read_all(bytes: &[u8]) -> Result<Vec<(u64, Accumulator)>, PartialError> {
    let mut r = std::io::BufReader::new(bytes);
    let (header, key) = read_header(&mut r, "f")?;
    let mut blocks = Vec::new();
    while let Some(b) = read_block(&mut r, &header, &key, "f", blocks.len() as u64)? {
        blocks.push(b);
    }
    Ok(blocks)
}

#[test]
fn blocks_read_back_bit_for_bit() {
    let (header, acc) = small();
    let mut bytes = Vec::new();
    let key = write_header(&mut bytes, &header).unwrap();
    write_block(&mut bytes, &key, 7, &acc).unwrap();
    let mut r = std::io::BufReader::new(&bytes[..]);
    assert_eq!(read_header(&mut r, "f").unwrap(), (header.clone(), key));
    let (index, back) = read_block(&mut r, &header, &key, "f", 0).unwrap().unwrap();
    assert_eq!((index, &back), (7, &acc));
    assert!(read_block(&mut r, &header, &key, "f", 1).unwrap().is_none());
    // A file cut inside a block is an error, not a short ensemble.
    assert!(matches!(
        read_all(&bytes[..bytes.len() - 3]),
        Err(PartialError::Truncated { .. })
    ));
    // Blocks spooled without digests and written with the header make the same file.
    let mut spooled = Vec::new();
    write_partial(&mut spooled, &header, &mut &encode_block(7, &acc)[..]).unwrap();
    assert_eq!(spooled, bytes);
}

/// One changed bit anywhere in a partial file, in its header, its digests or any block's
/// index, count or sums, makes it unreadable; the untouched file reads.
#[test]
fn every_single_bit_flip_is_refused() {
    let (header, acc) = small();
    let mut bytes = Vec::new();
    let key = write_header(&mut bytes, &header).unwrap();
    write_block(&mut bytes, &key, 0, &acc).unwrap();
    write_block(&mut bytes, &key, 1, &acc).unwrap();
    assert_eq!(read_all(&bytes).unwrap().len(), 2);
    for i in 0..bytes.len() {
        for bit in [i % 8, (i + 3) % 8] {
            let mut damaged = bytes.clone();
            damaged[i] ^= 1 << bit;
            assert!(
                read_all(&damaged).is_err(),
                "byte {i} bit {bit} of {} accepted",
                bytes.len()
            );
        }
    }
}

/// A header edited alike in every file and given a digest of its own no longer matches the
/// blocks: the digest binds the configuration to the sums made with it.
#[test]
fn a_header_rewritten_with_its_own_digest_does_not_match_its_blocks() {
    let (header, acc) = small();
    let mut honest = Vec::new();
    let key = write_header(&mut honest, &header).unwrap();
    write_block(&mut honest, &key, 0, &acc).unwrap();
    let block = &honest[honest.len() - header.block_bytes() - DIGEST_BYTES..];
    let mut edited_header = header.clone();
    edited_header.config.ensemble.seed += 1;
    let mut edited = Vec::new();
    write_header(&mut edited, &edited_header).unwrap();
    edited.extend_from_slice(block);
    let err = read_all(&edited).unwrap_err();
    assert!(
        matches!(&err, PartialError::Damaged { why, .. } if why.contains("block 0")),
        "{err}"
    );
}

/// Non-finite sums written with a valid digest (a shard whose computation overflowed) are
/// refused, naming the block.
#[test]
fn sums_that_are_not_finite_are_refused() {
    let (header, mut acc) = small();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        acc.fixes[1].nis = bad;
        let mut bytes = Vec::new();
        let key = write_header(&mut bytes, &header).unwrap();
        write_block(&mut bytes, &key, 0, &acc).unwrap();
        let err = read_all(&bytes).unwrap_err().to_string();
        assert!(
            err.contains("block 0") && err.contains("not finite"),
            "{err}"
        );
    }
}

#[test]
fn a_partial_of_the_first_format_is_refused_with_the_way_out() {
    let bytes = b"accelcal-partial 1\n{}\n";
    let err = read_all(bytes).unwrap_err().to_string();
    assert!(err.contains("format 1") && err.contains("again"), "{err}");
    // And a device without line ends is read no further than the magic line's length.
    let zeros = std::io::repeat(0).take(1 << 30);
    let err = read_header(&mut std::io::BufReader::new(zeros), "z").unwrap_err();
    assert!(matches!(err, PartialError::Format { .. }), "{err}");
}
