//! A ROS 1 bag (format 2.0) of `sensor_msgs/Imu`, read here rather than with the `rosbag`
//! crate (0.6.3): that crate hands out the same raw records (chunks, connections, messages)
//! through a memory map, leaving the connections' fields and the messages to decode as here,
//! and brings bzip2's C library; a flat scan of the records is about as much code as using it.
//! The file is read from disk record by record, a chunk at a time (`visit_ros1`): memory is
//! one chunk's, whatever the bag's length; [`Ros1Records`] reads it so, the chosen `Imu` topic
//! as [`Record`]s read again from disk as often as an analysis needs. A chunk is plain or compressed as rosbag compresses: lz4 (the LZ4 frame
//! format, the `lz4` crate) or bz2 (the `bzip2` crate on its pure-Rust `libbz2-rs-sys`).
//!
//! # Format
//! ROS bag format 2.0 (wiki.ros.org/Bags/Format/2.0): after `#ROSBAG V2.0\n`, records of a
//! little-endian u32 header length, the header's fields (each a u32 length then `name=value`),
//! a u32 data length and the data. `op` = 0x05 a chunk (its data the records 0x07 connection —
//! `conn`, `topic`, the type in its data's fields — and 0x02 message — `conn`, its data the
//! message; the header's `compression` none, lz4 or bz2 and `size` the records' length), 0x03
//! the bag header (`index_pos`), 0x04 and 0x06 indices. A message is ROS 1 serialized, decoded
//! by [`super::messages`].

use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::Path;

use super::container::{Container, MAX_EXPANSION, expansion_limit};
use super::messages::{ROS1_IMU_TYPE, decode_ros1_message, u32_at};
use super::records::{Channel, ImuRecords, Record};
use super::{LogError, LogProblem, unreadable};

pub use super::container::ROSBAG_MAGIC;

/// Whether the file at `path` starts as a ROS 1 bag does.
pub fn is_ros1(path: &Path) -> bool {
    let mut head = [0u8; 13];
    std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok_and(|()| head == ROSBAG_MAGIC)
}

/// The fields `name=value` of a record's header (or a connection's data).
fn fields(b: &[u8]) -> Option<BTreeMap<&[u8], &[u8]>> {
    let mut out = BTreeMap::new();
    let mut at = 0;
    while at < b.len() {
        let len = u32_at(b, at)? as usize;
        let field = b.get(at + 4..at + 4 + len)?;
        let eq = field.iter().position(|&c| c == b'=')?;
        out.insert(&field[..eq], &field[eq + 1..]);
        at += 4 + len;
    }
    Some(out)
}

/// One record: its header's fields and its data, and where the next starts.
type RawRecord<'a> = (BTreeMap<&'a [u8], &'a [u8]>, &'a [u8], usize);

fn record(b: &[u8], at: usize) -> Option<RawRecord<'_>> {
    let header_len = u32_at(b, at)? as usize;
    let header = fields(b.get(at + 4..at + 4 + header_len)?)?;
    let data_at = at + 4 + header_len;
    let data_len = u32_at(b, data_at)? as usize;
    let data = b.get(data_at + 4..data_at + 4 + data_len)?;
    Some((header, data, data_at + 4 + data_len))
}

/// What [`visit_ros1`] hands on: a connection (topic, type), then each message on it.
pub(super) enum Ros1Event<'a> {
    /// A connection: its topic and its type.
    Connection(&'a str, &'a str),
    /// A message: its topic, its type, and its bytes.
    Message(&'a str, &'a str, &'a [u8]),
}

/// The visitor of [`visit_ros1`].
type Visit<'v> = dyn FnMut(Ros1Event<'_>) -> Result<(), LogError> + 'v;

/// What the records read so far say.
#[derive(Default)]
struct Reading {
    /// conn → (topic, type).
    connections: BTreeMap<u32, (String, String)>,
}

