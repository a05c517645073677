//! An MCAP file or a ROS 2 bag of MCAP files read record by record from disk (the `mcap`
//! crate's linear reader fed in pieces: no file is held whole), and the chosen `Imu` topic's
//! messages as [`Record`]s read again from disk as often as an analysis needs.
//!
//! # Format
//! MCAP (mcap.dev/spec, version 0): the magic bytes, then records of an opcode, a u64 length and
//! their data — Schema, Channel (a topic and its schema), Message (a channel's message) —, most
//! of them in Chunks (plain, lz4 or zstd, a CRC each), a summary section after the data
//! whose Footer points at it. The `mcap` crate reads the records: chunks, compression, CRCs.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::{Path, PathBuf};

use super::messages::{ROS2_IMU_TYPE, decode_imu};
use super::records::{Channel, ImuRecords, Record};
use super::{LogError, LogProblem, unreadable};

/// The first bytes of an MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The longest record the MCAP reader accepts, bytes: a corrupt length then is an error, where
/// `mcap::MessageStream` (0.26, no limit) panics on a length near 2⁶⁴.
const RECORD_LIMIT: usize = 1 << 30;

/// Bytes read from the file at most per request of the reader.
const READ_PIECE: usize = 1 << 20;

/// What [`visit_mcap`] hands on: a channel (topic, type), then each message of a typed topic.
pub(super) enum McapEvent<'a> {
    /// A channel: its topic and its schema's name.
    Channel(&'a str, &'a str),
    /// A message: its topic, its type, and its bytes.
    Message(&'a str, &'a str, &'a [u8]),
}

