//! A static IMU recorded as ROS 2 `sensor_msgs/msg/Imu` messages: an MCAP file (Foxglove's
//! `mcap` crate reads the container: chunks, compression, CRCs) or a ROS 2 bag directory whose
//! storage is MCAP; the `Imu` message's CDR layout decoded here.
//!
//! # Formula
//! Time is the header's stamp, t = (sec − sec₀) + nanosec·10⁻⁹ s with sec₀ the first message's
//! whole second (exact to the nanosecond over a day, where sec + nanosec·10⁻⁹ would keep 0.2 µs
//! of an epoch time), checked as a CSV log's time stamps are: strictly increasing, every step
//! within `input::csv::steps::ACCEPTED_STEP_RATIO` of the median.

use std::collections::BTreeMap;
use std::path::Path;

use super::mcap_stream::{McapEvent, McapRecords, visit_mcap};
use super::stream::{ImuRecords, Record};
use super::{Channel, ImuSamples};
use crate::allan::log::{first_gap, median_step};
use crate::input::{LogError, LogProblem};

/// The first bytes of an MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The ROS 2 type of an IMU message.
pub const IMU_TYPE: &str = "sensor_msgs/msg/Imu";

/// Bytes of the fixed part of an `Imu` message after its frame id, from the 8-byte-aligned
/// orientation on: orientation (4), its covariance (9), angular velocity (3), its covariance
/// (9), linear acceleration (3), its covariance (9), all float64.
const FIXED_F64: usize = 4 + 9 + 3 + 9 + 3 + 9;

/// One decoded message: the stamp (sec, nanosec), angular velocity and linear acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuMessage {
    /// header.stamp.sec.
    pub sec: i32,
    /// header.stamp.nanosec.
    pub nanosec: u32,
    /// angular_velocity x, y, z, rad/s.
    pub angular_velocity: [f64; 3],
    /// linear_acceleration x, y, z, m/s².
    pub linear_acceleration: [f64; 3],
}

impl ImuMessage {
    /// The record of this message, the `at`-th of its topic: its stamp in seconds from the
    /// whole second `sec0` holds (the first message's, which sets it), the accelerometers' values
    /// then the gyros'.
    pub fn record(&self, sec0: &std::cell::Cell<Option<i64>>, at: u64) -> Record {
        let first = sec0.get().unwrap_or(i64::from(self.sec));
        sec0.set(Some(first));
        let [ax, ay, az] = self.linear_acceleration;
        let [gx, gy, gz] = self.angular_velocity;
        Record {
            t_s: (i64::from(self.sec) - first) as f64 + f64::from(self.nanosec) * 1e-9,
            values: [ax, ay, az, gx, gy, gz],
            at,
        }
    }
}

