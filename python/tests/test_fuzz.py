"""The Python surface under mutated calls: a few hundred calls with arrays and arguments changed
at random (dtype, shape, length, NaN, infinities, huge and tiny numbers, repeated or reversed
time stamps, bad configurations) must each return or raise ValueError / FileNotFoundError —
never another exception, and never end the interpreter. The calls run in a child interpreter,
so that a crash fails the test instead of ending pytest."""

import subprocess
import sys

from conftest import COMMA2K19

CALLS = 300

CHILD = r'''
import sys
import numpy as np
import accelcal

rng = np.random.default_rng(int(sys.argv[1]))
a = np.loadtxt(sys.argv[2] + "/accel_gravcomp.csv", delimiter=",", skiprows=1)[:1500]
g = np.loadtxt(sys.argv[2] + "/gps.csv", delimiter=",", skiprows=1)[:120]
base = [a[:, 0], a[:, 1], g[:, 0], g[:, 1], g[:, 2]]
SPECIAL = [np.nan, np.inf, -np.inf, 1e308, -1e308, 5e-324, 0.0, -0.0, 1e20]

def pick(good, bad):
    """Mostly the good value, sometimes one of the bad ones."""
    return good if rng.random() < 0.75 else bad[int(rng.integers(len(bad)))]

def mutate(x):
    x = np.array(x, copy=True)
    kind = rng.integers(10)
    if kind == 0:
        return x.astype(rng.choice(["float32", "int64", "complex128", "object", "bool", "U8"]))
    if kind == 1:
        return np.stack([x, x], axis=int(rng.integers(2)))
    if kind == 2:
        return x[: int(rng.integers(0, x.size + 1))]
    if kind == 3:
        x[int(rng.integers(x.size))] = rng.choice(SPECIAL)
        return x
    if kind == 4:
        return x[::-1]
    if kind == 5:
        i = int(rng.integers(1, x.size))
        x[i] = x[i - 1]
        return x
    if kind == 6:
        return x * rng.choice([1e-12, 1e12, -1.0])
    if kind == 7:
        return x[::2]
    if kind == 8:
        return x.tolist()
    return x

CONFIGS = [None, "[filter]\nbias_model = 'gauss_markov'\n", "[accelerometer]\nsample_rate_hz = -1\n",
           "not toml at all =", {"filter": {"gps_position_sigma_m": 0.0}}, "/no/such/file.toml",
           {"initial": {"position_mean_m": float("1e300")}}, "[[x]]\n", {"unknown": 1}]
done = failed = 0
reasons = {}
for n in range({calls}):
    what = rng.integers(4)
    try:
        if what < 2:
            args = [mutate(x) if rng.random() < 0.3 else x for x in base]
            estimate = [None, True, ["gps_position_sigma_m"], ["nonsense"]][int(rng.integers(4))]
            accelcal.calibrate(*args, config=pick(None, CONFIGS), estimate_noise=estimate,
                               confidence=pick(0.95, [0.0, 1.0, np.nan]))
        elif what == 2:
            y = mutate(a[:, 1]) if rng.random() < 0.7 else a[:64, 1]
            accelcal.allan(y, rate_hz=pick(100.0, [0.0, -1.0, np.inf, 1e-300]),
                           confidence=pick(0.683, [0.0, 2.0, np.nan]))
        else:
            accelcal.ensemble(pick(None, CONFIGS), realizations=pick(16, [0, 1, -1]),
                              seed=int(rng.integers(0, 2**63)), engine=pick("epoch", ["sample", "x"]))
        done += 1
    except (ValueError, FileNotFoundError) as e:
        failed += 1
        reasons[str(e).split(":")[0][:40]] = reasons.get(str(e).split(":")[0][:40], 0) + 1
print(done, failed)
print(sorted(reasons.items(), key=lambda r: -r[1])[:12], file=sys.stderr)
'''


def test_mutated_calls_return_or_raise_value_errors():
    child = subprocess.run(
        [sys.executable, "-c", CHILD.replace("{calls}", str(CALLS)), "5", str(COMMA2K19)],
        capture_output=True, text=True, timeout=300,
    )
    assert child.returncode == 0, child.stderr[-3000:]
    done, failed = map(int, child.stdout.split())
    assert done + failed == CALLS
    # The mutations reach both sides: some calls succeed, most are refused.
    assert done >= 10 and failed >= CALLS // 3, (done, failed)


