//! A ROS 2 bag: a directory of one recording's files, read here when its storage is MCAP
//! (`ros2 bag record -s mcap`, or `ros2 bag convert`): its `.mcap` files in name order, each read
//! by [`super::mcap`].
//!
//! # Format
//! rosbag2's layout (ros2/rosbag2, `metadata.yaml` of `rosbag2_bagfile_information`): the
//! directory holds `metadata.yaml`, whose `storage_identifier` names the storage (`mcap`, or
//! `sqlite3` for the older default, which is refused), and the storage's files, a split bag's
//! parts numbered in sequence.

use std::path::{Path, PathBuf};

use super::{LogError, unreadable};

/// The MCAP files of a ROS 2 bag directory, in name order (a split bag's parts in sequence).
pub(super) fn bag_files(dir: &Path) -> Result<Vec<PathBuf>, LogError> {
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