/// Decodes a `sensor_msgs/msg/Imu` message serialized as CDR (OMG DDS-XTypes 1.3, §7.4.3.5:
/// a 4-byte encapsulation header — 0x0001 little-endian, 0x0000 big-endian — then each
/// primitive aligned to its size relative to the end of that header; a string as a uint32
/// length counting its terminating NUL, then its bytes).
///
/// # Errors
/// What was expected, in words, when the bytes are not such a message.
pub fn decode_imu(data: &[u8]) -> Result<ImuMessage, String> {
    let Some((header, body)) = data.split_first_chunk::<4>() else {
        return Err(format!(
            "{} bytes: expected a 4-byte CDR header",
            data.len()
        ));
    };
    let little = match header[1] {
        0x01 => true,
        0x00 => false,
        k => {
            return Err(format!(
                "CDR encapsulation kind 0x{:02x}{k:02x}: expected 0x0001 (little-endian) or 0x0000",
                header[0]
            ));
        }
    };
    let u32_at = |at: usize| -> Option<u32> {
        let b: [u8; 4] = body.get(at..at + 4)?.try_into().ok()?;
        Some(if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    };
    let f64_at = |at: usize| -> f64 {
        let b: [u8; 8] = body[at..at + 8].try_into().expect("8 bytes");
        if little {
            f64::from_le_bytes(b)
        } else {
            f64::from_be_bytes(b)
        }
    };
    let short = || format!("{} bytes: too short for a {IMU_TYPE} message", data.len());
    let (sec, nanosec, id_len) = match (u32_at(0), u32_at(4), u32_at(8)) {
        (Some(s), Some(n), Some(l)) => (s as i32, n, l as usize),
        _ => return Err(short()),
    };
    // The orientation starts at the first multiple of 8 after the frame id.
    let start = (12 + id_len).div_ceil(8) * 8;
    if body.len() < start + 8 * FIXED_F64 {
        return Err(short());
    }
    let vector = |first: usize| std::array::from_fn(|k| f64_at(start + 8 * (first + k)));
    Ok(ImuMessage {
        sec,
        nanosec,
        angular_velocity: vector(4 + 9),
        linear_acceleration: vector(4 + 9 + 3 + 9),
    })
}

/// The messages of every `Imu` topic of one recording, and every topic's type.
#[derive(Default)]
pub(super) struct Topics {
    /// Each `Imu` topic's messages in the recording's order.
    pub imu: BTreeMap<String, Vec<ImuMessage>>,
    /// Every topic's type.
    pub types: BTreeMap<String, String>,
}

pub(super) fn unreadable(file: &str, message: String) -> LogError {
    LogError::of_file(file, LogProblem::Unreadable { message })
}

/// Reads the messages of one MCAP file into `topics` (every `Imu` topic's decoded).
fn read_mcap(path: &Path, topics: &mut Topics) -> Result<(), LogError> {
    let file = path.display().to_string();
    visit_mcap(path, true, &mut |event| match event {
        McapEvent::Channel(topic, kind) => {
            topics
                .types
                .entry(topic.to_string())
                .or_insert(kind.to_string());
            Ok(())
        }
        McapEvent::Message(topic, kind, data) => {
            if kind != IMU_TYPE {
                return Ok(());
            }
            let list = topics.imu.entry(topic.to_string()).or_default();
            let decoded = decode_imu(data).map_err(|e| {
                unreadable(&format!("{file}, topic {topic}, message {}", list.len()), e)
            })?;
            list.push(decoded);
            Ok(())
        }
    })
}

/// The MCAP files of a ROS 2 bag directory, in name order (a split bag's parts in sequence).
fn bag_files(dir: &Path) -> Result<Vec<std::path::PathBuf>, LogError> {
    let name = dir.display().to_string();
    let metadata = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap_or_default();
    if let Some(line) = metadata
        .lines()
        .find(|l| l.trim_start().starts_with("storage_identifier:"))
    {
        let storage = line.split(':').nth(1).unwrap_or("").trim();
        if storage != "mcap" {
            return Err(unreadable(
                &name,
                format!(
                    "the bag's storage is {storage}: expected mcap (ros2 bag convert makes one)"
                ),
            ));
        }
    }
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| unreadable(&name, e.to_string()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(unreadable(
            &name,
            "a directory without .mcap files: expected a ROS 2 bag whose storage is mcap".into(),
        ));
    }
    Ok(files)
}

/// Whether `path` is read as a recording (an MCAP file or a bag directory) rather than CSV. Only
/// a regular file's first bytes are looked at: a pipe is read as CSV, its bytes left unread.
pub fn is_recording(path: &Path) -> bool {
    if path.is_dir() {
        return true;
    }
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return false;
    }
    if super::rosbag1::is_ros1(path) {
        return true;
    }
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok_and(|()| head == MCAP_MAGIC)
}

