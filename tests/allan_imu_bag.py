"""Static IMU recordings for tests/allan_imu_bag.rs, made by the ROS tools' own Python packages.

    python3 allan_imu_bag.py OUT N

writes into OUT the same N messages of sensor_msgs/msg/Imu at 200 Hz, serialized as CDR by
rosbags:
- bag/: a ROS 2 bag directory written by rosbags with MCAP storage (topic /imu, and
  /temperature of another type);
- imu.mcap: an MCAP file written by the mcap package (lz4 chunks), topic /imu with a shorter
  frame id (another CDR alignment) and a second Imu topic /imu2;
- imu.csv: its CSV export, t_s = (sec - sec0) + nanosec * 1e-9 and every value as repr writes it
  (shortest round trip);
- imu.bag, imu_lz4.bag, imu_bz2.bag: ROS 1 bags of the same messages written by rosbags (plain,
  lz4 and bz2 chunks), topic /imu and /temperature;
- nan.mcap (a NaN in angular_velocity.y of message 7), back.mcap (message 9's stamp before
  message 8's) and other.mcap (a Temperature topic alone).
"""

import sys
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer as McapWriter
from rosbags.rosbag1 import Writer as Bag1Writer
from rosbags.rosbag2 import StoragePlugin, Writer as BagWriter
from rosbags.typesys import Stores, get_typestore

TS = get_typestore(Stores.ROS2_HUMBLE)
IMU = "sensor_msgs/msg/Imu"
TEMPERATURE = "sensor_msgs/msg/Temperature"
T = TS.types
SEC0 = 1_700_000_000
STEP_NS = 5_000_000


def samples(n):
    rng = np.random.default_rng(31)
    tau0 = STEP_NS * 1e-9
    acc = rng.normal(0.0, 2e-3 / np.sqrt(tau0), (n, 3)) + np.cumsum(
        rng.normal(0.0, 1e-3 * np.sqrt(tau0), (n, 3)), axis=0
    )
    acc[:, 2] -= 9.80665
    gyr = rng.normal(0.0, 1e-4 / np.sqrt(tau0), (n, 3)) + np.cumsum(
        rng.normal(0.0, 5e-5 * np.sqrt(tau0), (n, 3)), axis=0
    )
    stamps = []
    for i in range(n):
        ns = SEC0 * 1_000_000_000 + 123_456_789 + i * STEP_NS
        stamps.append((ns // 1_000_000_000, ns % 1_000_000_000))
    return stamps, acc, gyr


def imu_message(stamp, a, g, frame):
    zeros = np.zeros(9)
    msg = T[IMU](
        header=T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=stamp[0], nanosec=stamp[1]),
            frame_id=frame,
        ),
        orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=zeros,
        angular_velocity=T["geometry_msgs/msg/Vector3"](x=g[0], y=g[1], z=g[2]),
        angular_velocity_covariance=zeros,
        linear_acceleration=T["geometry_msgs/msg/Vector3"](x=a[0], y=a[1], z=a[2]),
        linear_acceleration_covariance=zeros,
    )
    return bytes(TS.serialize_cdr(msg, IMU))


def temperature_message(stamp):
    msg = T[TEMPERATURE](
        header=T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=stamp[0], nanosec=stamp[1]),
            frame_id="t",
        ),
        temperature=25.0,
        variance=0.0,
    )
    return bytes(TS.serialize_cdr(msg, TEMPERATURE))


def nanoseconds(stamp):
    return stamp[0] * 1_000_000_000 + stamp[1]


