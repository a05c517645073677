//! An MCAP file or a ROS 2 bag of MCAP files read record by record from disk (the `mcap`
//! crate's linear reader fed in pieces: no file is held whole), and the chosen `Imu` topic's
//! messages as [`Record`](super::records::Record)s read again from disk as often as an analysis needs.
//!
//! # Format
//! MCAP (mcap.dev/spec, version 0): the magic bytes, then records of an opcode, a u64 length and
//! their data — Schema, Channel (a topic and its schema), Message (a channel's message) —, most
//! of them in Chunks (plain, lz4 or zstd, a CRC each), a summary section after the data
//! whose Footer points at it. The `mcap` crate's linear reader splits the file into records;
//! chunks are opened here (`input::mcap_chunks`: lz4, zstd, CRC32).

use std::collections::BTreeMap;
use std::io::Read as _;

use super::container::{Container, expansion_limit};
use super::mcap_chunks::{self, Ahead, ChunkError, MESSAGE_HEADER, Opened, Piece};
use super::mcap_summary::{Counts, summary, topic_of};
use super::messages::ImuMessage;
use super::{LogError, unreadable};

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
    /// Consecutive messages of one channel, each decoded as a CDR `Imu` on the pool (only
    /// when [`visit_mcap`] is asked to sort the chunks).
    Messages(&'a Topic, MessageRun<'a>),
}

/// Consecutive messages of one channel as [`McapEvent::Messages`] hands them on.
pub(super) struct MessageRun<'a> {
    /// Each message decoded as a CDR `sensor_msgs/msg/Imu`.
    pub rows: &'a [ImuMessage],
    /// Their records (opcode, length and data each).
    records: &'a [u8],
}

impl<'a> MessageRun<'a> {
    /// Each message's bytes (after its header), in order: what [`McapEvent::Message`] would
    /// have handed on.
    pub fn payloads(&self) -> impl Iterator<Item = &'a [u8]> + 'a {
        mcap_chunks::records(self.records, u64::MAX)
            .filter_map(|r| r.ok())
            .map(|(_, data)| &data[MESSAGE_HEADER..])
    }
}

/// Reads the records of the MCAP file `source` in order (chunks decompressed on the thread
/// pool while earlier ones are handed on, [`mcap_chunks`]; their CRCs
/// checked when `check_crcs`; records no longer than [`RECORD_LIMIT`] nor than the file's
/// [`expansion_limit`]), handing channels and messages to `visit`. Records other than schemas,
/// channels, messages and chunks are skipped unread. With `sorting`, each chunk's runs of
/// messages that decode as CDR `Imu` messages are decoded on the pool and handed on as
/// [`McapEvent::Messages`] (the other records as without).
///
/// # Errors
/// [`LogError`] for a file the `mcap` crate refuses (naming the message it stopped at), a
/// record longer than the file can hold, a message of a channel not defined before it, or
/// `visit`'s error: the first in the file's order.
pub(super) fn visit_mcap(
    source: &Container,
    (check_crcs, sorting): (bool, bool),
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
    let mut ahead = Ahead::new(check_crcs, limit, sorting);
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
    fn chunk(&mut self, opened: Opened, ahead: &mut Ahead) -> Result<(), LogError> {
        let error = |r: &Self, e: ChunkError| match e {
            ChunkError::TooLarge { opcode, len } => r.too_large(opcode, len),
            ChunkError::Broken(e) => r.broken(&e),
        };
        let Opened {
            bytes,
            copy,
            sorted,
        } = opened;
        let bytes = bytes.map_err(|e| error(self, e))?;
        let Some(mut sorted) = sorted else {
            for record in mcap_chunks::records(&bytes, self.limit) {
                let (opcode, data) = record.map_err(|e| error(self, e))?;
                self.record(opcode, data)?;
            }
            ahead.recycle([bytes, copy], None);
            return Ok(());
        };
        for piece in sorted.pieces.drain(..) {
            match piece {
                Piece::Run {
                    channel,
                    records,
                    rows,
                } => {
                    let Some(topic) = self.channels.get(&channel) else {
                        let e = format!("channel {channel} is not defined before it");
                        return Err(self.broken(&e));
                    };
                    self.index += rows.len();
                    let run = MessageRun {
                        rows: &sorted.rows[rows],
                        records: &bytes[records],
                    };
                    (self.visit)(McapEvent::Messages(topic, run))?;
                }
                Piece::Record { opcode, data } => self.record(opcode, &bytes[data])?,
                Piece::Error(e) => return Err(error(self, e)),
            }
        }
        ahead.recycle([bytes, copy], Some(sorted));
        Ok(())
    }

    /// Hands on a schema, channel or message record (others are skipped).
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<(), LogError> {
        use mcap::records::{Record, op};
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
    visit_mcap(source, (true, false), &mut |event| {
        if let McapEvent::Channel(topic) = event {
            out.entry(topic.topic.clone()).or_insert(topic.clone());
        }
        Ok(())
    })?;
    Ok((out, None))
}
