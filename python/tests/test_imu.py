"""The three-axis form, ``accelcal.calibrate(imu=…, gnss=…)``: the numbers of
``accelcal calibrate --imu --gnss`` bit for bit (summary.json, every column of estimates.csv) on
the shipped comma2k19 minute and on a simulated drive, each with a negative control; bad input
raises ValueError naming the column and the index."""

import json

import numpy as np
import pytest

import accelcal
from conftest import REPO

COMMA_3D = REPO / "examples" / "comma2k19_3d"


def table(path):
    """A CSV log's columns as float64 arrays (``nan`` read as NaN)."""
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: data[:, k].copy() for k, n in enumerate(names)}


def command_summary(out, imu, gnss):
    """The command's summary.json with the logs named as the arrays name them."""
    summary = (out / "summary.json").read_text()
    for key, path, name in [("imu_file", imu, "imu"), ("gnss_file", gnss, "gnss")]:
        line = f'"{key}": "{path}"'
        assert line in summary
        summary = summary.replace(line, f'"{key}": "{name}"')
    return summary


def assert_equals_the_command(r, out, imu, gnss):
    summary = command_summary(out, imu, gnss)
    assert r.summary_json == summary
    assert r.summary == json.loads(summary)
    assert r.estimates_csv == (out / "estimates.csv").read_text()
    data = table(out / "estimates.csv")
    assert list(r.estimates) == list(data)
    for name, column in data.items():
        assert r.estimates[name].dtype == np.float64
        assert np.array_equal(r.estimates[name], column, equal_nan=True), name
    assert r.estimates["t_s"].size == r.summary["fixes_used"]


@pytest.mark.parametrize("estimate", [None, ["gnss_velocity_sigma_m_s"]])
def test_comma2k19_minute_equals_the_command(cli, tmp_path, estimate):
    imu, gnss = COMMA_3D / "imu.csv", COMMA_3D / "gnss.csv"
    args = ["calibrate", "--imu", imu, "--gnss", gnss, "--out", tmp_path, "--quiet"]
    if estimate:
        args += ["--estimate-noise", "--estimate", ",".join(estimate)]
    cli(*args)
    imu_table, gnss_table = table(imu), table(gnss)
    # vd_m_s is "nan" (not measured) in most rows of the minute.
    assert np.isnan(gnss_table["vd_m_s"]).sum() > 500
    r = accelcal.calibrate(imu=imu_table, gnss=gnss_table, estimate_noise=estimate)
    assert_equals_the_command(r, tmp_path, imu, gnss)
    if estimate:
        keys = r.summary["noise_estimate"]["keys"]
        assert [k["key"] for k in keys] == estimate
    page = r.html()
    assert page.startswith("<!DOCTYPE html>") and "accelcal.calibrate(imu=imu, gnss=gnss" in page
    # Negative control: one gyro sample moved by 10⁻⁹ rad/s changes the summary.
    moved = dict(imu_table)
    moved["gz_rad_s"] = imu_table["gz_rad_s"].copy()
    moved["gz_rad_s"][3000] += 1e-9
    other = accelcal.calibrate(imu=moved, gnss=gnss_table, estimate_noise=estimate)
    assert other.summary_json != r.summary_json


def test_simulated_drive_equals_the_command(cli, tmp_path):
    """A simulated drive of 120 s (``simulate --model ins --logs``), its IMU given as increments
    too: Δv = f·Δt and Δθ = ω·Δt per step, the products the reader forms from the rates, are the
    same steps, so the same estimates; the summary names the other layout."""
    config = tmp_path / "ins.toml"
    text = cli("config", "--model", "ins").stdout
    assert "duration_s = 600.0" in text
    config.write_text(text.replace("duration_s = 600.0", "duration_s = 120.0"))
    logs = tmp_path / "logs"
    cli("simulate", "--model", "ins", "--config", config, "--seed", 5, "--logs", logs, "--quiet")
    imu, gnss = logs / "imu.csv", logs / "gnss.csv"
    out = tmp_path / "out"
    cli("calibrate", "--imu", imu, "--gnss", gnss, "--out", out, "--quiet")
    imu_table, gnss_table = table(imu), table(gnss)
    r = accelcal.calibrate(imu=imu_table, gnss=gnss_table)
    assert_equals_the_command(r, out, imu, gnss)
    assert r.summary["imu_layout"] == "rates"

    # The same drive as increments, written as a log for the command and given as arrays.
    t = imu_table["t_s"]
    dt = np.diff(t, prepend=t[0] - (t[1] - t[0]))
    rates = ["ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s"]
    increments = ["dvx_m_s", "dvy_m_s", "dvz_m_s", "dthx_rad", "dthy_rad", "dthz_rad"]
    inc = {"t_s": t}
    for rate, name in zip(rates, increments):
        inc[name] = imu_table[rate] * dt
    inc_path = tmp_path / "imu_increments.csv"
    with open(inc_path, "w") as f:
        f.write(",".join(inc) + "\n")
        for row in zip(*inc.values()):
            f.write(",".join(repr(float(x)) for x in row) + "\n")
    out_inc = tmp_path / "out_inc"
    cli("calibrate", "--imu", inc_path, "--gnss", gnss, "--out", out_inc, "--quiet")
    r_inc = accelcal.calibrate(imu=inc, gnss=gnss_table)
    assert_equals_the_command(r_inc, out_inc, inc_path, gnss)
    assert r_inc.summary["imu_layout"] == "increments"
    assert r_inc.estimates_csv == r.estimates_csv
    assert r_inc.summary_json != r.summary_json
    # Control: increments twice as large are another drive.
    doubled = {k: (v if k == "t_s" else 2.0 * v) for k, v in inc.items()}
    assert accelcal.calibrate(imu=doubled, gnss=gnss_table).estimates_csv != r.estimates_csv


