#!/usr/bin/env python3
"""Time `accelcal calibrate --imu --gnss` against KF-GINS on the same recording.

KF-GINS (https://github.com/i2Nav-WHU/KF-GINS) is a C++ GNSS/INS loosely coupled EKF (21 error
states, covariance propagated at every IMU sample). This script

1. converts a recording written by `accelcal simulate --model ins --logs DIR` (imu.csv with mean
   rates over the step ending at t_s, gnss.csv, truth.csv) into KF-GINS's text formats:
   IMU  `t dθx dθy dθz dvx dvy dvz` (rad, m/s: increments over the step ending at t, body axes
        forward-right-down), so increment = mean rate × (t_k − t_{k−1});
   GNSS `t lat_deg lon_deg h_m σN σE σD` (m);
2. writes a KF-GINS YAML with the initial state from truth.csv's first row and the noise of the
   simulation's configuration (`accelcal config --model ins`, overlaid with --sim-config);
3. runs KF-GINS and `accelcal calibrate --imu imu.csv --gnss gnss.csv` alternately, N times each,
   under /usr/bin/time -v (wall, user, sys, peak RSS), and prints medians, min–max and the ratio;
4. optionally times KF-GINS with its three per-epoch output files sent to /dev/null, and a build
   with the per-epoch writes removed (--kfgins-noout), to show what its output costs;
5. compares KF-GINS's last navigation row (and accelcal's final attitude) with truth.csv.

Python 3.11+ (tomllib), standard library and numpy only.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

D2R = math.pi / 180.0
R2D = 180.0 / math.pi
WGS84_A = 6378137.0
WGS84_E2 = 0.0066943799901413156
NAV_FILES = ("KF_GINS_Navresult.nav", "KF_GINS_IMU_ERR.txt", "KF_GINS_STD.txt")


# --------------------------------------------------------------------------------------------
# configuration


def sim_config(accelcal: str, overlay: Path | None) -> dict:
    """The simulation's configuration: accelcal's defaults for --model ins, then the overlay."""
    text = subprocess.run(
        [accelcal, "config", "--model", "ins"], check=True, capture_output=True, text=True
    ).stdout
    cfg = tomllib.loads(text)
    if overlay is not None:
        with open(overlay, "rb") as f:
            user = tomllib.load(f)
        for key, value in user.items():
            if isinstance(value, dict):
                cfg.setdefault(key, {}).update(value)
            else:
                cfg[key] = value
    return cfg


# --------------------------------------------------------------------------------------------
# conversion


def header(path: Path) -> list[str]:
    with open(path) as f:
        return f.readline().strip().split(",")


def first_row(path: Path) -> dict:
    with open(path) as f:
        names = f.readline().strip().split(",")
        values = [float(x) for x in f.readline().strip().split(",")]
    return dict(zip(names, values))


def tail_rows(path: Path, nbytes: int = 1 << 16) -> list[dict]:
    names = header(path)
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        size = f.tell()
        f.seek(max(0, size - nbytes))
        lines = f.read().decode().splitlines()[1:]
    rows = []
    for line in lines:
        parts = line.strip().split(",")
        if len(parts) == len(names):
            try:
                rows.append(dict(zip(names, (float(x) for x in parts))))
            except ValueError:
                pass
    return rows


def convert_imu(src: Path, dst: Path) -> tuple[int, float, float, float]:
    """imu.csv (rates or increments) → KF-GINS IMU text file. Returns rows, rate, t0, t_end."""
    names = header(src)
    data = np.loadtxt(src, delimiter=",", skiprows=1, dtype=np.float64)
    col = {n: i for i, n in enumerate(names)}
    t = data[:, col["t_s"]]
    dt = np.diff(t)
    # The first row's step: the recording's step before it is not in the file (simulate's first
    # row is the mean over (0, t_0]); take the median step, which is what KF-GINS assumes too.
    median = float(np.median(dt))
    dt = np.concatenate(([median], dt))
    rates = ["gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2", "az_m_s2"]
    incs = ["dthx_rad", "dthy_rad", "dthz_rad", "dvx_m_s", "dvy_m_s", "dvz_m_s"]
    if all(n in col for n in rates):
        inc = data[:, [col[n] for n in rates]] * dt[:, None]
    elif all(n in col for n in incs):
        inc = data[:, [col[n] for n in incs]]
    else:
        raise SystemExit(f"{src}: neither rate nor increment columns in {names}")
    out = np.column_stack((t, inc))
    np.savetxt(dst, out, fmt="%.17g", delimiter=" ")
    return len(t), 1.0 / median, float(t[0]), float(t[-1])


def convert_gnss(src: Path, dst: Path, sigma_ned: list[float]) -> int:
    names = header(src)
    data = np.loadtxt(src, delimiter=",", skiprows=1, dtype=np.float64, ndmin=2)
    col = {n: i for i, n in enumerate(names)}
    cols = [data[:, col[n]] for n in ("t_s", "lat_deg", "lon_deg", "height_m")]
    for k, n in enumerate(("sigma_n_m", "sigma_e_m", "sigma_d_m")):
        cols.append(data[:, col[n]] if n in col else np.full(len(data), sigma_ned[k]))
    np.savetxt(dst, np.column_stack(cols), fmt="%.17g", delimiter=" ")
    return len(data)


def kfgins_yaml(path: Path, imu: Path, gnss: Path, out: Path, rate: float, t0: float,
                truth0: dict, cfg: dict) -> dict:
    """KF-GINS's YAML. Initial state: truth's first row (its time is the first IMU row's).
    Noise: the simulation's truth statistics ([imu], [gnss], [initial])."""
    imu_c, gnss_c, init_c = cfg["imu"], cfg["gnss"], cfg["initial"]
    notes = []

    def corr_time_h(model_key: str, tau_key: str) -> float:
        model = imu_c.get(model_key, "gauss_markov")
        if model == "gauss_markov":
            return imu_c[tau_key] / 3600.0
        notes.append(f"{model_key} = {model}: KF-GINS models Gauss-Markov only; τ = 1e4 h used")
        return 1.0e4

    tau_g = corr_time_h("gyro_bias_model", "gyro_bias_correlation_time_s")
    tau_a = corr_time_h("accel_bias_model", "accel_bias_correlation_time_s")
    if abs(tau_g - tau_a) > 1e-9:
        notes.append(f"KF-GINS has one correlation time: the gyro's {tau_g} h used for both")
    floor_ppm = 1.0
    gs = max(imu_c.get("gyro_scale_factor_sigma_ppm", 0.0), floor_ppm)
    as_ = max(imu_c.get("accel_scale_factor_sigma_ppm", 0.0), floor_ppm)
    if gs == floor_ppm or as_ == floor_ppm:
        notes.append(f"scale-factor σ 0 in the simulation: KF-GINS's 6 scale states given {floor_ppm} ppm")
    arw = imu_c["gyro_arw_rad_per_sqrt_s"] * R2D * 60.0          # deg/√h
    vrw = imu_c["accel_vrw_m_s_per_sqrt_s"] * 60.0               # m/s/√h
    gb = imu_c["gyro_bias_sigma_rad_s"] * R2D * 3600.0           # deg/h
    ab = imu_c["accel_bias_sigma_m_s2"] / 1e-5                   # mGal
    pos_std = init_c["position_sigma_m"]
    vel_std = init_c["velocity_sigma_m_s"]
    tilt, yaw = init_c["tilt_sigma_deg"], init_c["yaw_sigma_deg"]
    lever = gnss_c["gnss_lever_arm_m"]

    def v3(x):
        return "[ " + ", ".join(f"{float(v):.17g}" for v in x) + " ]"

    text = f"""# written by benches/kf_gins.py
imupath: "{imu}"
gnsspath: "{gnss}"
outputpath: "{out}"
imudatalen: 7
imudatarate: {int(round(rate))}
starttime: {t0:.17g}
endtime: -1
initpos: {v3([truth0['lat_deg'], truth0['lon_deg'], truth0['height_m']])}
initvel: {v3([truth0['vn_m_s'], truth0['ve_m_s'], truth0['vd_m_s']])}
initatt: {v3([truth0['roll_deg'], truth0['pitch_deg'], truth0['yaw_deg']])}
initgyrbias: [ 0, 0, 0 ]
initaccbias: [ 0, 0, 0 ]
initgyrscale: [ 0, 0, 0 ]
initaccscale: [ 0, 0, 0 ]
initposstd: {v3([pos_std] * 3)}
initvelstd: {v3([vel_std] * 3)}
initattstd: {v3([tilt, tilt, yaw])}
imunoise:
  arw: {v3([arw] * 3)}
  vrw: {v3([vrw] * 3)}
  gbstd: {v3([gb] * 3)}
  abstd: {v3([ab] * 3)}
  gsstd: {v3([gs] * 3)}
  asstd: {v3([as_] * 3)}
  corrtime: {tau_g:.17g}
antlever: {v3(lever)}
"""
    path.write_text(text)
    return {"arw_deg_sqrt_h": arw, "vrw_m_s_sqrt_h": vrw, "gbstd_deg_h": gb, "abstd_mgal": ab,
            "scale_std_ppm": [gs, as_], "corrtime_h": tau_g, "antlever_m": lever,
            "init_std": [pos_std, vel_std, tilt, yaw], "notes": notes}


# --------------------------------------------------------------------------------------------
# timing


def parse_time_v(stderr: str) -> dict:
    def grab(label: str) -> str:
        m = re.search(r"^\s*" + re.escape(label) + r":\s*(.+)$", stderr, re.M)
        if not m:
            raise RuntimeError(f"/usr/bin/time -v output lacks {label!r}:\n{stderr[-2000:]}")
        return m.group(1).strip()

    wall = 0.0
    for part in grab("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":"):
        wall = wall * 60.0 + float(part)
    return {
        "wall_s": wall,
        "user_s": float(grab("User time (seconds)")),
        "sys_s": float(grab("System time (seconds)")),
        "rss_mib": int(grab("Maximum resident set size (kbytes)")) / 1024.0,
        "cpu_percent": float(grab("Percent of CPU this job got").rstrip("%") or 0),
        "ctx_voluntary": int(grab("Voluntary context switches")),
        "ctx_involuntary": int(grab("Involuntary context switches")),
        "exit": int(grab("Exit status")),
    }


def timed(cmd: list[str], log: Path, before=None) -> dict:
    if before is not None:
        before()
    with open(log, "w") as out:
        t0 = time.perf_counter()
        proc = subprocess.run(["/usr/bin/time", "-v", *cmd], stdout=out,
                              stderr=subprocess.PIPE, text=True)
        outer = time.perf_counter() - t0
    log.with_suffix(".time").write_text(proc.stderr)
    res = parse_time_v(proc.stderr)
    res["outer_wall_s"] = outer
    if proc.returncode != 0 or res["exit"] != 0:
        sys.stderr.write(proc.stderr[-3000:])
        raise SystemExit(f"command failed ({proc.returncode}): {' '.join(cmd)}; log {log}")
    return res


def stats(runs: list[dict], key: str) -> tuple[float, float, float]:
    xs = [r[key] for r in runs]
    return statistics.median(xs), min(xs), max(xs)


def loadavg() -> str:
    return Path("/proc/loadavg").read_text().strip()


def sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


# --------------------------------------------------------------------------------------------
# sanity check


def radii(lat_rad: float) -> tuple[float, float]:
    s2 = math.sin(lat_rad) ** 2
    w = math.sqrt(1.0 - WGS84_E2 * s2)
    return WGS84_A * (1 - WGS84_E2) / w**3, WGS84_A / w


def wrap180(x: float) -> float:
    return (x + 180.0) % 360.0 - 180.0


def truth_at(truth_tail: list[dict], t: float) -> dict:
    best = min(truth_tail, key=lambda r: abs(r["t_s"] - t))
    if abs(best["t_s"] - t) > 1e-6:
        raise SystemExit(f"no truth row at t = {t} (nearest {best['t_s']})")
    return best


def kfgins_check(out_dir: Path, truth_tail: list[dict]) -> dict:
    nav = tail_rows_plain(out_dir / NAV_FILES[0])
    err = tail_rows_plain(out_dir / NAV_FILES[1])
    _, t, lat, lon, h, vn, ve, vd, roll, pitch, yaw = nav
    tr = truth_at(truth_tail, t)
    rm, rn = radii(tr["lat_deg"] * D2R)
    dn = (lat - tr["lat_deg"]) * D2R * (rm + tr["height_m"])
    de = (lon - tr["lon_deg"]) * D2R * (rn + tr["height_m"]) * math.cos(tr["lat_deg"] * D2R)
    dd = -(h - tr["height_m"])
    dv = math.sqrt((vn - tr["vn_m_s"]) ** 2 + (ve - tr["ve_m_s"]) ** 2 + (vd - tr["vd_m_s"]) ** 2)
    gb_est = np.array(err[1:4]) * D2R / 3600.0          # deg/h → rad/s
    ab_est = np.array(err[4:7]) * 1e-5                  # mGal → m/s²
    gb_true = np.array([tr["bgx_rad_s"], tr["bgy_rad_s"], tr["bgz_rad_s"]])
    ab_true = np.array([tr["bax_m_s2"], tr["bay_m_s2"], tr["baz_m_s2"]])
    return {
        "t_s": t,
        "pos_err_m": math.sqrt(dn * dn + de * de + dd * dd),
        "pos_err_ned_m": [dn, de, dd],
        "vel_err_m_s": dv,
        "roll_err_deg": wrap180(roll - tr["roll_deg"]),
        "pitch_err_deg": wrap180(pitch - tr["pitch_deg"]),
        "heading_err_deg": wrap180(yaw - tr["yaw_deg"]),
        "gyro_bias_err_rad_s": (gb_est - gb_true).tolist(),
        "accel_bias_err_m_s2": (ab_est - ab_true).tolist(),
    }


def tail_rows_plain(path: Path) -> list[float]:
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        f.seek(max(0, f.tell() - 4096))
        last = f.read().decode().strip().splitlines()[-1]
    return [float(x) for x in last.split()]


def accelcal_check(out_dir: Path, truth_tail: list[dict], t_end: float) -> dict | None:
    p = out_dir / "summary.json"
    if not p.exists():
        return None
    s = json.loads(p.read_text())
    att = s.get("attitude_deg", {})
    tr = truth_at(truth_tail, t_end)
    gb = np.array(s["gyro_bias_rad_s"]["value"]) - [tr["bgx_rad_s"], tr["bgy_rad_s"], tr["bgz_rad_s"]]
    ab = np.array(s["accel_bias_m_s2"]["value"]) - [tr["bax_m_s2"], tr["bay_m_s2"], tr["baz_m_s2"]]
    return {
        "roll_err_deg": wrap180(att["roll"] - tr["roll_deg"]),
        "pitch_err_deg": wrap180(att["pitch"] - tr["pitch_deg"]),
        "heading_err_deg": wrap180(att["yaw"] - tr["yaw_deg"]),
        "sigma_yaw_deg": att.get("sigma_yaw"),
        "gyro_bias_err_rad_s": gb.tolist(),
        "accel_bias_err_m_s2": ab.tolist(),
        "fixes_used": s.get("fixes_used"),
        "alignment_t_s": (s.get("alignment") or {}).get("t_s"),
    }


# --------------------------------------------------------------------------------------------


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--accelcal", required=True, help="accelcal binary (a copy, not target/)")
    ap.add_argument("--kfgins", required=True, help="KF-GINS binary")
    ap.add_argument("--recording", required=True, type=Path,
                    help="directory of `accelcal simulate --model ins --logs`")
    ap.add_argument("--runs", type=int, default=5, help="timed runs of each tool")
    ap.add_argument("--work", required=True, type=Path, help="scratch directory")
    ap.add_argument("--sim-config", type=Path, default=None,
                    help="the TOML the recording was simulated with (default: accelcal's defaults)")
    ap.add_argument("--kfgins-noout", default=None,
                    help="optional KF-GINS build with the per-epoch writes removed (output cost)")
    ap.add_argument("--output-cost-runs", type=int, default=3,
                    help="runs of KF-GINS with outputs to /dev/null (and of --kfgins-noout); 0: skip")
    args = ap.parse_args()

    rec, work = args.recording.resolve(), args.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    for exe in (args.accelcal, args.kfgins):
        if not os.access(exe, os.X_OK):
            raise SystemExit(f"not executable: {exe}")
    if "/target/" in os.path.realpath(args.accelcal):
        print("note: --accelcal points into a cargo target/ directory; a rebuild mid-run changes it")

    # ---- conversion (untimed)
    cfg = sim_config(args.accelcal, args.sim_config)
    imu_csv, gnss_csv, truth_csv = rec / "imu.csv", rec / "gnss.csv", rec / "truth.csv"
    kf_imu, kf_gnss, kf_yaml = work / "kfgins_imu.txt", work / "kfgins_gnss.txt", work / "kf-gins.yaml"
    kf_out, kf_null, ac_out = work / "kfgins_out", work / "kfgins_devnull", work / "accelcal_out"
    kf_out.mkdir(exist_ok=True)
    t = time.perf_counter()
    n_imu, rate, t0, t_end = convert_imu(imu_csv, kf_imu)
    n_gnss = convert_gnss(gnss_csv, kf_gnss, cfg["gnss"]["gnss_position_sigma_m"])
    truth0 = first_row(truth_csv)
    if abs(truth0["t_s"] - t0) > 1e-9:
        raise SystemExit(f"truth's first row at {truth0['t_s']} s, imu's at {t0} s")
    noise = kfgins_yaml(kf_yaml, kf_imu, kf_gnss, kf_out, rate, t0, truth0, cfg)
    print(f"recording {rec}: {n_imu} IMU rows at {rate:.6g} Hz ({t0:g}–{t_end:g} s), "
          f"{n_gnss} fixes; converted in {time.perf_counter() - t:.1f} s")
    print(f"KF-GINS config {kf_yaml}: ARW {noise['arw_deg_sqrt_h']:.4g} deg/√h, "
          f"VRW {noise['vrw_m_s_sqrt_h']:.4g} m/s/√h, gyro bias {noise['gbstd_deg_h']:.4g} deg/h, "
          f"accel bias {noise['abstd_mgal']:.4g} mGal, τ {noise['corrtime_h']:g} h, "
          f"lever {noise['antlever_m']} m, initial σ pos/vel/tilt/yaw {noise['init_std']}")
    for n in noise["notes"]:
        print(f"  note: {n}")

    # /dev/null variant: the three output files are symlinks to /dev/null
    kf_null.mkdir(exist_ok=True)
    for name in NAV_FILES:
        link = kf_null / name
        if link.is_symlink() or link.exists():
            link.unlink()
        link.symlink_to("/dev/null")
    kf_yaml_null = work / "kf-gins-devnull.yaml"
    kf_yaml_null.write_text(kf_yaml.read_text().replace(f'outputpath: "{kf_out}"',
                                                         f'outputpath: "{kf_null}"'))

    kf_cmd = [args.kfgins, str(kf_yaml)]
    ac_cmd = [args.accelcal, "calibrate", "--imu", str(imu_csv), "--gnss", str(gnss_csv),
              "--out", str(ac_out)]

    def clean_kf():
        for name in NAV_FILES:
            (kf_out / name).unlink(missing_ok=True)

    def clean_ac():
        shutil.rmtree(ac_out, ignore_errors=True)

    print(f"accelcal: {args.accelcal} ({subprocess.run([args.accelcal, '--version'], capture_output=True, text=True).stdout.strip()}, sha256 {sha256(args.accelcal)})")
    print(f"KF-GINS:  {args.kfgins} (sha256 {sha256(args.kfgins)})")
    print("commands (each under /usr/bin/time -v):")
    print("  " + " ".join(kf_cmd))
    print("  " + " ".join(ac_cmd))

    # ---- timed runs, alternating
    load_before = loadavg()
    print(f"loadavg before: {load_before}")
    kf_runs, ac_runs = [], []
    for i in range(args.runs):
        kf_runs.append(timed(kf_cmd, work / f"kfgins_run{i}.log", clean_kf))
        ac_runs.append(timed(ac_cmd, work / f"accelcal_run{i}.log", clean_ac))
        print(f"  run {i + 1}/{args.runs}: KF-GINS {kf_runs[-1]['wall_s']:.2f} s, "
              f"accelcal {ac_runs[-1]['wall_s']:.2f} s; CPU got {kf_runs[-1]['cpu_percent']:.0f} % / "
              f"{ac_runs[-1]['cpu_percent']:.0f} %   (load {loadavg().split()[0]})")
    load_after = loadavg()
    print(f"loadavg after:  {load_after}")

    # what KF-GINS wrote (from the last run, left in place)
    out_rows = sum(1 for _ in open(kf_out / NAV_FILES[0]))
    out_mb = sum((kf_out / n).stat().st_size for n in NAV_FILES) / 1e6
    kf_cost = [float(m.group(1)) for i in range(args.runs)
               for m in [re.search(r"Cost ([0-9.eE+-]+) s in total",
                                   (work / f"kfgins_run{i}.log").read_text())] if m]

    print()
    print(f"{'':22}{'median':>9}{'min':>9}{'max':>9}   (wall s; user+sys s median; peak RSS MiB median)")
    for name, runs in (("KF-GINS", kf_runs), ("accelcal calibrate", ac_runs)):
        med, lo, hi = stats(runs, "wall_s")
        cpu = statistics.median(r["user_s"] + r["sys_s"] for r in runs)
        rss = statistics.median(r["rss_mib"] for r in runs)
        print(f"{name:22}{med:9.3f}{lo:9.3f}{hi:9.3f}   cpu {cpu:.3f} s, RSS {rss:.1f} MiB")
    kf_med, ac_med = stats(kf_runs, "wall_s")[0], stats(ac_runs, "wall_s")[0]
    kf_cpu = statistics.median(r["user_s"] + r["sys_s"] for r in kf_runs)
    ac_cpu = statistics.median(r["user_s"] + r["sys_s"] for r in ac_runs)
    print(f"ratio KF-GINS/accelcal: wall {kf_med / ac_med:.1f}×, cpu {kf_cpu / ac_cpu:.1f}×")
    if kf_cost:
        print(f"KF-GINS's own 'Cost … s in total' (after its start-up): median {statistics.median(kf_cost):.3f} s")
    print(f"KF-GINS writes 3 text files (nav, IMU error, std) with one row per IMU epoch: "
          f"{out_rows} nav rows, {out_mb:.0f} MB per run, inside its timed run")

    # ---- output cost
    result_cost = {}
    if args.output_cost_runs > 0:
        null_runs = [timed([args.kfgins, str(kf_yaml_null)], work / f"kfgins_devnull{i}.log")
                     for i in range(args.output_cost_runs)]
        m_null = stats(null_runs, "wall_s")[0]
        result_cost["devnull"] = null_runs
        line = (f"output cost: KF-GINS with its files → /dev/null: median {m_null:.3f} s "
                f"({m_null - kf_med:+.3f} s, {100 * (m_null - kf_med) / kf_med:+.0f} % against writing files)")
        if args.kfgins_noout:
            no_runs = [timed([args.kfgins_noout, str(kf_yaml_null)], work / f"kfgins_noout{i}.log")
                       for i in range(args.output_cost_runs)]
            m_no = stats(no_runs, "wall_s")[0]
            result_cost["noout"] = no_runs
            line += (f"; build without the per-epoch writes: median {m_no:.3f} s "
                     f"(formatting + writing = {kf_med - m_no:.3f} s, "
                     f"{100 * (kf_med - m_no) / kf_med:.0f} %; ratio to accelcal {m_no / ac_med:.1f}×)")
        print(line)

    # ---- sanity check
    tail = tail_rows(truth_csv)
    kc = kfgins_check(kf_out, tail)
    print(f"KF-GINS vs truth at t = {kc['t_s']:g} s: position error {kc['pos_err_m']:.3f} m "
          f"(N/E/D {kc['pos_err_ned_m'][0]:+.3f}/{kc['pos_err_ned_m'][1]:+.3f}/{kc['pos_err_ned_m'][2]:+.3f}), "
          f"velocity {kc['vel_err_m_s']:.4f} m/s, roll {kc['roll_err_deg']:+.4f}°, "
          f"pitch {kc['pitch_err_deg']:+.4f}°, heading {kc['heading_err_deg']:+.4f}°")
    print(f"  its final bias errors: gyro {np.array2string(np.array(kc['gyro_bias_err_rad_s']), precision=6)} rad/s, "
          f"accel {np.array2string(np.array(kc['accel_bias_err_m_s2']), precision=5)} m/s²")
    acc = accelcal_check(ac_out, tail, t_end)
    if acc:
        print(f"accelcal (no --config: consumer-MEMS defaults, lever arm 0) vs truth at the last fix: "
              f"roll {acc['roll_err_deg']:+.3f}°, pitch {acc['pitch_err_deg']:+.3f}°, "
              f"heading {acc['heading_err_deg']:+.3f}° (σ {acc['sigma_yaw_deg']:.2f}°); "
              f"{acc['fixes_used']} fixes used from t = {acc['alignment_t_s']} s")
        print(f"  its final bias errors: gyro {np.array2string(np.array(acc['gyro_bias_err_rad_s']), precision=6)} rad/s, "
              f"accel {np.array2string(np.array(acc['accel_bias_err_m_s2']), precision=5)} m/s²")

    results = {
        "recording": str(rec), "imu_rows": n_imu, "imu_rate_hz": rate, "fixes": n_gnss,
        "commands": {"kfgins": kf_cmd, "accelcal": ac_cmd},
        "loadavg_before": load_before, "loadavg_after": load_after,
        "kfgins": kf_runs, "accelcal": ac_runs, "kfgins_cost_s": kf_cost,
        "ratio_wall": kf_med / ac_med, "ratio_cpu": kf_cpu / ac_cpu,
        "kfgins_output": {"rows": out_rows, "mb": out_mb}, "output_cost": result_cost,
        "kfgins_noise": noise, "check_kfgins": kc, "check_accelcal": acc,
    }
    (work / "results.json").write_text(json.dumps(results, indent=1))
    print(f"results: {work / 'results.json'}")


if __name__ == "__main__":
    main()
