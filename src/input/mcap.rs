//! An MCAP file or a ROS 2 bag of MCAP files read record by record from disk (the `mcap`
//! crate's linear reader fed in pieces: no file is held whole), and the chosen `Imu` topic's
//! messages as [`Record`]s read again from disk as often as an analysis needs.
//!
//! # Format
//! MCAP (mcap.dev/spec, version 0): the magic bytes, then records of an opcode, a u64 length and
//! their data — Schema, Channel (a topic and its schema), Message (a channel's message) —, most
//! of them in Chunks (plain, lz4 or zstd, a CRC each), a summary section after the data
//! whose Footer points at it. The `mcap` crate reads the records: chunks, compression, CRCs.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::io::Read as _;

use super::container::{Container, expansion_limit};
use super::messages::{ImuMessage, ROS1_IMU_TYPE, ROS2_IMU_TYPE, decode_imu, decode_ros1};
use super::records::{Channel, ImuRecords, Record};
use super::{LogError, LogProblem, unreadable};

pub use super::container::MCAP_MAGIC;

/// The longest record the MCAP reader accepts, bytes: a corrupt length then is an error, where
/// `mcap::MessageStream` (0.26, no limit) panics on a length near 2⁶⁴. A file of n bytes is
/// held to fewer: [`expansion_limit`] of n.
const RECORD_LIMIT: u64 = 1 << 30;

/// Bytes read from the file at most per request of the reader.
const READ_PIECE: usize = 1 << 20;

/// A channel as its record defines it: its topic, its schema's name, its messages' encoding.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Topic {
    /// The topic.
    pub topic: String,
    /// The schema's name (`sensor_msgs/msg/Imu`).
    pub kind: String,
    /// The channel's message encoding (`cdr`).
    pub encoding: String,
}

impl Topic {
    /// Whether its messages are `sensor_msgs/Imu` messages this reader decodes: a schema named
    /// `sensor_msgs/msg/Imu` or, as ROS 1 spells it, `sensor_msgs/Imu` (the same message), in
    /// CDR or in ROS 1's serialization.
    pub fn is_imu(&self) -> bool {
        matches!(self.kind.as_str(), ROS2_IMU_TYPE | ROS1_IMU_TYPE)
            && matches!(self.encoding.as_str(), "cdr" | "ros1")
    }

    /// The message `data` of this `Imu` topic decoded.
    ///
    /// # Errors
    /// What was expected, in words, when the bytes are not such a message.
    pub fn decode(&self, data: &[u8]) -> Result<ImuMessage, String> {
        if self.encoding == "ros1" {
            return decode_ros1(data).ok_or_else(|| {
                format!(
                    "{} bytes: too short for a ROS 1 serialized {ROS1_IMU_TYPE} message",
                    data.len()
                )
            });
        }
        decode_imu(data)
    }

    /// The topic's type as a listing of topics gives it: the schema's name, and the encoding
    /// when it is not one this reader decodes.
    pub fn describe(&self) -> String {
        if matches!(self.encoding.as_str(), "cdr" | "ros1") {
            self.kind.clone()
        } else {
            format!("{}, encoding {}", self.kind, self.encoding)
        }
    }
}

/// What [`visit_mcap`] hands on: a channel, then each message of a channel.
pub(super) enum McapEvent<'a> {
    /// A channel.
    Channel(&'a Topic),
    /// A message: its channel and its bytes.
    Message(&'a Topic, &'a [u8]),
}

/// The channel of a record that names a schema (by its id among `schemas`) or none.
fn topic_of(c: mcap::records::Channel, schemas: &BTreeMap<u16, String>) -> Topic {
    let kind = schemas
        .get(&c.schema_id)
        .cloned()
        .unwrap_or_else(|| "(no schema)".to_string());
    Topic {
        topic: c.topic,
        kind,
        encoding: c.message_encoding,
    }
}

