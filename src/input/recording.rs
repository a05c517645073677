//! A static IMU recorded as `sensor_msgs/Imu` messages: an MCAP file ([`super::mcap`]), a ROS 2
//! bag directory whose storage is MCAP ([`super::rosbag2`]) or a ROS 1 bag ([`super::rosbag1`]),
//! the messages decoded by [`super::messages`]; the chosen topic's messages held whole as the
//! channels' samples ([`read_recording`]) or read again from disk as records
//! ([`open_recording`]).
//!
//! # Formula
//! Time is the header's stamp, t = (sec − sec₀) + nanosec·10⁻⁹ s with sec₀ the first message's
//! whole second (exact to the nanosecond over a day, where sec + nanosec·10⁻⁹ would keep 0.2 µs
//! of an epoch time), checked as a CSV log's time stamps are: strictly increasing, every step
//! within `input::csv::steps::ACCEPTED_STEP_RATIO` of the median.

use std::collections::BTreeMap;
use std::path::Path;

use super::container::{Container, Kind};
use super::csv::static_log::{first_gap, median_step};
use super::mcap::{MCAP_MAGIC, McapEvent, visit_mcap};
use super::mcap_records::McapRecords;
use super::messages::{ImuMessage, ROS1_IMU_TYPE, decode_ros1_message};
use super::records::{Channel, ImuRecords, ImuSamples};
use super::rosbag2::bag_files;
use super::{LogError, LogProblem, unreadable};

/// The messages of every `Imu` topic of one recording, and every topic's type.
#[derive(Default)]
pub(super) struct Topics {
    /// Each `Imu` topic's messages in the recording's order.
    pub imu: BTreeMap<String, Vec<ImuMessage>>,
    /// Every topic's type.
    pub types: BTreeMap<String, String>,
}

/// What an MCAP file's `Imu` topic is, in the words of a message that finds none.
const MCAP_IMU: (&str, &str) = (
    "sensor_msgs/msg/Imu",
    " (a schema sensor_msgs/msg/Imu or sensor_msgs/Imu, encoding cdr or ros1)",
);

/// What a ROS 1 bag's `Imu` topic is.
const ROS1_IMU: (&str, &str) = (ROS1_IMU_TYPE, "");

/// Reads the messages of one MCAP file into `topics` (every `Imu` topic's decoded).
fn read_mcap(source: &Container, topics: &mut Topics) -> Result<(), LogError> {
    let file = source.name();
    visit_mcap(source, (true, false), &mut |event| match event {
        McapEvent::Channel(topic) => {
            topics
                .types
                .entry(topic.topic.clone())
                .or_insert(topic.describe());
            Ok(())
        }
        McapEvent::Message(topic, data) => {
            if !topic.is_imu() {
                return Ok(());
            }
            let name = &topic.topic;
            let list = topics.imu.entry(name.clone()).or_default();
            let decoded = topic.decode(data).map_err(|e| {
                unreadable(&format!("{file}, topic {name}, message {}", list.len()), e)
            })?;
            list.push(decoded);
            Ok(())
        }
        McapEvent::Messages(..) => unreachable!("runs are handed on only when asked"),
    })
}

/// Reads the connections and `Imu` messages of the ROS 1 bag `source` into `topics`.
///
/// # Errors
/// As [`super::rosbag1::visit_ros1`], and a message too short for an `Imu`.
fn read_ros1(source: &Container, topics: &mut Topics) -> Result<(), LogError> {
    let file = source.name();
    super::rosbag1::visit_ros1(source, &mut |event| {
        match event {
            super::rosbag1::Ros1Event::Connection(topic, kind) => {
                topics
                    .types
                    .entry(topic.to_string())
                    .or_insert(kind.to_string());
            }
            super::rosbag1::Ros1Event::Message(topic, kind, data) if kind == ROS1_IMU_TYPE => {
                let list = topics.imu.entry(topic.to_string()).or_default();
                list.push(decode_ros1_message(file, topic, list.len(), data)?);
            }
            super::rosbag1::Ros1Event::Message(..) => {}
        }
        Ok(())
    })
}

