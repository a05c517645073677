"""Bad input raises ValueError (or FileNotFoundError) naming the argument and the index, with
the command line's message where the command line has one; never a crash of the interpreter."""

import re

import numpy as np
import pytest

import accelcal
from conftest import COMMA2K19


def arrays():
    a = np.loadtxt(COMMA2K19 / "accel_gravcomp.csv", delimiter=",", skiprows=1)
    g = np.loadtxt(COMMA2K19 / "gps.csv", delimiter=",", skiprows=1)
    return [a[:, 0], a[:, 1], g[:, 0], g[:, 1], g[:, 2]]


NAMES = ["accel_t", "accel", "gps_t", "gps_position", "gps_velocity"]


def with_changed(k, value):
    args = arrays()
    args[k] = value(args[k])
    return args


@pytest.mark.parametrize("k", range(5))
def test_wrong_dtype(k):
    args = with_changed(k, lambda a: a.astype(str))
    with pytest.raises(ValueError, match=rf"^{NAMES[k]}: dtype <U\d+ is not a real number type"):
        accelcal.calibrate(*args)


@pytest.mark.parametrize("k", range(5))
def test_two_dimensional(k):
    args = with_changed(k, lambda a: np.stack([a, a]))
    with pytest.raises(ValueError, match=rf"^{NAMES[k]}: a 2-D array of shape \(2, \d+\)"):
        accelcal.calibrate(*args)


@pytest.mark.parametrize("k", range(5))
def test_nan_names_the_index(k):
    def nan(a):
        a = a.copy()
        a[17] = np.nan
        return a

    with pytest.raises(ValueError, match=rf"^{NAMES[k]}\[17\] is nan: expected a finite number"):
        accelcal.calibrate(*with_changed(k, nan))


@pytest.mark.parametrize("k", [0, 2])
def test_unsorted_time_names_the_index(k):
    def swap(t):
        t = t.copy()
        t[40], t[41] = t[41], t[40]
        return t

    with pytest.raises(ValueError, match=rf"^{NAMES[k]}\[41\] = .* is not after {NAMES[k]}\[40\]"):
        accelcal.calibrate(*with_changed(k, swap))


@pytest.mark.parametrize("k", [1, 3, 4])
def test_mismatched_lengths(k):
    with pytest.raises(ValueError, match=rf"^{NAMES[k]} has \d+ values and \w+ has \d+"):
        accelcal.calibrate(*with_changed(k, lambda a: a[:-1]))


def test_other_real_dtypes_and_strides_are_converted_once():
    args = arrays()
    # A float64, contiguous array is the data handed on, not a copy; any other is copied once.
    a = np.ascontiguousarray(args[1])
    assert accelcal._vector("accel", a) is a
    assert not np.shares_memory(accelcal._vector("accel", a.astype(np.float32)), a)
    base = accelcal.calibrate(*args).summary_json
    # A strided view of the same doubles: converted to a contiguous copy, the same numbers.
    wide = np.stack([args[1], args[1]], axis=1)
    strided = list(args)
    strided[1] = wide[:, 0]
    assert not strided[1].flags.c_contiguous
    assert accelcal.calibrate(*strided).summary_json == base
    # Integers are converted to float64.
    t = np.arange(1 << 12, dtype=np.int64)
    y = np.random.default_rng(2).integers(-50, 50, t.size)
    assert accelcal.allan(y, rate_hz=1.0).to_json() == accelcal.allan(y.astype(float), rate_hz=1.0).to_json()


def test_allan_errors_are_the_commands():
    with pytest.raises(ValueError, match="the log has 10 samples; the Allan analysis needs at least"):
        accelcal.allan(np.arange(10.0), rate_hz=100.0)
    with pytest.raises(ValueError, match="every sample is the same number"):
        accelcal.allan(np.ones(1000), rate_hz=100.0)
    with pytest.raises(ValueError, match="the confidence is 1.5; expected a number strictly between 0 and 1"):
        accelcal.allan(np.random.default_rng(1).standard_normal(1000), rate_hz=100.0, confidence=1.5)
    with pytest.raises(ValueError, match="rate_hz = -1"):
        accelcal.allan(np.random.default_rng(1).standard_normal(1000), rate_hz=-1)


def test_config_errors_are_the_commands(cli, tmp_path):
    missing = tmp_path / "missing.toml"
    done = cli("ensemble", "--config", missing, check=False)
    assert done.returncode == 2
    with pytest.raises(FileNotFoundError) as e:
        accelcal.ensemble(missing)
    assert str(e.value) in done.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text("[ensemble]\nrealizations = 0\n")
    done = cli("ensemble", "--config", bad, check=False)
    assert done.returncode == 2
    with pytest.raises(ValueError) as e:
        accelcal.ensemble(bad)
    assert str(e.value) in done.stderr and "bad.toml:2:" in str(e.value)
    with pytest.raises(ValueError, match=re.escape("engine = \"fast\"")):
        accelcal.ensemble(engine="fast")
    with pytest.raises(ValueError, match="estimate_noise: \"no_such_key\""):
        accelcal.calibrate(*arrays(), estimate_noise=["no_such_key"])
