#!/usr/bin/env python3
"""The log path on an hour-long 1 kHz log, against pandas reading the same file.

Makes the log once (`accelcal simulate --logs` with a 3600 s, 1000 Hz configuration: 3 600 001
accelerometer rows, 103 MB; 18 000 fixes) and its gzip copy, then times, each the median of
--repeats runs with its minimum and maximum:

- `calibrate` with its default outputs (wall time and peak resident size, /usr/bin/time);
- the same on the .csv.gz log, and through a pipe (`--accel <(gzip -dc …)`);
- `calibrate --estimate-noise`, with the two GPS σ's and with all four statistics;
- `calibrate --every-sample` (MB/s of estimates.csv written);
- `pandas.read_csv` of the accelerometer log (the peer: a Python user's first step);
- the one pass alone in MB/s, with 1 and 2 threads (`cargo bench --bench log_read`).

The load average before and after is printed: the machine may be shared.

    cargo build --release && python3 benches/log_speed.py [--dir DIR] [--repeats R]
"""

import argparse
import gzip
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIG = "[profile]\nduration_s = 3600.0\n\n[accelerometer]\nsample_rate_hz = 1000.0\n"


def binary():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = target / "release" / "accelcal"
    if not path.exists():
        sys.exit(f"{path} is missing: run `cargo build --release` first")
    return str(path)


def make_logs(accelcal, d):
    d.mkdir(parents=True, exist_ok=True)
    (d / "hour.toml").write_text(CONFIG)
    logs = d / "logs"
    if not (logs / "accelerometer.csv").exists():
        subprocess.run(
            [accelcal, "simulate", "--config", "hour.toml", "--logs", "logs"],
            cwd=d,
            check=True,
            stdout=subprocess.DEVNULL,
        )
    gz = logs / "accelerometer.csv.gz"
    if not gz.exists():
        with open(logs / "accelerometer.csv", "rb") as src, gzip.open(gz, "wb", 6) as dst:
            shutil.copyfileobj(src, dst, 1 << 20)
    return logs


def timed(command, cwd):
    """Wall time (s) and peak resident size (MB) of one run through /usr/bin/time."""
    with tempfile.NamedTemporaryFile("r") as report:
        full = ["/usr/bin/time", "-o", report.name, "-f", "%e %M"] + command
        subprocess.run(full, cwd=cwd, check=True, stdout=subprocess.DEVNULL)
        wall, kb = report.read().split()[-2:]
    return float(wall), int(kb) / 1024


def spread(values, fmt="{:.2f}"):
    return (
        f"{fmt.format(statistics.median(values))} "
        f"({fmt.format(min(values))}–{fmt.format(max(values))})"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", default=str(ROOT / "target" / "log-bench"))
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    accelcal = binary()
    d = Path(args.dir)
    logs = make_logs(accelcal, d)
    size_mb = (logs / "accelerometer.csv").stat().st_size / 1e6
    gz_mb = (logs / "accelerometer.csv.gz").stat().st_size / 1e6
    print(f"log: {size_mb:.1f} MB ({gz_mb:.1f} MB gzip); load average {os.getloadavg()}")
    start = time.perf_counter()
    with open(d / "bound.bin", "wb") as f:
        chunk = b"0" * (1 << 20)
        for _ in range(1300):
            f.write(chunk)
        f.flush()
        os.fsync(f.fileno())
    bound = 1300 * 1.048576 / (time.perf_counter() - start)
    os.remove(d / "bound.bin")
    print(f"writing 1.36 GB here (the --every-sample bound): {bound:.0f} MB/s")
    base = ["calibrate", "--config", "hour.toml", "--gps", "logs/gps.csv", "-q"]
    runs = {
        "calibrate (default outputs)": base + ["--accel", "logs/accelerometer.csv", "--out", "o"],
        "calibrate, .csv.gz": base + ["--accel", "logs/accelerometer.csv.gz", "--out", "o"],
        "calibrate --estimate-noise (two GPS σ's)": base
        + ["--accel", "logs/accelerometer.csv", "--out", "o", "--estimate-noise"],
        "calibrate --estimate-noise (σ_p, σ_v, W, K)": base
        + [
            "--accel",
            "logs/accelerometer.csv",
            "--out",
            "o",
            "--estimate-noise",
            "--estimate",
            "gps_position_sigma_m,gps_velocity_sigma_m_s,accel_noise_var_m2_s4,"
            "bias_random_walk_m_s2_per_sqrt_s",
        ],
    }
    rows = []
    for label, command in runs.items():
        results = [timed([accelcal] + command, d) for _ in range(args.repeats)]
        walls, peaks = [r[0] for r in results], [r[1] for r in results]
        rows.append((label, spread(walls) + " s", spread(peaks, "{:.0f}") + " MB"))
    pipe = " ".join(base) + " --accel <(gzip -dc logs/accelerometer.csv.gz) --out o"
    walls = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        subprocess.run(
            ["bash", "-c", f'"{accelcal}" {pipe}'], cwd=d, check=True, stdout=subprocess.DEVNULL
        )
        walls.append(time.perf_counter() - start)
    rows.append(("calibrate, pipe from gzip -dc", spread(walls) + " s", ""))
    rates, walls = [], []
    for _ in range(max(3, args.repeats // 2)):
        command = base + ["--accel", "logs/accelerometer.csv", "--out", "e", "--every-sample"]
        wall, _ = timed([accelcal] + command, d)
        written = (d / "e" / "estimates.csv").stat().st_size / 1e6
        walls.append(wall)
        rates.append(written / wall)
    rows.append(
        (
            f"calibrate --every-sample ({written:.0f} MB written)",
            spread(walls) + " s",
            spread(rates, "{:.0f}") + " MB/s",
        )
    )
    shutil.rmtree(d / "e", ignore_errors=True)
    try:
        import pandas

        walls = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            frame = pandas.read_csv(logs / "accelerometer.csv")
            walls.append(time.perf_counter() - start)
            del frame
        rows.append(
            (
                f"pandas {pandas.__version__} read_csv (peer)",
                spread(walls) + " s",
                spread([size_mb / w for w in walls], "{:.0f}") + " MB/s",
            )
        )
    except ImportError:
        rows.append(("pandas read_csv (peer)", "pandas is not installed", ""))
    for threads in (1, 2):
        out = subprocess.run(
            ["cargo", "bench", "-q", "--bench", "log_read", "--", "--accel",
             str(logs / "accelerometer.csv"), "--gps", str(logs / "gps.csv"),
             "--repeats", str(args.repeats)],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
            env={**os.environ, "RAYON_NUM_THREADS": str(threads)},
        ).stdout
        line = [l for l in out.splitlines() if l.startswith("one pass")][-1]
        rows.append((f"the one pass alone, {threads} thread(s)", "", line.split(": ", 1)[1]))
    print(f"load average after: {os.getloadavg()}\n")
    print("| run | wall, median (min–max) | peak / rate |\n|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} |")


if __name__ == "__main__":
    main()