/// Reads the records of the MCAP file `path` in order (chunks decompressed, their CRCs checked
/// when `check_crcs`, records no longer than [`RECORD_LIMIT`]), handing channels and messages
/// to `visit`.
///
/// # Errors
/// [`LogError`] for a file the `mcap` crate refuses (naming the message it stopped at), a
/// message of a channel not defined before it, or `visit`'s error.
pub(super) fn visit_mcap(
    path: &Path,
    check_crcs: bool,
    visit: &mut dyn FnMut(McapEvent<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let file = path.display().to_string();
    let mut input = std::fs::File::open(path).map_err(|e| unreadable(&file, e.to_string()))?;
    let mut head = [0u8; 8];
    if input.read_exact(&mut head).is_err() || head != MCAP_MAGIC {
        return Err(unreadable(
            &file,
            "expected an MCAP file (its magic bytes)".into(),
        ));
    }
    let mut input = std::io::Read::chain(&head[..], input);
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_validate_chunk_crcs(check_crcs)
            .with_record_length_limit(RECORD_LIMIT),
    );
    let mut schemas: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels: BTreeMap<u16, (String, String)> = BTreeMap::new();
    let mut index = 0usize;
    let broken = |index: usize, e: &dyn std::fmt::Display| {
        unreadable(
            &file,
            format!("not a readable MCAP file at message {index}: {e}"),
        )
    };
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event.map_err(|e| broken(index, &e))? {
            LinearReadEvent::ReadRequest(need) => {
                let buffer = reader.insert(need.min(READ_PIECE));
                let got = input
                    .read(buffer)
                    .map_err(|e| unreadable(&file, e.to_string()))?;
                reader.notify_read(got);
                continue;
            }
            LinearReadEvent::Record { opcode, data } => (opcode, data),
        };
        match mcap::parse_record(opcode, data).map_err(|e| broken(index, &e))? {
            Record::Schema { header, .. } => {
                schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                let kind = schemas
                    .get(&c.schema_id)
                    .cloned()
                    .unwrap_or_else(|| "(no schema)".to_string());
                visit(McapEvent::Channel(&c.topic, &kind))?;
                channels.insert(c.id, (c.topic, kind));
            }
            Record::Message { header, data } => {
                index += 1;
                let Some((topic, kind)) = channels.get(&header.channel_id) else {
                    let e = format!("channel {} is not defined before it", header.channel_id);
                    return Err(broken(index - 1, &e));
                };
                visit(McapEvent::Message(topic, kind, &data))?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// The chosen `Imu` topic of MCAP files read in sequence, as records of the six channels.
pub struct McapRecords {
    /// The recording's name in messages.
    name: String,
    files: Vec<PathBuf>,
    topic: String,
    /// The first message's whole second, once read.
    sec0: Cell<Option<i64>>,
    /// Whether a read went through every file: its chunks' CRCs were checked then, and are
    /// not again (13 % of a read's time).
    read_once: Cell<bool>,
}

impl McapRecords {
    /// The `Imu` topic `topic` of `files` (the parts of the recording `name`).
    pub(super) fn new(name: String, files: Vec<PathBuf>, topic: String) -> Self {
        Self {
            name,
            files,
            topic,
            sec0: Cell::new(None),
            read_once: Cell::new(false),
        }
    }
}

impl ImuRecords for McapRecords {
    fn channels(&self) -> &[Channel] {
        &Channel::ALL
    }

    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError> {
        // Messages per `Imu` topic: every one is decoded, as the whole-series reader does.
        let mut counts: BTreeMap<String, u64> = BTreeMap::new();
        for f in &self.files {
            visit_mcap(f, !self.read_once.get(), &mut |event| {
                let McapEvent::Message(topic, kind, data) = event else {
                    return Ok(());
                };
                if kind != ROS2_IMU_TYPE {
                    return Ok(());
                }
                // A lookup by the borrowed name: no allocation per message.
                if !counts.contains_key(topic) {
                    counts.insert(topic.to_string(), 0);
                }
                let k = counts.get_mut(topic).expect("inserted");
                let m = decode_imu(data).map_err(|e| {
                    let at = format!("{}, topic {topic}, message {k}", f.display());
                    unreadable(&at, e)
                })?;
                let at = *k;
                *k += 1;
                if topic != self.topic {
                    return Ok(());
                }
                visit(&m.record(&self.sec0, at))
            })?;
        }
        self.read_once.set(true);
        Ok(())
    }

    fn error_at(&self, at: u64, problem: LogProblem) -> LogError {
        let at = format!("{}, topic {}, message {at}", self.name, self.topic);
        LogError::of_file(&at, problem)
    }

    fn error(&self, problem: LogProblem) -> LogError {
        LogError::of_file(&format!("{}, topic {}", self.name, self.topic), problem)
    }
}

/// Every topic of the MCAP file `path` and its type, from its summary section when it has one
/// (the footer's `summary_start`, MCAP specification § Footer), else by reading it through.
///
/// # Errors
/// As [`visit_mcap`].
pub(super) fn topics(path: &Path) -> Result<BTreeMap<String, String>, LogError> {
    if let Some(t) = summary_topics(path) {
        return Ok(t);
    }
    let mut out = BTreeMap::new();
    visit_mcap(path, true, &mut |event| {
        if let McapEvent::Channel(topic, kind) = event {
            out.entry(topic.to_string()).or_insert(kind.to_string());
        }
        Ok(())
    })?;
    Ok(out)
}

/// The topics the summary section lists; `None` without one or when it does not parse.
fn summary_topics(path: &Path) -> Option<BTreeMap<String, String>> {
    use mcap::records::Record;
    use std::io::{Seek, SeekFrom};
    // The footer: opcode, length (8), summary_start (8), summary_offset_start (8), CRC (4),
    // then the closing magic bytes.
    const FOOTER: u64 = 1 + 8 + 8 + 8 + 4;
    let mut f = std::fs::File::open(path).ok()?;
    let len = f.metadata().ok()?.len();
    let footer_at = len.checked_sub(FOOTER + MCAP_MAGIC.len() as u64)?;
    f.seek(SeekFrom::Start(footer_at)).ok()?;
    let mut footer = [0u8; FOOTER as usize];
    f.read_exact(&mut footer).ok()?;
    let summary_start = u64::from_le_bytes(footer[9..17].try_into().ok()?);
    if footer[0] != 0x02 || summary_start == 0 || summary_start >= footer_at {
        return None;
    }
    let mut summary = vec![0u8; usize::try_from(footer_at - summary_start).ok()?];
    f.seek(SeekFrom::Start(summary_start)).ok()?;
    f.read_exact(&mut summary).ok()?;
    let (mut schemas, mut out) = (BTreeMap::new(), BTreeMap::new());
    let mut rest = summary.as_slice();
    while !rest.is_empty() {
        let opcode = *rest.first()?;
        let n = usize::try_from(u64::from_le_bytes(rest.get(1..9)?.try_into().ok()?)).ok()?;
        let data = rest.get(9..9 + n)?;
        match mcap::parse_record(opcode, data).ok()? {
            Record::Schema { header, .. } => {
                schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                let kind = schemas
                    .get(&c.schema_id)
                    .cloned()
                    .unwrap_or_else(|| "(no schema)".to_string());
                out.entry(c.topic).or_insert(kind);
            }
            _ => {}
        }
        rest = &rest[9 + n..];
    }
    // A summary that repeats no channel says nothing of the topics.
    (!out.is_empty()).then_some(out)
}
