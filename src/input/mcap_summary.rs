//! What an MCAP file's records define — a channel's topic, schema and encoding ([`Topic`]) —
//! and its summary section (MCAP specification § Summary Section, § Footer): the topics it
//! lists and what its Statistics record counts, read without reading the file through when
//! the footer points at a summary.

use std::collections::BTreeMap;
use std::io::Read as _;

use super::container::{Container, MCAP_MAGIC};
use super::messages::{ImuMessage, ROS1_IMU_TYPE, ROS2_IMU_TYPE, decode_imu, decode_ros1};

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

/// The channel of a record that names a schema (by its id among `schemas`) or none.
pub(super) fn topic_of(c: mcap::records::Channel, schemas: &BTreeMap<u16, String>) -> Topic {
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

/// What a file's summary section counts: its chunks and each topic's messages.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Counts {
    /// Chunks (the Statistics record's, else the Chunk Index records').
    pub chunks: u64,
    /// Messages per topic (the Statistics record's channel message counts).
    pub messages: BTreeMap<String, u64>,
}

/// The topics the summary section lists, and its counts when it has a Statistics record;
/// `None` without a summary or when it does not parse.
pub(super) fn summary(source: &Container) -> Option<(BTreeMap<String, Topic>, Option<Counts>)> {
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
