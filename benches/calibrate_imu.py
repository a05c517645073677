#!/usr/bin/env python3
"""`calibrate --imu --gnss` on a 720 000-row recording, against pandas reading the same file.

The issue's target is one hour of 200 Hz IMU with 1 Hz GNSS (720 000 rows, about 60 MB) in
≤ 1 s on 2 cores with peak memory ≤ 64 MB. The three-axis drive is at most 600 s long, so the
recording here has the same number of IMU rows at six times the rate: `accelcal simulate
--model ins --logs` of the default drive with `[imu] imu_rate_hz = 1200` (720 000 rows, 600
fixes at 1 Hz instead of the hour's 3 600; every row is one mechanization step either way, and
a fix's update costs a few steps). Then, each the median of --repeats runs with min and max:

- `accelcal calibrate --imu imu.csv --gnss gnss.csv` with its default outputs (wall time and
  peak resident size from /usr/bin/time), all threads and one;
- `pandas.read_csv` of the same imu.csv (the peer: a Python user's first step), in the same run;
- both again on imu7.csv, the same rows with the time stamps to the microsecond and the sensor
  columns to 7 significant digits (simulate writes the
  shortest decimals that read back to the same f64, 17 digits: 103 MB; a real IMU's 16-bit
  samples need about 7, which gives the issue's 60 MB or so), with gnss7.csv, its fixes' times
  rounded alike so that they stay on samples;
- imu.csv with gnss_between.csv, every fix 0.4 ms (half a step) later: each fix between two
  IMU samples, as in a real recording.

The load average before and after is printed: the machine may be shared.

    cargo build --release && python3 benches/calibrate_imu.py [--dir DIR] [--repeats R]
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIG = 'model = "ins"\n\n[imu]\nimu_rate_hz = 1200.0\n'


def binary():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = target / "release" / "accelcal"
    if not path.exists():
        sys.exit(f"{path} is missing: run `cargo build --release` first")
    return str(path)


def make_logs(accelcal, d):
    d.mkdir(parents=True, exist_ok=True)
    (d / "fine.toml").write_text(CONFIG)
    logs = d / "logs"
    if not (logs / "imu.csv").exists():
        subprocess.run(
            [accelcal, "simulate", "-q", "--model", "ins", "--config", "fine.toml",
             "--logs", "logs"],
            cwd=d,
            check=True,
            stdout=subprocess.DEVNULL,
        )
    short = logs / "imu7.csv"
    if not short.exists():
        import pandas

        frame = pandas.read_csv(logs / "imu.csv")
        # The time stamps to the microsecond, not to 7 digits (which would jitter the steps).
        frame["t_s"] = frame["t_s"].map("{:.6f}".format)
        frame.to_csv(short, index=False, float_format="%.7g")
        fixes = pandas.read_csv(logs / "gnss.csv")
        fixes["t_s"] = fixes["t_s"].map("{:.6f}".format)
        fixes.to_csv(logs / "gnss7.csv", index=False, float_format="%.17g")
        fixes = pandas.read_csv(logs / "gnss.csv")
        fixes["t_s"] = fixes["t_s"] + 0.0004
        fixes.to_csv(logs / "gnss_between.csv", index=False, float_format="%.17g")
    return logs


def timed(command, cwd, env=None):
    """Wall time (s) and peak resident size (MB) of one run through /usr/bin/time."""
    with tempfile.NamedTemporaryFile("r") as report:
        full = ["/usr/bin/time", "-o", report.name, "-f", "%e %M"] + command
        subprocess.run(full, cwd=cwd, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, env={**os.environ, **(env or {})})
        wall, kb = report.read().split()[-2:]
    return float(wall), int(kb) / 1024


def spread(values, fmt="{:.2f}"):
    return (
        f"{fmt.format(statistics.median(values))} "
        f"({fmt.format(min(values))}–{fmt.format(max(values))})"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", default=str(ROOT / "target" / "imu-bench"))
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    accelcal = binary()
    d = Path(args.dir)
    logs = make_logs(accelcal, d)
    print(f"{os.cpu_count()} cores; load average {os.getloadavg()}")
    with open(logs / "gnss.csv") as f:
        fixes = sum(1 for _ in f) - 1
    table = []
    for name, gnss in (("imu.csv", "gnss.csv"), ("imu7.csv", "gnss7.csv"),
                       ("imu.csv", "gnss_between.csv")):
        imu = logs / name
        size_mb = imu.stat().st_size / 1e6
        with open(imu) as f:
            rows = sum(1 for _ in f) - 1
        print(f"{name}: {rows} rows, {size_mb:.1f} MB; {gnss}: {fixes} fixes")
        command = [accelcal, "calibrate", "-q", "--imu", f"logs/{name}", "--gnss",
                   f"logs/{gnss}", "--out", "o"]
        warnings = subprocess.run(command, cwd=d, check=True, capture_output=True,
                                  text=True).stderr
        print(f"the calibration's warnings: {warnings.strip() or 'none'}")
        medians = {}
        for label, env in (("all threads", None), ("1 thread", {"RAYON_NUM_THREADS": "1"})):
            results = [timed(command, d, env) for _ in range(args.repeats)]
            walls, peaks = [r[0] for r in results], [r[1] for r in results]
            medians[label] = statistics.median(walls)
            table.append((f"{name} ({size_mb:.0f} MB), {gnss}: `calibrate`, {label}",
                          spread(walls) + " s", spread(peaks, "{:.0f}") + " MB"))
        import pandas

        walls = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            frame = pandas.read_csv(imu)
            walls.append(time.perf_counter() - start)
            del frame
        medians["pandas"] = statistics.median(walls)
        ratio = medians["all threads"] / medians["pandas"]
        table.append((f"{name}: pandas {pandas.__version__} `read_csv` (peer)",
                      spread(walls) + " s",
                      spread([size_mb / w for w in walls], "{:.0f}") + " MB/s; "
                      f"calibrate / read_csv {ratio:.2f}"))
    print(f"load average after: {os.getloadavg()}\n")
    print("| run | wall, median (min–max) | peak / rate |\n|---|---|---|")
    for r in table:
        print(f"| {r[0]} | {r[1]} | {r[2]} |")


if __name__ == "__main__":
    main()