def comma():
    return table(COMMA_3D / "imu.csv"), table(COMMA_3D / "gnss.csv")


def test_a_dataframe_like_table_is_read_by_column_name():
    class Frame:
        """Only __getitem__ by column name, as a DataFrame gives it."""

        def __init__(self, d):
            self.d = d

        def __getitem__(self, name):
            return self.d[name]

    imu, gnss = comma()
    a = accelcal.calibrate(imu=Frame(imu), gnss=Frame(gnss))
    b = accelcal.calibrate(imu=imu, gnss=gnss)
    assert a.summary_json == b.summary_json
    # A numpy structured array (np.genfromtxt with names=True): its fields are strided views,
    # converted once; "nan" read as NaN.
    imu_s, gnss_s = (
        np.genfromtxt(COMMA_3D / name, delimiter=",", names=True) for name in ("imu.csv", "gnss.csv")
    )
    assert not imu_s["t_s"].flags.c_contiguous
    c = accelcal.calibrate(imu=imu_s, gnss=gnss_s)
    assert c.summary_json == b.summary_json


@pytest.mark.parametrize(
    "log,column",
    [("imu", "t_s"), ("imu", "az_m_s2"), ("imu", "gx_rad_s"), ("gnss", "t_s"), ("gnss", "height_m")],
)
def test_missing_column(log, column):
    imu, gnss = comma()
    del (imu if log == "imu" else gnss)[column]
    with pytest.raises(ValueError, match=rf"^{log}: no column '{column}'"):
        accelcal.calibrate(imu=imu, gnss=gnss)


def test_rates_and_increments_together():
    imu, gnss = comma()
    imu["dvx_m_s"] = imu["ax_m_s2"]
    with pytest.raises(ValueError, match=r"^imu: has both 'ax_m_s2' \(rates\) and 'dvx_m_s'"):
        accelcal.calibrate(imu=imu, gnss=gnss)


@pytest.mark.parametrize("log,column", [("imu", "ay_m_s2"), ("gnss", "lat_deg"), ("gnss", "ve_m_s")])
def test_two_dimensional(log, column):
    imu, gnss = comma()
    t = imu if log == "imu" else gnss
    t[column] = np.stack([t[column], t[column]])
    with pytest.raises(ValueError, match=rf"^{log}\['{column}'\]: a 2-D array of shape \(2, \d+\)"):
        accelcal.calibrate(imu=imu, gnss=gnss)


@pytest.mark.parametrize(
    "log,column,value,words",
    [
        ("imu", "gy_rad_s", np.nan, "a finite number"),
        ("imu", "t_s", np.inf, "a finite number"),
        ("gnss", "lon_deg", np.nan, "a finite number"),
        # An optional column takes NaN (not measured), not an infinity.
        ("gnss", "vn_m_s", np.inf, r"a finite number or NaN \(not measured\)"),
    ],
)
def test_not_finite_names_column_and_index(log, column, value, words):
    imu, gnss = comma()
    t = imu if log == "imu" else gnss
    t[column] = t[column].copy()
    t[column][23] = value
    with pytest.raises(ValueError, match=rf"^{log}\['{column}'\]\[23\] is {value}: expected {words}"):
        accelcal.calibrate(imu=imu, gnss=gnss)


