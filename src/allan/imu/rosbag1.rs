//! A ROS 1 bag (format 2.0) of `sensor_msgs/Imu`, read here rather than with the `rosbag`
//! crate (0.6.3): that crate hands out the same raw records (chunks, connections, messages)
//! through a memory map, leaving the connections' fields and the messages to decode as here,
//! and brings bzip2's C library; a flat scan of the records is about as much code as using it.
//!
//! # Formula
//! ROS bag format 2.0 (wiki.ros.org/Bags/Format/2.0): after `#ROSBAG V2.0\n`, records of a
//! little-endian u32 header length, the header's fields (each a u32 length then `name=value`),
//! a u32 data length and the data. `op` = 0x05 a chunk (its data the records 0x07 connection —
//! `conn`, `topic`, the type in its data's fields — and 0x02 message — `conn`, its data the
//! message), 0x03 the bag header, 0x04 and 0x06 indices. A `sensor_msgs/Imu` message is ROS 1
//! serialized (little-endian, unaligned): header {u32 seq, u32 sec, u32 nsec, string frame_id as
//! u32 length + bytes}, then 37 float64 (orientation, its covariance, angular velocity, its
//! covariance, linear acceleration, its covariance).

use std::collections::BTreeMap;
use std::path::Path;

use super::bag::{ImuMessage, Topics, unreadable};
use crate::logs::LogError;

/// The first bytes of a ROS 1 bag.
pub const ROSBAG_MAGIC: &[u8] = b"#ROSBAG V2.0\n";

/// The ROS 1 type of an IMU message.
pub const IMU_TYPE: &str = "sensor_msgs/Imu";

/// Whether the file at `path` starts as a ROS 1 bag does.
pub fn is_ros1(path: &Path) -> bool {
    let mut head = [0u8; 13];
    std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok_and(|()| head == ROSBAG_MAGIC)
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
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
type Record<'a> = (BTreeMap<&'a [u8], &'a [u8]>, &'a [u8], usize);

fn record(b: &[u8], at: usize) -> Option<Record<'_>> {
    let header_len = u32_at(b, at)? as usize;
    let header = fields(b.get(at + 4..at + 4 + header_len)?)?;
    let data_at = at + 4 + header_len;
    let data_len = u32_at(b, data_at)? as usize;
    let data = b.get(data_at + 4..data_at + 4 + data_len)?;
    Some((header, data, data_at + 4 + data_len))
}

/// Decodes a ROS 1 serialized `sensor_msgs/Imu`.
fn decode(data: &[u8]) -> Option<ImuMessage> {
    let (sec, nanosec) = (u32_at(data, 4)?, u32_at(data, 8)?);
    let start = 16 + u32_at(data, 12)? as usize;
    let f = |k: usize| -> Option<f64> {
        let at = start + 8 * k;
        Some(f64::from_le_bytes(data.get(at..at + 8)?.try_into().ok()?))
    };
    Some(ImuMessage {
        sec: i32::try_from(sec).ok()?,
        nanosec,
        angular_velocity: [f(13)?, f(14)?, f(15)?],
        linear_acceleration: [f(25)?, f(26)?, f(27)?],
    })
}

/// What the records read so far say.
#[derive(Default)]
struct Reading {
    /// conn → (topic, type).
    connections: BTreeMap<u32, (String, String)>,
}

impl Reading {
    /// Takes in the records of `b` (a bag's or a chunk's), `place` saying where they lie.
    fn records(
        &mut self,
        file: &str,
        b: &[u8],
        mut at: usize,
        place: &str,
        topics: &mut Topics,
    ) -> Result<(), LogError> {
        while at < b.len() {
            let Some((header, data, next)) = record(b, at) else {
                return Err(unreadable(
                    file,
                    format!(
                        "{place}: the record at byte {at} is cut short or malformed: expected a ROS bag 2.0 record"
                    ),
                ));
            };
            let conn = header.get(&b"conn"[..]).and_then(|c| u32_at(c, 0));
            match header.get(&b"op"[..]).and_then(|o| o.first()) {
                Some(0x05) => self.chunk(file, &header, data, at, topics)?,
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
                    topics.types.entry(topic.clone()).or_insert(kind.clone());
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
                    if kind == IMU_TYPE {
                        let list = topics.imu.entry(topic.clone()).or_default();
                        let Some(m) = decode(data) else {
                            let at = format!("{file}, topic {topic}, message {}", list.len());
                            return Err(unreadable(
                                &at,
                                format!("{} bytes: too short for a {IMU_TYPE} message", data.len()),
                            ));
                        };
                        list.push(m);
                    }
                }
                _ => {}
            }
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
        topics: &mut Topics,
    ) -> Result<(), LogError> {
        let place = format!("the chunk at byte {at}");
        let compression = header.get(&b"compression"[..]).copied().unwrap_or(b"none");
        let plain = match compression {
            b"none" => data.to_vec(),
            b"lz4" => {
                let mut out = Vec::new();
                lz4::Decoder::new(data)
                    .and_then(|mut d| std::io::Read::read_to_end(&mut d, &mut out))
                    .map_err(|e| {
                        unreadable(
                            file,
                            format!("{place}: lz4 data that does not decompress: {e}"),
                        )
                    })?;
                out
            }
            other => {
                return Err(unreadable(
                    file,
                    format!(
                        "{place} is compressed with {}: expected none or lz4 (rosbag compress --lz4, or rosbag decompress)",
                        String::from_utf8_lossy(other)
                    ),
                ));
            }
        };
        self.records(file, &plain, 0, &place, topics)
    }
}

/// Reads the connections and `Imu` messages of the ROS 1 bag at `path` into `topics`.
///
/// # Errors
/// [`LogError`] naming the file and the byte offset of a record that is cut short or malformed,
/// a chunk compressed otherwise than plain or lz4, or a message too short for an `Imu`.
pub(super) fn read_ros1(path: &Path, topics: &mut Topics) -> Result<(), LogError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| unreadable(&file, e.to_string()))?;
    Reading::default().records(&file, &bytes, ROSBAG_MAGIC.len(), "the bag", topics)
}
