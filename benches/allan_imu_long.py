"""`accelcal allan --imu` on a long static recording beside allantools, in one run.

    python3 benches/allan_imu_long.py [--hours 8] [--rate 400] [--dir /tmp/accelcal-long]
                                      [--repeats 3] [--bin target/release/accelcal]

Writes DIR/imu-<hours>h-<rate>hz.mcap once (kept for the next run): sensor_msgs/msg/Imu messages
at RATE Hz, serialized as CDR (the layout rosbags writes, built here with numpy: a fixed frame id
"imu" makes every message 316 bytes), lz4 chunks by the `mcap` package. The six channels are
white noise plus a random walk (accelerometer N = 2e-3 m/s/sqrt(s), K = 1e-3 m/s^2/sqrt(s) on
gravity; gyro N = 1e-4 rad/sqrt(s), K = 5e-5 rad/s/sqrt(s)).

Then, REPEATS times each (in turn with --alternate): the binary on the file under /usr/bin/time -v (wall, peak RSS, and the
temporary disk it used: the least free space of --out's file system during the run, polled every
20 ms, against the free space before), and allantools.oadev (octave tau, in memory, the samples
generated again) on the six channels one after the other. Prints the medians, and the largest
relative difference of the binary's deviation from allantools' within the window (m <= 2^18) and
beyond it (the tau summed from the phase on disk). With --reference, also from a long-double
reference (numpy.longdouble, 64-bit significand: the mean, the phase and each tau's sum of squared
second differences), at every tau, for both.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile
import threading
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


def free_bytes(path):
    st = os.statvfs(path)
    return st.f_bavail * st.f_frsize


def run_binary(binary, path):
    out = Path(tempfile.mkdtemp(prefix="allan-imu-long-"))
    cmd = ["/usr/bin/time", "-v", binary, "allan", "--imu", str(path), "--out", str(out),
           "--quiet"]
    before = free_bytes(out)
    least = [before]
    done = threading.Event()

    def poll():
        while not done.wait(0.02):
            least[0] = min(least[0], free_bytes(out))

    watcher = threading.Thread(target=poll)
    watcher.start()
    start = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    finally:
        done.set()
        watcher.join()
    wall = time.perf_counter() - start
    disk_mb = (before - least[0]) / 1e6
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    cpu = sum(float(re.search(rf"{k} time \(seconds\): ([\d.]+)", p.stderr).group(1))
              for k in ("User", "System"))
    return wall, rss_kb / 1024, cpu, json.loads((out / "allan.json").read_text()), disk_mb


def long_double_adev(y, ms):
    """The overlapping Allan deviation at each m, every step in numpy.longdouble."""
    y = y.astype(np.longdouble)
    x = np.concatenate([np.zeros(1, np.longdouble), np.cumsum(y - y.mean())])
    out = []
    for m in ms:
        m = int(m)
        d = x[2 * m:] - 2 * x[m:-m] + x[:-2 * m]
        mm = np.longdouble(m)
        out.append(np.sqrt(np.sum(d * d) / (2 * len(d) * mm * mm)))
    return np.array(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hours", type=float, default=8.0)
    ap.add_argument("--rate", type=float, default=400.0)
    ap.add_argument("--dir", default="/tmp/accelcal-long")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--bin", default="target/release/accelcal")
    ap.add_argument("--alternate", action="store_true",
                    help="run the binary and allantools in turn, REPEATS rounds (the machine's "
                         "load then falls on both alike)")
    ap.add_argument("--reference", action="store_true",
                    help="compare both with a long-double computation too")
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
    y = np.concatenate([c for _, c in channels(n, a.rate, PIECE)])

    def allantools_six():
        start, c0 = time.perf_counter(), time.process_time()
        devs = []
        for k in range(6):
            taus, dev, _, _ = allantools.oadev(np.ascontiguousarray(y[:, k]), rate=a.rate,
                                               data_type="freq", taus="octave")
            devs.append(dev)
        return time.perf_counter() - start, time.process_time() - c0, devs

    runs, times, cpu = [], [], []
    if a.alternate:
        for _ in range(a.repeats):
            runs.append(run_binary(a.bin, path))
            wall, c, devs = allantools_six()
            times.append(wall)
            cpu.append(c)
    else:
        runs = [run_binary(a.bin, path) for _ in range(a.repeats)]
    walls, rss, cpus = ([r[i] for r in runs] for i in range(3))
    print(f"accelcal allan --imu: wall median {statistics.median(walls):.2f} s "
          f"(min {min(walls):.2f}, max {max(walls):.2f}), CPU median "
          f"{statistics.median(cpus):.2f} s, peak RSS median {statistics.median(rss):.0f} MB "
          f"(max {max(rss):.0f}), temporary disk at most {max(r[4] for r in runs):.0f} MB "
          f"(the phase: {6 * 8 * (n + 1) / 1e6:.0f} MB)")
    if not a.alternate:
        for _ in range(a.repeats):
            wall, c, devs = allantools_six()
            times.append(wall)
            cpu.append(c)
    print(f"allantools.oadev, six channels in memory: wall median {statistics.median(times):.2f} s "
          f"(min {min(times):.2f}, max {max(times):.2f}), CPU median {statistics.median(cpu):.2f} s")
    print("load average after: %.1f %.1f %.1f" % os.getloadavg())
    print(f"ratio of the medians, allantools / accelcal: "
          f"{statistics.median(times) / statistics.median(walls):.2f}")
    columns = ["ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s"]
    worst = {"allantools": [0.0, 0.0], "long double": [0.0, 0.0],
             "allantools vs long double": [0.0, 0.0]}
    for k, column in enumerate(columns):
        ch = runs[0][3]["channels"][column]
        ours = np.array(ch["adev_m_s2" if k < 3 else "adev_rad_s"])
        m = np.rint(np.array(ch["tau_s"]) * a.rate).astype(np.int64)
        pairs = [("allantools", ours, devs[k][: len(ours)])]
        if a.reference:
            ref = long_double_adev(y[:, k], m).astype(np.float64)
            pairs += [("long double", ours, ref),
                      ("allantools vs long double", devs[k][: len(ours)], ref)]
        for name, got, want in pairs:
            rel = np.abs(got / want - 1.0)
            worst[name][0] = max(worst[name][0], rel[m <= EXACT_MAX_M].max())
            if (m > EXACT_MAX_M).any():
                worst[name][1] = max(worst[name][1], rel[m > EXACT_MAX_M].max())
    for name, (inside, beyond) in worst.items():
        if name == "allantools" or a.reference:
            print(f"largest relative difference, {name}: {inside:.1e} at m <= 2^18 (window), "
                  f"{beyond:.1e} beyond (phase on disk)")


if __name__ == "__main__":
    main()