def write_bag(path, stamps, acc, gyr):
    with BagWriter(path, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        imu = w.add_connection("/imu", IMU, typestore=TS)
        temp = w.add_connection("/temperature", TEMPERATURE, typestore=TS)
        for i, s in enumerate(stamps):
            w.write(imu, nanoseconds(s), imu_message(s, acc[i], gyr[i], "imu_link"))
            if i % 100 == 0:
                w.write(temp, nanoseconds(s), temperature_message(s))


def write_mcap(path, stamps, acc, gyr, topics=("/imu", "/imu2"), temperature=False):
    with open(path, "wb") as f:
        w = McapWriter(f, compression=CompressionType.LZ4)
        w.start(profile="ros2", library="allan_imu_bag.py")
        imu_schema = w.register_schema(name=IMU, encoding="ros2msg", data=b"")
        channels = [
            w.register_channel(topic=t, message_encoding="cdr", schema_id=imu_schema)
            for t in topics
        ]
        temp = None
        if temperature:
            schema = w.register_schema(name=TEMPERATURE, encoding="ros2msg", data=b"")
            temp = w.register_channel(
                topic="/temperature", message_encoding="cdr", schema_id=schema
            )
        for i, s in enumerate(stamps):
            ns = nanoseconds(s)
            for c in channels:
                data = imu_message(s, acc[i], gyr[i], "imu")
                w.add_message(channel_id=c, log_time=ns, data=data, publish_time=ns, sequence=i)
            if temp is not None:
                w.add_message(
                    channel_id=temp, log_time=ns, data=temperature_message(s), publish_time=ns
                )
        w.finish()


def write_bag1(path, stamps, acc, gyr, compression=None):
    ts = get_typestore(Stores.ROS1_NOETIC)
    t = ts.types
    w = Bag1Writer(path)
    if compression is not None:
        w.set_compression(compression)
    with w:
        imu = w.add_connection("/imu", IMU, typestore=ts)
        temp = w.add_connection("/temperature", TEMPERATURE, typestore=ts)
        for i, s in enumerate(stamps):
            header = t["std_msgs/msg/Header"](
                seq=i,
                stamp=t["builtin_interfaces/msg/Time"](sec=s[0], nanosec=s[1]),
                frame_id="imu_link",
            )
            msg = t[IMU](
                header=header,
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.zeros(9),
                angular_velocity=t["geometry_msgs/msg/Vector3"](x=gyr[i][0], y=gyr[i][1], z=gyr[i][2]),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=t["geometry_msgs/msg/Vector3"](
                    x=acc[i][0], y=acc[i][1], z=acc[i][2]
                ),
                linear_acceleration_covariance=np.zeros(9),
            )
            w.write(imu, nanoseconds(s), bytes(ts.serialize_ros1(msg, IMU)))
            if i % 100 == 0:
                tmsg = t[TEMPERATURE](header=header, temperature=25.0, variance=0.0)
                w.write(temp, nanoseconds(s), bytes(ts.serialize_ros1(tmsg, TEMPERATURE)))


def write_csv(path, stamps, acc, gyr):
    lines = ["t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s"]
    sec0 = stamps[0][0]
    for i, (sec, nanosec) in enumerate(stamps):
        t = float(sec - sec0) + float(nanosec) * 1e-9
        values = [t, *acc[i].tolist(), *gyr[i].tolist()]
        lines.append(",".join(repr(float(v)) for v in values))
    Path(path).write_text("\n".join(lines) + "\n")


def main():
    out, n = Path(sys.argv[1]), int(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    stamps, acc, gyr = samples(n)
    write_bag(out / "bag", stamps, acc, gyr)
    write_mcap(out / "imu.mcap", stamps, acc, gyr, temperature=True)
    write_csv(out / "imu.csv", stamps, acc, gyr)
    write_bag1(out / "imu.bag", stamps, acc, gyr)
    write_bag1(out / "imu_lz4.bag", stamps, acc, gyr, Bag1Writer.CompressionFormat.LZ4)
    write_bag1(out / "imu_bz2.bag", stamps, acc, gyr, Bag1Writer.CompressionFormat.BZ2)
    bad = gyr.copy()
    bad[7, 1] = float("nan")
    write_mcap(out / "nan.mcap", stamps[:50], acc, bad, topics=("/imu",))
    back = list(stamps[:50])
    back[9] = back[7]
    write_mcap(out / "back.mcap", back, acc, gyr, topics=("/imu",))
    write_mcap(out / "other.mcap", stamps[:50], acc, gyr, topics=(), temperature=True)


if __name__ == "__main__":
    main()