/// Reads the records of the MCAP file `source` in order (chunks decompressed, their CRCs
/// checked when `check_crcs`, records no longer than [`RECORD_LIMIT`] nor than the file's
/// [`expansion_limit`]), handing channels and messages to `visit`.
///
/// # Errors
/// [`LogError`] for a file the `mcap` crate refuses (naming the message it stopped at), a
/// record longer than the file can hold, a message of a channel not defined before it, or
/// `visit`'s error.
pub(super) fn visit_mcap(
    source: &Container,
    check_crcs: bool,
    visit: &mut dyn FnMut(McapEvent<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let file = source.name();
    let (mut input, file_len) = source.open()?;
    let mut head = [0u8; 8];
    if input.read_exact(&mut head).is_err() || head != MCAP_MAGIC {
        return Err(unreadable(
            file,
            "expected an MCAP file (its magic bytes)".into(),
        ));
    }
    let mut input = std::io::Read::chain(&head[..], input);
    let limit = RECORD_LIMIT.min(expansion_limit(file_len));
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_validate_chunk_crcs(check_crcs)
            .with_record_length_limit(usize::try_from(limit).unwrap_or(usize::MAX)),
    );
    let mut schemas: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels: BTreeMap<u16, Topic> = BTreeMap::new();
    let mut index = 0usize;
    let broken = |index: usize, e: &dyn std::fmt::Display| {
        unreadable(
            file,
            format!("not a readable MCAP file at message {index}: {e}"),
        )
    };
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| match e {
            mcap::McapError::RecordTooLarge { opcode, len } => unreadable(
                file,
                format!(
                    "at message {index}, a record (opcode 0x{opcode:02x}) declares {len} bytes, \
                     more than a file of {file_len} bytes can hold: expected at most {limit} \
                     (compressed data is taken to expand at most {} times)",
                    super::container::MAX_EXPANSION
                ),
            ),
            e => broken(index, &e),
        })?;
        let (opcode, data) = match event {
            LinearReadEvent::ReadRequest(need) => {
                let buffer = reader.insert(need.min(READ_PIECE));
                let got = input
                    .read(buffer)
                    .map_err(|e| unreadable(file, e.to_string()))?;
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
                let (id, topic) = (c.id, topic_of(c, &schemas));
                visit(McapEvent::Channel(&topic))?;
                channels.insert(id, topic);
            }
            Record::Message { header, data } => {
                index += 1;
                let Some(topic) = channels.get(&header.channel_id) else {
                    let e = format!("channel {} is not defined before it", header.channel_id);
                    return Err(broken(index - 1, &e));
                };
                visit(McapEvent::Message(topic, &data))?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// What a file's summary section counts: its chunks and each topic's messages.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Counts {
    /// Chunks (the Statistics record's, else the Chunk Index records').
    pub chunks: u64,
    /// Messages per topic (the Statistics record's channel message counts).
    pub messages: BTreeMap<String, u64>,
}

/// One MCAP file to read: where it is, and what its summary counts (when it does).
pub(super) type McapFile = (Container, Option<Counts>);

/// The chosen `Imu` topic of MCAP files read in sequence, as records of the six channels.
pub struct McapRecords {
    /// The recording's name in messages.
    name: String,
    files: Vec<McapFile>,
    topic: String,
    /// The first message's whole second, once read.
    sec0: Cell<Option<i64>>,
    /// Whether a read went through every file: its chunks' CRCs were checked then, and are
    /// not again (13 % of a read's time).
    read_once: Cell<bool>,
    /// What the first whole read found amiss, in words.
    warnings: RefCell<Vec<String>>,
}

impl McapRecords {
    /// The `Imu` topic `topic` of `files` (the parts of the recording `name`).
    pub(super) fn new(name: String, files: Vec<McapFile>, topic: String) -> Self {
        Self {
            name,
            files,
            topic,
            sec0: Cell::new(None),
            read_once: Cell::new(false),
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// The warning of a file whose summary counts other than `read` messages of the topic.
    fn compare(&self, file: &str, counts: &Counts, read: u64) -> Option<String> {
        let listed = counts.messages.get(&self.topic).copied()?;
        (listed != read).then(|| {
            format!(
                "{file}: its summary lists {} chunk(s) and {listed} message(s) on topic {}; {read} \
                 were read (a record of an unknown kind or a damaged part was skipped)",
                counts.chunks, self.topic
            )
        })
    }
}

impl ImuRecords for McapRecords {
    fn channels(&self) -> &[Channel] {
        &Channel::ALL
    }

    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError> {
        // Messages per `Imu` topic: every one is decoded, as the whole-series reader does.
        let mut counts: BTreeMap<String, u64> = BTreeMap::new();
        let first = !self.read_once.get();
        for (f, summary) in &self.files {
            let before = counts.get(&self.topic).copied().unwrap_or(0);
            visit_mcap(f, first, &mut |event| {
                let McapEvent::Message(topic, data) = event else {
                    return Ok(());
                };
                if !topic.is_imu() {
                    return Ok(());
                }
                let name = topic.topic.as_str();
                // A lookup by the borrowed name: no allocation per message.
                if !counts.contains_key(name) {
                    counts.insert(name.to_string(), 0);
                }
                let k = counts.get_mut(name).expect("inserted");
                let m = topic.decode(data).map_err(|e| {
                    let at = format!("{}, topic {name}, message {k}", f.name());
                    unreadable(&at, e)
                })?;
                let at = *k;
                *k += 1;
                if name != self.topic {
                    return Ok(());
                }
                visit(&m.record(&self.sec0, at))
            })?;
            let read = counts.get(&self.topic).copied().unwrap_or(0) - before;
            if first
                && let Some(w) = summary
                    .as_ref()
                    .and_then(|c| self.compare(f.name(), c, read))
            {
                self.warnings.borrow_mut().push(w);
            }
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

    fn warnings(&self) -> Vec<String> {
        self.warnings.borrow().clone()
    }
}

/// Every topic of the MCAP file `source`, from its summary section when it has one (the
/// footer's `summary_start`, MCAP specification § Footer), else by reading it through; and
/// what the summary counts, when it does.
///
/// # Errors
/// As [`visit_mcap`].
pub(super) fn topics(
    source: &Container,
) -> Result<(BTreeMap<String, Topic>, Option<Counts>), LogError> {
    if let Some((t, counts)) = summary(source) {
        return Ok((t, counts));
    }
    let mut out = BTreeMap::new();
    visit_mcap(source, true, &mut |event| {
        if let McapEvent::Channel(topic) = event {
            out.entry(topic.topic.clone()).or_insert(topic.clone());
        }
        Ok(())
    })?;
    Ok((out, None))
}

/// The topics the summary section lists, and its counts when it has a Statistics record;
/// `None` without a summary or when it does not parse.
fn summary(source: &Container) -> Option<(BTreeMap<String, Topic>, Option<Counts>)> {
    use mcap::records::Record;
    use std::io::{Seek, SeekFrom};
    // The footer: opcode, length (8), summary_start (8), summary_offset_start (8), CRC (4),
    // then the closing magic bytes.
    const FOOTER: u64 = 1 + 8 + 8 + 8 + 4;
    let (mut f, len) = source.open().ok()?;
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
    let (mut schemas, mut channels, mut out) = (BTreeMap::new(), BTreeMap::new(), BTreeMap::new());
    let (mut statistics, mut chunk_indices) = (None, 0u64);
    let mut rest = summary.as_slice();
    while !rest.is_empty() {
        let opcode = *rest.first()?;
        let n = usize::try_from(u64::from_le_bytes(rest.get(1..9)?.try_into().ok()?)).ok()?;
        let data = rest.get(9..9usize.checked_add(n)?)?;
        match mcap::parse_record(opcode, data).ok()? {
            Record::Schema { header, .. } => {
                schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                let (id, topic) = (c.id, topic_of(c, &schemas));
                channels.insert(id, topic.topic.clone());
                out.entry(topic.topic.clone()).or_insert(topic);
            }
            Record::Statistics(s) => statistics = Some(s),
            Record::ChunkIndex(_) => chunk_indices += 1,
            _ => {}
        }
        rest = &rest[9 + n..];
    }
    // A summary that repeats no channel says nothing of the topics.
    if out.is_empty() {
        return None;
    }
    let counts = statistics.map(|s| {
        let mut messages = BTreeMap::new();
        for (id, n) in &s.channel_message_counts {
            if let Some(topic) = channels.get(id) {
                *messages.entry(topic.clone()).or_insert(0) += n;
            }
        }
        let chunks = if s.chunk_count > 0 {
            u64::from(s.chunk_count)
        } else {
            chunk_indices
        };
        Counts { chunks, messages }
    });
    Some((out, counts))
}
