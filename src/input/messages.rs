//! The `sensor_msgs/Imu` message of a ROS recording decoded: its stamp, angular velocity and
//! linear acceleration (orientation and covariances are skipped).
//!
//! # Format
//! The message is `sensor_msgs/Imu.msg` (ros2/common_interfaces for ROS 2's
//! `sensor_msgs/msg/Imu`, ros/common_msgs for ROS 1's `sensor_msgs/Imu`): a header (stamp, frame
//! id), then orientation (4 float64), its covariance (9), angular velocity (3), its covariance
//! (9), linear acceleration (3), its covariance (9).
//! - ROS 2 serializes it as CDR (OMG DDS-XTypes 1.3, §7.4.3.5): a 4-byte encapsulation header,
//!   then every primitive aligned to its size; the header is {i32 sec, u32 nanosec, string
//!   frame_id}.
//! - ROS 1 serializes it little-endian and unaligned: the header is {u32 seq, u32 sec, u32 nsec,
//!   string frame_id as u32 length + bytes}.

use super::records::Record;
use super::{LogError, unreadable};

/// The ROS 2 type of an IMU message.
pub const ROS2_IMU_TYPE: &str = "sensor_msgs/msg/Imu";

/// The ROS 1 type of an IMU message.
pub const ROS1_IMU_TYPE: &str = "sensor_msgs/Imu";

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
    let short = || {
        format!(
            "{} bytes: too short for a {ROS2_IMU_TYPE} message",
            data.len()
        )
    };
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

/// Decodes a ROS 1 serialized `sensor_msgs/Imu`.
pub(super) fn decode_ros1(data: &[u8]) -> Option<ImuMessage> {
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

/// The `Imu` message `index` of `topic`, or the error naming it.
pub(super) fn decode_ros1_message(
    file: &str,
    topic: &str,
    index: usize,
    data: &[u8],
) -> Result<ImuMessage, LogError> {
    decode_ros1(data).ok_or_else(|| {
        let at = format!("{file}, topic {topic}, message {index}");
        unreadable(
            &at,
            format!(
                "{} bytes: too short for a {ROS1_IMU_TYPE} message",
                data.len()
            ),
        )
    })
}

/// The little-endian u32 at byte `at` of `b`, if `b` holds it (ROS 1's serialization and its
/// bag's records).
pub(super) fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
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
