"""calibrate of a 1 h, 1 kHz log (3.6·10⁶ samples, 3 600 fixes at 1 Hz): from numpy arrays, by
the command line on the same log as CSV, and pandas.read_csv of that CSV alone, in one run;
medians of REPEATS runs each (docs/SPEED.md). Needs pandas; the binary from ACCELCAL_BIN or
target/release/accelcal.

    python python/bench/speed.py [DIR]
"""

import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import pandas as pd

import accelcal

REPEATS = 7
RATE_HZ = 1000.0
DURATION_S = 3600.0


def drive():
    """A sinusoidal drive (2 m/s² at 0.05 Hz) with a 0.05 m/s² bias, white accelerometer noise
    (σ 0.01 m/s²) and GPS at 1 Hz (σ 0.5 m, 0.05 m/s)."""
    rng = np.random.default_rng(1)
    n = int(DURATION_S * RATE_HZ)
    t = np.arange(n) / RATE_HZ
    w, amplitude = 2 * np.pi * 0.05, 2.0
    a = amplitude * np.sin(w * t) + 0.05 + 0.01 * rng.standard_normal(n)
    gt = np.arange(0.0, DURATION_S, 1.0) + 0.0005
    p = amplitude / w * gt - amplitude / w**2 * np.sin(w * gt) + 0.5 * rng.standard_normal(gt.size)
    v = amplitude / w * (1 - np.cos(w * gt)) + 0.05 * rng.standard_normal(gt.size)
    return t, a, gt, p, v


def write_csv(path, columns, arrays):
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in zip(*(x.tolist() for x in arrays)):
            f.write(",".join(map(repr, row)) + "\n")


def median_s(run):
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), min(times), max(times)


def main():
    root = pathlib.Path(__file__).resolve().parents[2]
    binary = os.environ.get("ACCELCAL_BIN", str(root / "target" / "release" / "accelcal"))
    work = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp())
    t, a, gt, p, v = drive()
    accel_csv, gps_csv = work / "accel.csv", work / "gps.csv"
    write_csv(accel_csv, ["t_s", "accel_m_s2"], [t, a])
    write_csv(gps_csv, ["t_s", "position_m", "velocity_m_s"], [gt, p, v])
    out = work / "out"
    cli = [binary, "calibrate", "--accel", accel_csv, "--gps", gps_csv, "--out", out, "--quiet"]
    subprocess.run(cli, check=True, capture_output=True)
    from_arrays = accelcal.calibrate(t, a, gt, p, v)
    same = from_arrays.estimates_csv == (out / "estimates.csv").read_text()
    rows = {
        "accelcal.calibrate from arrays": median_s(lambda: accelcal.calibrate(t, a, gt, p, v)),
        "accelcal calibrate (command line, CSV)": median_s(
            lambda: subprocess.run(cli, check=True, capture_output=True)
        ),
        "pandas.read_csv of the accelerometer CSV": median_s(lambda: pd.read_csv(accel_csv)),
    }
    size_mb = accel_csv.stat().st_size / 1e6
    print(f"{t.size} samples, {gt.size} fixes, accelerometer CSV {size_mb:.1f} MB; "
          f"estimates.csv equal to the command's: {same}; {os.cpu_count()} cores; "
          f"numpy {np.__version__}, pandas {pd.__version__}, accelcal {accelcal.__version__}")
    print("| what | median s | min s | max s |")
    print("|---|---|---|---|")
    for name, (med, lo, hi) in rows.items():
        print(f"| {name} | {med:.3f} | {lo:.3f} | {hi:.3f} |")


if __name__ == "__main__":
    main()