/// Whether `path` is read as a recording (an MCAP file or a bag directory) rather than CSV. Only
/// a regular file's first bytes are looked at: a pipe's bytes are left unread (a stream is told
/// by [`super::container::copy_stream`]).
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
            read_ros1(&Container::file(f), &mut topics)?;
        } else {
            read_mcap(&Container::file(f), &mut topics)?;
        }
    }
    let imu_type = if files.iter().any(|f| super::rosbag1::is_ros1(f)) {
        ROS1_IMU
    } else {
        MCAP_IMU
    };
    let chosen = choose_topic(&name, &topics, topic, imu_type)?;
    let messages = &topics.imu[&chosen];
    samples(&name, &chosen, messages)
}

/// The `Imu` topic read: `topic` when given, else the only one (the type's name and what is
/// accepted as one, for messages).
///
/// # Errors
/// [`LogError`] naming `name` when `topic` is not an `Imu` topic of the recording, or none is
/// given and it has none or several (the topics and their types listed).
fn choose_topic(
    name: &str,
    topics: &Topics,
    topic: Option<&str>,
    (imu_type, accepted): (&str, &str),
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
        (Some(t), _) => format!("no {imu_type} topic {t}{accepted}; {}", listing()),
        (None, 1) => return Ok(topics.imu.keys().next().expect("one").clone()),
        (None, 0) => format!("no {imu_type} topic{accepted}; {}", listing()),
        (None, _) => format!(
            "several {imu_type} topics: choose one with --topic; {}",
            listing()
        ),
    };
    Err(unreadable(name, problem))
}

/// The `Imu` topic of the MCAP file, ROS 2 bag directory or ROS 1 bag `path` as records read
/// from disk each time (for `allan::imu::stream`).
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
    let files = files.iter().map(|f| Container::file(f)).collect();
    open_parts(name, files, ros1, topic)
}

/// The `Imu` topic of the copy of a stream, `source`, whose first bytes told `kind` (an MCAP
/// file or a ROS 1 bag), as records read from the copy each time.
///
/// # Errors
/// As [`open_recording`].
pub fn open_stream(
    source: Container,
    kind: Kind,
    topic: Option<&str>,
) -> Result<Box<dyn ImuRecords>, LogError> {
    let name = source.name().to_string();
    open_parts(name, vec![source], kind == Kind::Ros1, topic)
}

/// The `Imu` topic of the recording `name`: a ROS 1 bag (`ros1`), or MCAP files read in
/// sequence.
fn open_parts(
    name: String,
    files: Vec<Container>,
    ros1: bool,
    topic: Option<&str>,
) -> Result<Box<dyn ImuRecords>, LogError> {
    let mut topics = Topics::default();
    if ros1 {
        for f in &files {
            for (t, kind) in super::rosbag1::topics(f)? {
                if kind == ROS1_IMU_TYPE {
                    topics.imu.entry(t.clone()).or_default();
                }
                topics.types.entry(t).or_insert(kind);
            }
        }
        let chosen = choose_topic(&name, &topics, topic, ROS1_IMU)?;
        let bag = files.into_iter().next().expect("a bag is one file");
        return Ok(Box::new(super::rosbag1::Ros1Records::new(bag, chosen)));
    }
    let mut parts = Vec::with_capacity(files.len());
    for f in files {
        let (listed, counts) = super::mcap::topics(&f)?;
        for (t, described) in listed {
            if described.is_imu() {
                topics.imu.entry(t.clone()).or_default();
            }
            topics.types.entry(t).or_insert(described.describe());
        }
        parts.push((f, counts));
    }
    let chosen = choose_topic(&name, &topics, topic, MCAP_IMU)?;
    Ok(Box::new(McapRecords::new(name, parts, chosen)))
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