impl Reading {
    /// Takes in one record (its header's fields and its data) found at byte `at` of `place`.
    fn record(
        &mut self,
        file: &str,
        header: &BTreeMap<&[u8], &[u8]>,
        data: &[u8],
        (at, place): (usize, &str),
        visit: &mut Visit<'_>,
    ) -> Result<(), LogError> {
        let conn = header.get(&b"conn"[..]).and_then(|c| u32_at(c, 0));
        match header.get(&b"op"[..]).and_then(|o| o.first()) {
            Some(0x05) => self.chunk(file, header, data, at, visit)?,
            Some(0x07) => {
                let kind = fields(data)
                    .and_then(|f| f.get(&b"type"[..]).map(|t| t.to_vec()))
                    .unwrap_or_default();
                let topic = header
                    .get(&b"topic"[..])
                    .map(|t| t.to_vec())
                    .unwrap_or_default();
                let (topic, kind) = (
                    String::from_utf8_lossy(&topic).into_owned(),
                    String::from_utf8_lossy(&kind).into_owned(),
                );
                visit(Ros1Event::Connection(&topic, &kind))?;
                self.connections
                    .insert(conn.unwrap_or(u32::MAX), (topic, kind));
            }
            Some(0x02) => {
                let Some((topic, kind)) = conn.and_then(|c| self.connections.get(&c)) else {
                    return Err(unreadable(
                        file,
                        format!(
                            "{place}: the message at byte {at} names no connection defined before it"
                        ),
                    ));
                };
                visit(Ros1Event::Message(topic, kind, data))?;
            }
            _ => {}
        }
        Ok(())
    }

    /// Takes in the records of `b` (a chunk's, decompressed), `place` saying where it lies.
    fn records(
        &mut self,
        file: &str,
        b: &[u8],
        place: &str,
        visit: &mut Visit<'_>,
    ) -> Result<(), LogError> {
        let mut at = 0;
        while at < b.len() {
            let Some((header, data, next)) = record(b, at) else {
                return Err(unreadable(
                    file,
                    format!(
                        "{place}: the record at byte {at} is cut short or malformed: expected a ROS bag 2.0 record"
                    ),
                ));
            };
            self.record(file, &header, data, (at, place), visit)?;
            at = next;
        }
        Ok(())
    }

    fn chunk(
        &mut self,
        file: &str,
        header: &BTreeMap<&[u8], &[u8]>,
        data: &[u8],
        at: usize,
        visit: &mut Visit<'_>,
    ) -> Result<(), LogError> {
        let place = format!("the chunk at byte {at}");
        let compression = header.get(&b"compression"[..]).copied().unwrap_or(b"none");
        // The chunk header's `size` is the records' length once decompressed: no more is
        // decompressed than it says, nor than its compressed bytes can hold (a corrupt chunk
        // cannot fill the memory).
        let size = header.get(&b"size"[..]).and_then(|c| u32_at(c, 0));
        let possible = expansion_limit(data.len() as u64);
        let limit = size.map_or(possible, u64::from);
        if compression != b"none" && limit > possible {
            return Err(unreadable(
                file,
                format!(
                    "{place} declares {limit} bytes once decompressed, more than its {} bytes of \
                     {} data can hold: expected at most {possible} (compressed data is taken to \
                     expand at most {MAX_EXPANSION} times)",
                    data.len(),
                    String::from_utf8_lossy(compression)
                ),
            ));
        }
        let inflate = |name: &str, reader: std::io::Result<Box<dyn std::io::Read + '_>>| {
            let mut out = Vec::new();
            reader
                .and_then(|r| {
                    std::io::Read::read_to_end(&mut std::io::Read::take(r, limit), &mut out)
                })
                .map_err(|e| {
                    unreadable(
                        file,
                        format!("{place}: {name} data that does not decompress: {e}"),
                    )
                })?;
            Ok::<_, LogError>(std::borrow::Cow::Owned(out))
        };
        let plain = match compression {
            b"none" => std::borrow::Cow::Borrowed(data),
            b"lz4" => inflate(
                "lz4",
                lz4::Decoder::new(data).map(|d| Box::new(d) as Box<dyn std::io::Read>),
            )?,
            b"bz2" => inflate("bz2", Ok(Box::new(bzip2::read::BzDecoder::new(data))))?,
            other => {
                return Err(unreadable(
                    file,
                    format!(
                        "{place} is compressed with {}: expected none, lz4 or bz2 (rosbag's compressions)",
                        String::from_utf8_lossy(other)
                    ),
                ));
            }
        };
        self.records(file, &plain, &place, visit)
    }
}

