//! A ROS 1 bag's chosen `Imu` topic read from disk record by record, a chunk at a time
//! (`visit_ros1`), as [`Record`]s for [`super::stream`]: no bag is held whole.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::Channel;
use super::rosbag1::{IMU_TYPE, Ros1Event, decode_message, visit_ros1};
use super::stream::{ImuRecords, Record};
use crate::input::{LogError, LogProblem};

/// The chosen `Imu` topic of a ROS 1 bag, as records of the six channels read from disk each
/// time.
pub struct Ros1Records {
    path: PathBuf,
    topic: String,
    /// The first message's whole second, once read.
    sec0: Cell<Option<i64>>,
}

impl Ros1Records {
    /// The `Imu` topic `topic` of the bag at `path`.
    pub(super) fn new(path: &Path, topic: String) -> Self {
        Self {
            path: path.to_path_buf(),
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
        let file = self.path.display().to_string();
        // Messages per `Imu` topic: every one is decoded, as the whole-series reader does.
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        visit_ros1(&self.path, &mut |event| {
            let Ros1Event::Message(topic, kind, data) = event else {
                return Ok(());
            };
            if kind != IMU_TYPE {
                return Ok(());
            }
            if !counts.contains_key(topic) {
                counts.insert(topic.to_string(), 0);
            }
            let k = counts.get_mut(topic).expect("inserted");
            let m = decode_message(&file, topic, *k, data)?;
            let at = *k as u64;
            *k += 1;
            if topic != self.topic {
                return Ok(());
            }
            visit(&m.record(&self.sec0, at))
        })
    }

    fn error_at(&self, at: u64, problem: LogProblem) -> LogError {
        let at = format!(
            "{}, topic {}, message {at}",
            self.path.display(),
            self.topic
        );
        LogError::of_file(&at, problem)
    }

    fn error(&self, problem: LogProblem) -> LogError {
        let at = format!("{}, topic {}", self.path.display(), self.topic);
        LogError::of_file(&at, problem)
    }
}