/// Reads the IMU of the MCAP file, ROS 2 bag directory or ROS 1 bag `path`: the one `Imu` topic, or
/// `topic` when given (needed when there are several).
///
/// # Errors
/// [`LogError`] naming the file and, for a message's problem, its topic and index: a container
/// the `mcap` crate refuses (truncated, a wrong CRC, an unknown compression), no `Imu` topic or
/// several without `topic` (the topics and their types listed), a message that is not an `Imu`,
/// a value that is not finite, a stamp not after the previous, a step outside the accepted band.
pub fn read_recording(path: &Path, topic: Option<&str>) -> Result<ImuSamples, LogError> {
    let name = path.display().to_string();
    let files = if path.is_dir() {
        bag_files(path)?
    } else {
        vec![path.to_path_buf()]
    };
    let mut topics = Topics::default();
    for f in &files {
        if f.is_file() && super::rosbag1::is_ros1(f) {
            super::rosbag1::read_ros1(f, &mut topics)?;
        } else {
            read_mcap(f, &mut topics)?;
        }
    }
    let imu_type = if files.iter().any(|f| super::rosbag1::is_ros1(f)) {
        super::rosbag1::IMU_TYPE
    } else {
        IMU_TYPE
    };
    let chosen = choose_topic(&name, &topics, topic, imu_type)?;
    let messages = &topics.imu[&chosen];
    samples(&name, &chosen, messages)
}

/// The `Imu` topic read: `topic` when given, else the only one.
///
/// # Errors
/// [`LogError`] naming `name` when `topic` is not an `Imu` topic of the recording, or none is
/// given and it has none or several (the topics and their types listed).
fn choose_topic(
    name: &str,
    topics: &Topics,
    topic: Option<&str>,
    imu_type: &str,
) -> Result<String, LogError> {
    let listing = || {
        let all: Vec<String> = topics
            .types
            .iter()
            .map(|(t, k)| format!("{t} ({k})"))
            .collect();
        if all.is_empty() {
            "no topics".to_string()
        } else {
            format!("topics: {}", all.join(", "))
        }
    };
    let problem = match (topic, topics.imu.len()) {
        (Some(t), _) if topics.imu.contains_key(t) => return Ok(t.to_string()),
        (Some(t), _) => format!("no {imu_type} topic {t}; {}", listing()),
        (None, 1) => return Ok(topics.imu.keys().next().expect("one").clone()),
        (None, 0) => format!("no {imu_type} topic; {}", listing()),
        (None, _) => format!(
            "several {imu_type} topics: choose one with --topic; {}",
            listing()
        ),
    };
    Err(unreadable(name, problem))
}

/// The `Imu` topic of the MCAP file, ROS 2 bag directory or ROS 1 bag `path` as records read
/// from disk each time ([`super::stream`]).
///
/// # Errors
/// As [`read_recording`] for the container and the choice of topic.
pub fn open_recording(path: &Path, topic: Option<&str>) -> Result<Box<dyn ImuRecords>, LogError> {
    let name = path.display().to_string();
    let files = if path.is_dir() {
        bag_files(path)?
    } else {
        vec![path.to_path_buf()]
    };
    let ros1 = path.is_file() && super::rosbag1::is_ros1(path);
    let mut topics = Topics::default();
    for f in &files {
        let listed = if ros1 {
            super::rosbag1::topics(f)?
        } else {
            super::mcap_stream::topics(f)?
        };
        for (t, kind) in listed {
            if kind == IMU_TYPE || kind == super::rosbag1::IMU_TYPE {
                topics.imu.entry(t.clone()).or_default();
            }
            topics.types.entry(t).or_insert(kind);
        }
    }
    if ros1 {
        let chosen = choose_topic(&name, &topics, topic, super::rosbag1::IMU_TYPE)?;
        return Ok(Box::new(super::rosbag1_stream::Ros1Records::new(
            path, chosen,
        )));
    }
    let chosen = choose_topic(&name, &topics, topic, IMU_TYPE)?;
    Ok(Box::new(McapRecords::new(name, files, chosen)))
}