/// Reads the records of the ROS 1 bag `source` in order from disk, one top-level record (a
/// chunk, decompressed) at a time, handing its connections and messages to `visit`.
///
/// # Errors
/// [`LogError`] naming the file and the byte offset of a record that is cut short or malformed
/// (a length past the file's end included), a chunk compressed otherwise than plain, lz4 or bz2,
/// declaring more bytes than its data can hold ([`expansion_limit`]) or whose data does not
/// decompress, a message on no connection, or `visit`'s error.
pub(super) fn visit_ros1(source: &Container, visit: &mut Visit<'_>) -> Result<(), LogError> {
    use std::io::Read as _;
    let file = source.name().to_string();
    let io = |e: std::io::Error| unreadable(&file, e.to_string());
    let (f, len) = source.open()?;
    let mut input = std::io::BufReader::with_capacity(1 << 20, f);
    let mut magic = [0u8; ROSBAG_MAGIC.len()];
    if input.read_exact(&mut magic).is_err() || magic != ROSBAG_MAGIC {
        return Err(unreadable(
            &file,
            "expected a ROS 1 bag (#ROSBAG V2.0)".into(),
        ));
    }
    let mut at = ROSBAG_MAGIC.len() as u64;
    let mut reading = Reading::default();
    let (mut header, mut data) = (Vec::new(), Vec::new());
    let cut = |at: u64| {
        unreadable(
            &file,
            format!(
                "the bag: the record at byte {at} is cut short or malformed: expected a ROS bag 2.0 record"
            ),
        )
    };
    loop {
        let mut word = [0u8; 4];
        match input.read(&mut word[..1]).map_err(io)? {
            0 => return Ok(()),
            _ => input.read_exact(&mut word[1..]).map_err(|_| cut(at))?,
        }
        // A length is trusted only as far as the file goes: a corrupt one allocates nothing.
        let header_len = u32::from_le_bytes(word);
        part(&mut input, &mut header, at + 4, header_len, len).map_err(|()| cut(at))?;
        let data_at = at + 4 + u64::from(header_len);
        let mut word = [0u8; 4];
        input.read_exact(&mut word).map_err(|_| cut(at))?;
        let data_len = u32::from_le_bytes(word);
        part(&mut input, &mut data, data_at + 4, data_len, len).map_err(|()| cut(at))?;
        let fields = fields(&header).ok_or_else(|| cut(at))?;
        let place = (usize::try_from(at).unwrap_or(usize::MAX), "the bag");
        reading.record(&file, &fields, &data, place, visit)?;
        at = data_at + 4 + u64::from(data_len);
    }
}

/// Reads `length` bytes at `from` into `buffer`, when the file of `file_len` bytes holds them.
fn part(
    input: &mut impl std::io::Read,
    buffer: &mut Vec<u8>,
    from: u64,
    length: u32,
    file_len: u64,
) -> Result<(), ()> {
    if from + u64::from(length) > file_len {
        return Err(());
    }
    buffer.resize(length as usize, 0);
    input.read_exact(buffer).map_err(|_| ())
}