@pytest.mark.parametrize("log", ["imu", "gnss"])
def test_unsorted_time_names_the_index(log):
    imu, gnss = comma()
    t = (imu if log == "imu" else gnss)["t_s"]
    t[40], t[41] = t[41], t[40]
    with pytest.raises(ValueError, match=rf"^{log}\['t_s'\]\[41\] = .* is not after {log}\['t_s'\]\[40\]"):
        accelcal.calibrate(imu=imu, gnss=gnss)


@pytest.mark.parametrize("log,column", [("imu", "gz_rad_s"), ("gnss", "height_m"), ("gnss", "vd_m_s")])
def test_mismatched_lengths(log, column):
    imu, gnss = comma()
    t = imu if log == "imu" else gnss
    t[column] = t[column][:-3]
    n = t["t_s"].size
    with pytest.raises(ValueError, match=rf"^{log}\['{column}'\] has {n - 3} values and {log}\['t_s'\] has {n}"):
        accelcal.calibrate(imu=imu, gnss=gnss)


def test_the_library_names_the_line_of_a_range_error(cli, tmp_path):
    """A latitude beyond 90° is the library's check: the same message as the command's, with
    the log called gnss and row i on line i + 2."""
    imu, gnss = comma()
    gnss["lat_deg"][30] = 91.0
    with pytest.raises(ValueError, match=r"^gnss, line 32: `lat_deg` = 91 is outside") as raised:
        accelcal.calibrate(imu=imu, gnss=gnss)
    text = (COMMA_3D / "gnss.csv").read_text().splitlines()
    fields = text[31].split(",")
    fields[1] = "91"
    text[31] = ",".join(fields)
    bad = tmp_path / "gnss"
    bad.write_text("\n".join(text) + "\n")
    done = cli("calibrate", "--imu", COMMA_3D / "imu.csv", "--gnss", bad, "--out", tmp_path / "o", check=False)
    assert done.returncode == 2
    assert str(raised.value) in done.stderr


def test_bad_estimate_key_and_both_forms():
    imu, gnss = comma()
    with pytest.raises(ValueError, match=r'^estimate_noise: "gps_position_sigma_m" is not a statistic'):
        accelcal.calibrate(imu=imu, gnss=gnss, estimate_noise=["gps_position_sigma_m"])
    with pytest.raises(ValueError, match=r"^accel_t given with imu/gnss"):
        accelcal.calibrate(imu["t_s"], imu=imu, gnss=gnss)
    with pytest.raises(ValueError, match=r"^gnss: None"):
        accelcal.calibrate(imu=imu)


def test_the_result_is_usable_from_another_thread():
    import threading

    imu, gnss = comma()
    r = accelcal.calibrate(imu=imu, gnss=gnss)
    pages = []
    worker = threading.Thread(target=lambda: pages.append(r.html()))
    worker.start()
    worker.join()
    assert pages and pages[0] == r.html()


@pytest.mark.parametrize("estimate", [None, ["gnss_velocity_sigma_m_s"]])
def test_scale_factors_equal_the_command(cli, tmp_path, estimate):
    """``[filter] error_states = 21``: the six scale factors in summary.json and estimates.csv,
    the command's bit for bit; the shipped minute (no turns) leaves them undetermined."""
    imu, gnss = COMMA_3D / "imu.csv", COMMA_3D / "gnss.csv"
    config = tmp_path / "scale.toml"
    config.write_text("[filter]\nerror_states = 21\n")
    out = tmp_path / "out"
    args = ["calibrate", "--imu", imu, "--gnss", gnss, "--config", config, "--out", out, "--quiet"]
    if estimate:
        args += ["--estimate-noise", "--estimate", ",".join(estimate)]
    cli(*args)
    r = accelcal.calibrate(imu=table(imu), gnss=table(gnss), config=config, estimate_noise=estimate)
    assert_equals_the_command(r, out, imu, gnss)
    for key in ("gyro_scale_factor_ppm", "accel_scale_factor_ppm"):
        assert r.summary[key]["identifiable"] == [False, False, False]
    assert "smoothed_sgz_ppm" in r.estimates
    page = r.html()
    assert "gyro scale factor, z" in page
    assert "Not determined: the gyro scale factor x" in page
    assert "A scale factor shows only through the motion it multiplies" in page
    # Control: the 15-state calibration has no scale factors.
    plain = accelcal.calibrate(imu=table(imu), gnss=table(gnss))
    assert "gyro_scale_factor_ppm" not in plain.summary
