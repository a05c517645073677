"""Every function gives the command line's numbers bit for bit on the same input. Each
comparison has a negative control: the same comparison with one input changed by a tiny amount
(one sample by 10⁻⁶ m/s², another seed) must fail, so an equality that holds by accident
(both sides empty, a constant) would be caught."""

import json

import numpy as np
import pytest

import accelcal
from conftest import COMMA2K19

RATE_HZ = 128.0  # τ₀ = 1/128 s exactly: the median step of t = k/128 is 1/rate_hz, bit for bit


def static_log(samples: int, seed: int) -> np.ndarray:
    """White noise (N) plus a random walk (K), m/s²."""
    rng = np.random.default_rng(seed)
    white = 0.02 * rng.standard_normal(samples)
    walk = np.cumsum(2e-5 * rng.standard_normal(samples))
    return 0.1 + white + walk


def write_log(path, columns, arrays):
    """A CSV log with every number in shortest round-trip form (repr), as the library reads it."""
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in zip(*arrays):
            f.write(",".join(repr(float(x)) for x in row) + "\n")


def test_allan_equals_the_command(cli, tmp_path):
    y = static_log(1 << 14, seed=7)
    t = np.arange(y.size) / RATE_HZ
    log = tmp_path / "static.csv"
    write_log(log, ["t_s", "accel_m_s2"], [t, y])
    out = tmp_path / "allan"
    cli("allan", "--accel", log, "--column", "accel_m_s2", "--confidence", 0.9, "--out", out)
    r = accelcal.allan(y, rate_hz=RATE_HZ, confidence=0.9)
    name = f"{log} (column accel_m_s2)"
    assert r.to_json() == (out / "allan.json").read_text()
    assert r.to_noise_toml(name) == (out / "noise.toml").read_text()
    assert r.to_imu_yaml(name) == (out / "imu.yaml").read_text()
    record = json.loads((out / "allan.json").read_text())
    assert np.array_equal(r.tau_s, np.array(record["tau_s"]))
    assert np.array_equal(r.adev, np.array(record["adev_m_s2"]))
    n = record["fit"]["velocity_random_walk_m_s_per_sqrt_s"]
    assert r.terms["velocity_random_walk_m_s_per_sqrt_s"] == (n["value"], n["lower"], n["upper"])
    # Negative control: one sample moved by 10⁻⁶ m/s² (5·10⁻⁵ of the noise's σ) changes the JSON.
    z = y.copy()
    z[100] += 1e-6
    assert accelcal.allan(z, rate_hz=RATE_HZ, confidence=0.9).to_json() != r.to_json()


# The run's wall time and rate, the only numbers of the JSON that depend on the machine's load.
TIMINGS = ("elapsed_s", "realizations_per_s")


def without_timings(doc):
    for key in TIMINGS:
        assert key in doc["summary"]
        del doc["summary"][key]
    return doc


@pytest.mark.parametrize("engine", ["sample", "epoch"])
def test_ensemble_equals_the_command(cli, tmp_path, engine):
    out = tmp_path / "ensemble.json"
    cli("ensemble", "--realizations", 64, "--seed", 11, "--engine", engine, "--json", out, "--quiet")
    expected = without_timings(json.loads(out.read_text()))
    got = without_timings(accelcal.ensemble(realizations=64, seed=11, engine=engine))
    assert got == expected
    # Negative control: another seed gives other statistics.
    other = without_timings(accelcal.ensemble(realizations=64, seed=12, engine=engine))
    assert other["summary"] != expected["summary"]


def test_config_as_dict_text_and_path_agree(tmp_path):
    text = "[ensemble]\nrealizations = 32\nseed = 4\n"
    path = tmp_path / "c.toml"
    path.write_text(text)
    def run(config):
        return without_timings(accelcal.ensemble(config))

    by_text = run(text)
    assert run(str(path)) == by_text
    assert run(path) == by_text
    assert run({"ensemble": {"realizations": 32, "seed": 4}}) == by_text
    assert run({"ensemble": {"realizations": 32, "seed": 5}}) != by_text


def test_simulate_equals_the_command(cli, tmp_path):
    cli("simulate", "--seed", 3, "--realization", 2, "--logs", tmp_path)
    got = accelcal.simulate(realization=2, seed=3)
    files = {"accel": "accelerometer.csv", "gps": "gps.csv", "truth": "truth.csv"}
    for key, file in files.items():
        names = (tmp_path / file).read_text().partition("\n")[0].split(",")
        data = np.loadtxt(tmp_path / file, delimiter=",", skiprows=1, ndmin=2)
        assert list(got[key]) == names
        for k, name in enumerate(names):
            assert got[key][name].dtype == np.float64
            assert np.array_equal(got[key][name], data[:, k]), (file, name)
    other = accelcal.simulate(realization=3, seed=3)
    assert not np.array_equal(other["accel"]["accel_m_s2"], got["accel"]["accel_m_s2"])


def comma2k19():
    a = np.loadtxt(COMMA2K19 / "accel_gravcomp.csv", delimiter=",", skiprows=1)
    g = np.loadtxt(COMMA2K19 / "gps.csv", delimiter=",", skiprows=1)
    return a[:, 0], a[:, 1], g[:, 0], g[:, 1], g[:, 2]


@pytest.mark.parametrize("estimate", [False, True])
def test_calibrate_equals_the_command_on_comma2k19(cli, tmp_path, estimate):
    args = ["calibrate", "--accel", COMMA2K19 / "accel_gravcomp.csv", "--gps", COMMA2K19 / "gps.csv",
            "--out", tmp_path, "--quiet"]
    if estimate:
        args.append("--estimate-noise")
    cli(*args)
    arrays = comma2k19()
    r = accelcal.calibrate(*arrays, estimate_noise=estimate or None)
    # The summary names the logs: the command's files, the arrays' "accel" and "gps".
    summary = (tmp_path / "summary.json").read_text()
    for key, path, name in [("accelerometer_log", "accel_gravcomp.csv", "accel"), ("gps_log", "gps.csv", "gps")]:
        line = f'"{key}": "{COMMA2K19 / path}"'
        assert line in summary
        summary = summary.replace(line, f'"{key}": "{name}"')
    assert r.summary_json == summary
    assert r.estimates_csv == (tmp_path / "estimates.csv").read_text()
    data = np.loadtxt(tmp_path / "estimates.csv", delimiter=",", skiprows=1)
    assert data.shape[0] == r.estimates["t_s"].size == arrays[2].size
    for k, name in enumerate(r.estimates):
        assert np.array_equal(r.estimates[name], data[:, k], equal_nan=True), name
    assert r.summary == json.loads(summary)
    page = r.html()
    assert page.startswith("<!DOCTYPE html>") and "accelcal.calibrate(" in page
    # Negative control: one accelerometer sample moved by 10⁻⁶ m/s² changes the summary.
    moved = list(arrays)
    moved[1] = arrays[1].copy()
    moved[1][3000] += 1e-6
    assert accelcal.calibrate(*moved, estimate_noise=estimate or None).summary_json != r.summary_json