IMU_CALLS = 120

CHILD_IMU = r'''
import sys
import numpy as np
import accelcal

rng = np.random.default_rng(int(sys.argv[1]))
def table(path, rows):
    return {k: v for k, v in (lambda d: [(n, d[n].copy()) for n in d.dtype.names])(
        np.genfromtxt(path, delimiter=",", names=True)[:rows])}
# The minute's first 30 s: the alignment needs a moving course, which it has by then.
imu = table(sys.argv[2] + "/imu.csv", 3000)
gnss = table(sys.argv[2] + "/gnss.csv", 600)
within = gnss["t_s"] <= imu["t_s"][-1]
gnss = {k: v[within] for k, v in gnss.items()}
SPECIAL = [np.nan, np.inf, -np.inf, 1e308, -1e308, 5e-324, 0.0, -0.0, 1e20, 91.0, -1.0]
INCREMENTS = ["dvx_m_s", "dvy_m_s", "dvz_m_s", "dthx_rad", "dthy_rad", "dthz_rad"]

def mutate(x):
    x = np.array(x, copy=True)
    kind = rng.integers(9)
    if kind == 0:
        return x.astype(rng.choice(["float32", "int64", "complex128", "object", "bool", "U8"]))
    if kind == 1:
        return np.stack([x, x], axis=int(rng.integers(2)))
    if kind == 2:
        return x[: int(rng.integers(0, x.size + 1))]
    if kind == 3:
        x[int(rng.integers(x.size))] = rng.choice(SPECIAL)
        return x
    if kind == 4:
        return x[::-1]
    if kind == 5:
        i = int(rng.integers(1, x.size))
        x[i] = x[i - 1]
        return x
    if kind == 6:
        return x * rng.choice([1e-12, 1e12, -1.0])
    if kind == 7:
        return x.tolist()
    return x

def mutated(t):
    t = dict(t)
    for name in list(t):
        if rng.random() < 0.15:
            t[name] = mutate(t[name])
    r = rng.random()
    if r < 0.05:
        del t[rng.choice(list(t))]
    elif r < 0.08:
        t[rng.choice(INCREMENTS)] = t["t_s"]
    elif r < 0.10:
        return [None, 5, [1.0, 2.0], "imu.csv", np.zeros(3)][int(rng.integers(5))]
    return t

CONFIGS = [None, "[imu]\naxes = 'flu'\n", "[gnss]\ngnss_velocity_sigma_m_s = -1\n", "not toml =",
           {"alignment": {"window_s": 0.0}}, "/no/such/file.toml", {"unknown": 1}]
done = failed = 0
reasons = {}
for n in range({calls}):
    try:
        config = CONFIGS[int(rng.integers(len(CONFIGS)))] if rng.random() < 0.2 else None
        estimate = ["nonsense"] if rng.random() < 0.05 else None
        accelcal.calibrate(imu=mutated(imu), gnss=mutated(gnss), config=config,
                           estimate_noise=estimate)
        done += 1
    except (ValueError, FileNotFoundError) as e:
        failed += 1
        key = str(e).split(":")[0][:40]
        reasons[key] = reasons.get(key, 0) + 1
print(done, failed)
print(sorted(reasons.items(), key=lambda r: -r[1])[:12], file=sys.stderr)
'''


def test_mutated_three_axis_calls_return_or_raise_value_errors():
    child = subprocess.run(
        [sys.executable, "-c", CHILD_IMU.replace("{calls}", str(IMU_CALLS)), "7",
         str(COMMA2K19.parent / "comma2k19_3d")],
        capture_output=True, text=True, timeout=300,
    )
    assert child.returncode == 0, child.stderr[-3000:]
    done, failed = map(int, child.stdout.split())
    assert done + failed == IMU_CALLS
    # The mutations reach both sides: some calls succeed, many are refused.
    assert done >= 10 and failed >= IMU_CALLS // 4, (done, failed)
