"""`accelcal allan --imu` on a long static recording beside allantools, in one run.

    python3 benches/allan_imu_long.py [--hours 8] [--rate 400] [--dir /tmp/accelcal-long]
                                      [--repeats 3] [--bin target/release/accelcal]

Writes DIR/imu-<hours>h-<rate>hz.mcap once (kept for the next run): sensor_msgs/msg/Imu messages
at RATE Hz, serialized as CDR (the layout rosbags writes, built here with numpy: a fixed frame id
"imu" makes every message 316 bytes), lz4 chunks by the `mcap` package. The six channels are
white noise plus a random walk (accelerometer N = 2e-3 m/s/sqrt(s), K = 1e-3 m/s^2/sqrt(s) on
gravity; gyro N = 1e-4 rad/sqrt(s), K = 5e-5 rad/s/sqrt(s)).

Then, REPEATS times each: the binary on the file under /usr/bin/time -v (wall, peak RSS), and
allantools.oadev (octave tau, in memory, the samples generated again) on the six channels one after
the other. Prints the medians, and the largest relative difference of the binary's deviation from
allantools' at the tau computed exactly (m <= 2^18) and at the strided ones.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import allantools
import numpy as np
from mcap.writer import CompressionType, Writer

IMU = "sensor_msgs/msg/Imu"
SEC0 = 1_700_000_000
PIECE = 1 << 20
EXACT_MAX_M = 1 << 18


def channels(n, rate, piece):
    """The samples [n0, n0 + len) of the six channels, piece by piece, from one seed."""
    rng = np.random.default_rng(31)
    tau0 = 1.0 / rate
    white = np.array([2e-3] * 3 + [1e-4] * 3) / np.sqrt(tau0)
    walk = np.array([1e-3] * 3 + [5e-5] * 3) * np.sqrt(tau0)
    bias = np.zeros(6)
    for n0 in range(0, n, piece):
        k = min(piece, n - n0)
        steps = rng.normal(0.0, 1.0, (k, 6)) * walk
        b = bias + np.cumsum(steps, axis=0) - steps
        y = rng.normal(0.0, 1.0, (k, 6)) * white + b
        y[:, 2] -= 9.80665
        bias = b[-1] + steps[-1]
        yield n0, y


def write_mcap(path, n, rate):
    step_ns = round(1e9 / rate)
    dtype = np.dtype([("enc", "<u4"), ("sec", "<i4"), ("nsec", "<u4"), ("idlen", "<u4"),
                      ("id", "S4"), ("v", "<f8", 37)])
    with open(path, "wb") as f:
        w = Writer(f, compression=CompressionType.LZ4)
        w.start("ros2", "accelcal bench")
        schema = w.register_schema(IMU, "ros2msg", b"")
        channel = w.register_channel("/imu", "cdr", schema)
        for n0, y in channels(n, rate, PIECE):
            k = len(y)
            rec = np.zeros(k, dtype)
            rec["enc"] = 0x100  # bytes 00 01 00 00: CDR little-endian
            ns = SEC0 * 1_000_000_000 + (n0 + np.arange(k, dtype=np.int64)) * step_ns
            rec["sec"] = ns // 1_000_000_000
            rec["nsec"] = ns % 1_000_000_000
            rec["idlen"] = 4
            rec["id"] = b"imu"
            rec["v"][:, 3] = 1.0
            rec["v"][:, 13:16] = y[:, 3:6]
            rec["v"][:, 25:28] = y[:, 0:3]
            raw = rec.tobytes()
            for i in range(k):
                t = int(ns[i])
                w.add_message(channel, log_time=t, publish_time=t,
                              data=raw[i * 316:(i + 1) * 316])
        w.finish()


def run_binary(binary, path):
    out = Path(tempfile.mkdtemp(prefix="allan-imu-long-"))
    cmd = ["/usr/bin/time", "-v", binary, "allan", "--imu", str(path), "--out", str(out),
           "--quiet"]
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    cpu = sum(float(re.search(rf"{k} time \(seconds\): ([\d.]+)", p.stderr).group(1))
              for k in ("User", "System"))
    return wall, rss_kb / 1024, cpu, json.loads((out / "allan.json").read_text())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hours", type=float, default=8.0)
    ap.add_argument("--rate", type=float, default=400.0)
    ap.add_argument("--dir", default="/tmp/accelcal-long")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--bin", default="target/release/accelcal")
    a = ap.parse_args()
    n = int(round(a.hours * 3600 * a.rate))
    d = Path(a.dir)
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"imu-{a.hours:g}h-{a.rate:g}hz.mcap"
    if not path.exists():
        start = time.perf_counter()
        write_mcap(path.with_suffix(".part"), n, a.rate)
        path.with_suffix(".part").rename(path)
        print(f"wrote {path} in {time.perf_counter() - start:.0f} s")
    print(f"{path}: {n} messages, {6 * n:.3g} values, {path.stat().st_size / 1e9:.2f} GB; "
          f"allantools {allantools.__version__}, numpy {np.__version__}")

    print("load average before: %.1f %.1f %.1f" % os.getloadavg())
    runs = [run_binary(a.bin, path) for _ in range(a.repeats)]
    walls, rss, cpus = ([r[i] for r in runs] for i in range(3))
    print(f"accelcal allan --imu: wall median {statistics.median(walls):.2f} s "
          f"(min {min(walls):.2f}, max {max(walls):.2f}), CPU median "
          f"{statistics.median(cpus):.2f} s, peak RSS median {statistics.median(rss):.0f} MB "
          f"(max {max(rss):.0f})")

    y = np.concatenate([c for _, c in channels(n, a.rate, PIECE)])
    times, cpu, worst_exact, worst_strided = [], [], 0.0, 0.0
    for rep in range(a.repeats):
        start, c0 = time.perf_counter(), time.process_time()
        devs = []
        for k in range(6):
            taus, dev, _, _ = allantools.oadev(np.ascontiguousarray(y[:, k]), rate=a.rate,
                                               data_type="freq", taus="octave")
            devs.append(dev)
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - c0)
    columns = ["ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s"]
    for k, column in enumerate(columns):
        ch = runs[0][3]["channels"][column]
        ours = np.array(ch["adev_m_s2" if k < 3 else "adev_rad_s"])
        m = np.rint(np.array(ch["tau_s"]) * a.rate)
        rel = np.abs(ours / devs[k][: len(ours)] - 1.0)
        worst_exact = max(worst_exact, rel[m <= EXACT_MAX_M].max())
        if (m > EXACT_MAX_M).any():
            worst_strided = max(worst_strided, rel[m > EXACT_MAX_M].max())
    print(f"allantools.oadev, six channels in memory: wall median {statistics.median(times):.2f} s "
          f"(min {min(times):.2f}, max {max(times):.2f}), CPU median {statistics.median(cpu):.2f} s")
    print("load average after: %.1f %.1f %.1f" % os.getloadavg())
    print(f"largest |accelcal/allantools - 1|: {worst_exact:.1e} at m <= 2^18 (exact), "
          f"{worst_strided:.1e} beyond (strided)")


if __name__ == "__main__":
    main()