/// The samples of the topic's messages, checked as a CSV log's rows are.
fn samples(file: &str, topic: &str, messages: &[ImuMessage]) -> Result<ImuSamples, LogError> {
    let at = |k: usize| format!("{file}, topic {topic}, message {k}");
    let sec0 = messages.first().map_or(0, |m| i64::from(m.sec));
    let mut times = Vec::with_capacity(messages.len());
    let mut channels: Vec<(Channel, Vec<f64>)> = Channel::ALL
        .into_iter()
        .map(|c| (c, Vec::with_capacity(messages.len())))
        .collect();
    for (k, m) in messages.iter().enumerate() {
        let t_s = (i64::from(m.sec) - sec0) as f64 + f64::from(m.nanosec) * 1e-9;
        if let Some(&previous_s) = times.last()
            && t_s <= previous_s
        {
            let problem = LogProblem::NotIncreasing { t_s, previous_s };
            return Err(LogError::of_file(&at(k), problem));
        }
        times.push(t_s);
        let values = m.linear_acceleration.into_iter().chain(m.angular_velocity);
        for ((channel, column), v) in channels.iter_mut().zip(values) {
            if !v.is_finite() {
                let problem = LogProblem::NotFinite {
                    column: channel.column(),
                    text: v.to_string(),
                };
                return Err(LogError::of_file(&at(k), problem));
            }
            column.push(v);
        }
    }
    let Some(median_s) = median_step(&times) else {
        let found = times.len() as u64;
        let problem = LogProblem::TooFewRows { found, needed: 2 };
        return Err(LogError::of_file(
            &format!("{file}, topic {topic}"),
            problem,
        ));
    };
    if let Some((i, problem)) = first_gap(&times, median_s) {
        return Err(LogError::of_file(&at(i), problem));
    }
    Ok(ImuSamples {
        channels,
        sample_period_s: median_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `Imu` message in CDR written out by hand: frame id `frame`, angular velocity
    /// (1, 2, 3), linear acceleration (4, 5, 6), everything else 0.
    fn message(frame: &str, little: bool) -> Vec<u8> {
        let u32b = |x: u32| {
            if little {
                x.to_le_bytes()
            } else {
                x.to_be_bytes()
            }
        };
        let f64b = |x: f64| {
            if little {
                x.to_le_bytes()
            } else {
                x.to_be_bytes()
            }
        };
        let mut b = vec![0, u8::from(little), 0, 0];
        b.extend(u32b(12));
        b.extend(u32b(345));
        b.extend(u32b(frame.len() as u32 + 1));
        b.extend(frame.as_bytes());
        b.push(0);
        while (b.len() - 4) % 8 != 0 {
            b.push(0);
        }
        let mut values = vec![0.0; FIXED_F64];
        values[13..16].copy_from_slice(&[1.0, 2.0, 3.0]);
        values[25..28].copy_from_slice(&[4.0, 5.0, 6.0]);
        values.into_iter().for_each(|v| b.extend(f64b(v)));
        b
    }

    #[test]
    fn the_imu_layout_is_decoded_at_every_alignment_and_both_byte_orders() {
        for frame in ["", "a", "imu", "imu_link", "a_longer_frame_id"] {
            for little in [true, false] {
                let m = decode_imu(&message(frame, little)).unwrap();
                assert_eq!((m.sec, m.nanosec), (12, 345), "{frame:?}");
                assert_eq!(m.angular_velocity, [1.0, 2.0, 3.0], "{frame:?}");
                assert_eq!(m.linear_acceleration, [4.0, 5.0, 6.0], "{frame:?}");
            }
        }
        let whole = message("imu", true);
        let e = decode_imu(&whole[..whole.len() - 1]).unwrap_err();
        assert!(e.contains("too short"), "{e}");
        let mut xcdr2 = whole.clone();
        xcdr2[1] = 0x07;
        assert!(decode_imu(&xcdr2).unwrap_err().contains("0x0007"));
    }
}
