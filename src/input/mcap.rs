//! An MCAP file or a ROS 2 bag of MCAP files read record by record from disk (the `mcap`
//! crate's linear reader fed in pieces: no file is held whole), and the chosen `Imu` topic's
//! messages as [`Record`]s read again from disk as often as an analysis needs.
//!
//! # Format
//! MCAP (mcap.dev/spec, version 0): the magic bytes, then records of an opcode, a u64 length and
//! their data — Schema, Channel (a topic and its schema), Message (a channel's message) —, most
//! of them in Chunks (plain, lz4 or zstd, a CRC each), a summary section after the data
//! whose Footer points at it. The `mcap` crate's linear reader splits the file into records;
//! chunks are opened here (`input::mcap_chunks`: lz4, zstd, CRC32).

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::io::Read as _;

use super::container::{Container, expansion_limit};
use super::mcap_chunks::{self, Ahead, ChunkError, Opened};
use super::mcap_summary::{Counts, summary, topic_of};
use super::records::{Channel, ImuRecords, Record};
use super::{LogError, LogProblem, unreadable};

pub use super::container::MCAP_MAGIC;
pub(super) use super::mcap_summary::Topic;

/// The longest record the MCAP reader accepts, bytes: a corrupt length then is an error, where
/// `mcap::MessageStream` (0.26, no limit) panics on a length near 2⁶⁴. A file of n bytes is
/// held to fewer: [`expansion_limit`] of n.
const RECORD_LIMIT: u64 = 1 << 30;

/// Bytes read from the file at most per request of the reader.
const READ_PIECE: usize = 1 << 20;

/// What [`visit_mcap`] hands on: a channel, then each message of a channel.
pub(super) enum McapEvent<'a> {
    /// A channel.
    Channel(&'a Topic),
    /// A message: its channel and its bytes.
    Message(&'a Topic, &'a [u8]),
}

/// Reads the records of the MCAP file `source` in order (chunks decompressed on the thread
/// pool while earlier ones are handed on, [`mcap_chunks`]; their CRCs
/// checked when `check_crcs`; records no longer than [`RECORD_LIMIT`] nor than the file's
/// [`expansion_limit`]), handing channels and messages to `visit`. Records other than schemas,
/// channels, messages and chunks are skipped unread.
///
/// # Errors
/// [`LogError`] for a file the `mcap` crate refuses (naming the message it stopped at), a
/// record longer than the file can hold, a message of a channel not defined before it, or
/// `visit`'s error: the first in the file's order.
pub(super) fn visit_mcap(
    source: &Container,
    check_crcs: bool,
    visit: &mut dyn FnMut(McapEvent<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    use mcap::records::op;
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
            .with_emit_chunks(true)
            .with_record_length_limit(usize::try_from(limit).unwrap_or(usize::MAX)),
    );
    let mut reading = Reading {
        file,
        file_len,
        limit,
        schemas: BTreeMap::new(),
        channels: BTreeMap::new(),
        index: 0,
        visit,
    };
    let mut ahead = Ahead::new(check_crcs, limit);
    while let Some(event) = reader.next_event() {
        let event = match event {
            Ok(event) => event,
            Err(e) => {
                // What the chunks before the damage hold comes first.
                while let Some(opened) = ahead.pop() {
                    reading.chunk(opened, &mut ahead)?;
                }
                return Err(match e {
                    mcap::McapError::RecordTooLarge { opcode, len } => {
                        reading.too_large(opcode, len)
                    }
                    e => reading.broken(&e),
                });
            }
        };
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let buffer = reader.insert(need.min(READ_PIECE));
                let got = input
                    .read(buffer)
                    .map_err(|e| unreadable(file, e.to_string()))?;
                reader.notify_read(got);
            }
            LinearReadEvent::Record { opcode, data } if opcode == op::CHUNK => {
                if let Some(opened) = ahead.push(data) {
                    reading.chunk(opened, &mut ahead)?;
                }
            }
            LinearReadEvent::Record { opcode, data }
                if matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) =>
            {
                while let Some(opened) = ahead.pop() {
                    reading.chunk(opened, &mut ahead)?;
                }
                reading.record(opcode, data)?;
            }
            LinearReadEvent::Record { .. } => {}
        }
    }
    while let Some(opened) = ahead.pop() {
        reading.chunk(opened, &mut ahead)?;
    }
    Ok(())
}

/// The state of one reading of a file: its schemas and channels so far, the messages handed on.
struct Reading<'a, 'v> {
    file: &'a str,
    file_len: u64,
    limit: u64,
    schemas: BTreeMap<u16, String>,
    channels: BTreeMap<u16, Topic>,
    /// Messages handed on so far.
    index: usize,
    visit: &'v mut dyn FnMut(McapEvent<'_>) -> Result<(), LogError>,
}

impl Reading<'_, '_> {
    /// The error of the file at the current message.
    fn broken(&self, e: &dyn std::fmt::Display) -> LogError {
        unreadable(
            self.file,
            format!("not a readable MCAP file at message {}: {e}", self.index),
        )
    }

    /// The error of a record (opcode `opcode`) declaring `len` bytes.
    fn too_large(&self, opcode: u8, len: u64) -> LogError {
        unreadable(
            self.file,
            format!(
                "at message {}, a record (opcode 0x{opcode:02x}) declares {len} bytes, more than \
                 a file of {} bytes can hold: expected at most {} (compressed data is taken to \
                 expand at most {} times)",
                self.index,
                self.file_len,
                self.limit,
                super::container::MAX_EXPANSION
            ),
        )
    }

    /// Hands on the records of an opened chunk, its buffers then back to `ahead`.
    fn chunk(&mut self, (opened, copy): Opened, ahead: &mut Ahead) -> Result<(), LogError> {
        let error = |r: &Self, e: ChunkError| match e {
            ChunkError::TooLarge { opcode, len } => r.too_large(opcode, len),
            ChunkError::Broken(e) => r.broken(&e),
        };
        let bytes = opened.map_err(|e| error(self, e))?;
        for record in mcap_chunks::records(&bytes, self.limit) {
            let (opcode, data) = record.map_err(|e| error(self, e))?;
            self.record(opcode, data)?;
        }
        ahead.recycle([bytes, copy]);
        Ok(())
    }

    /// Hands on a schema, channel or message record (others are skipped).
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<(), LogError> {
        use mcap::records::{Record, op};
        // A message's header: channel id (u16), sequence (u32), log and publish times (u64).
        const MESSAGE_HEADER: usize = 2 + 4 + 8 + 8;
        if opcode == op::MESSAGE && data.len() >= MESSAGE_HEADER {
            let id = u16::from_le_bytes([data[0], data[1]]);
            self.index += 1;
            let Some(topic) = self.channels.get(&id) else {
                self.index -= 1;
                return Err(self.broken(&format!("channel {id} is not defined before it")));
            };
            return (self.visit)(McapEvent::Message(topic, &data[MESSAGE_HEADER..]));
        }
        if !matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
            return Ok(());
        }
        match mcap::parse_record(opcode, data).map_err(|e| self.broken(&e))? {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                let (id, topic) = (c.id, topic_of(c, &self.schemas));
                (self.visit)(McapEvent::Channel(&topic))?;
                self.channels.insert(id, topic);
            }
            _ => {}
        }
        Ok(())
    }
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