/// The topics of the ROS 1 bag `source` and their types, from the connection records of its
/// index (the bag header's `index_pos`) when it has one, else by reading it through.
///
/// # Errors
/// As [`visit_ros1`].
pub(super) fn topics(source: &Container) -> Result<BTreeMap<String, String>, LogError> {
    if let Some(t) = index_topics(source) {
        return Ok(t);
    }
    let mut out = BTreeMap::new();
    visit_ros1(source, &mut |event| {
        if let Ros1Event::Connection(topic, kind) = event {
            out.entry(topic.to_string()).or_insert(kind.to_string());
        }
        Ok(())
    })?;
    Ok(out)
}

/// The topics the connection records after `index_pos` name; `None` without an index or when
/// it does not parse.
fn index_topics(source: &Container) -> Option<BTreeMap<String, String>> {
    use std::io::{Read as _, Seek, SeekFrom};
    let (f, len) = source.open().ok()?;
    let mut head = Vec::with_capacity(4096 + ROSBAG_MAGIC.len());
    let mut f = std::io::BufReader::new(f);
    std::io::Read::take(&mut f, 4096 + ROSBAG_MAGIC.len() as u64)
        .read_to_end(&mut head)
        .ok()?;
    let n = head.len();
    let (header, _, _) = record(&head[..n], ROSBAG_MAGIC.len())?;
    if header.get(&b"op"[..])?.first() != Some(&0x03) {
        return None;
    }
    let index_pos = u64::from_le_bytes(header.get(&b"index_pos"[..])?.get(..8)?.try_into().ok()?);
    if index_pos == 0 || index_pos >= len {
        return None;
    }
    f.seek(SeekFrom::Start(index_pos)).ok()?;
    let mut index = Vec::new();
    f.read_to_end(&mut index).ok()?;
    let mut out = BTreeMap::new();
    let mut at = 0;
    while at < index.len() {
        let (header, data, next) = record(&index, at)?;
        if header.get(&b"op"[..])?.first() == Some(&0x07) {
            let topic = String::from_utf8_lossy(header.get(&b"topic"[..])?).into_owned();
            let kind = String::from_utf8_lossy(fields(data)?.get(&b"type"[..])?).into_owned();
            out.entry(topic).or_insert(kind);
        }
        at = next;
    }
    (!out.is_empty()).then_some(out)
}

/// The chosen `Imu` topic of a ROS 1 bag, as records of the six channels read from disk each
/// time.
pub struct Ros1Records {
    source: Container,
    topic: String,
    /// The first message's whole second, once read.
    sec0: Cell<Option<i64>>,
}

impl Ros1Records {
    /// The `Imu` topic `topic` of the bag `source`.
    pub(super) fn new(source: Container, topic: String) -> Self {
        Self {
            source,
            topic,
            sec0: Cell::new(None),
        }
    }
}

impl ImuRecords for Ros1Records {
    fn channels(&self) -> &[Channel] {
        &Channel::ALL
    }

    fn read(&self, visit: &mut dyn FnMut(&Record) -> Result<(), LogError>) -> Result<(), LogError> {
        let file = self.source.name();
        // Messages per `Imu` topic: every one is decoded, as the whole-series reader does.
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        visit_ros1(&self.source, &mut |event| {
            let Ros1Event::Message(topic, kind, data) = event else {
                return Ok(());
            };
            if kind != ROS1_IMU_TYPE {
                return Ok(());
            }
            if !counts.contains_key(topic) {
                counts.insert(topic.to_string(), 0);
            }
            let k = counts.get_mut(topic).expect("inserted");
            let m = decode_ros1_message(file, topic, *k, data)?;
            let at = *k as u64;
            *k += 1;
            if topic != self.topic {
                return Ok(());
            }
            visit(&m.record(&self.sec0, at))
        })
    }

    fn error_at(&self, at: u64, problem: LogProblem) -> LogError {
        let at = format!("{}, topic {}, message {at}", self.source.name(), self.topic);
        LogError::of_file(&at, problem)
    }

    fn error(&self, problem: LogProblem) -> LogError {
        let at = format!("{}, topic {}", self.source.name(), self.topic);
        LogError::of_file(&at, problem)
    }
}
