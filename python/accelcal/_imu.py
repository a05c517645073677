"""The three-axis form of ``accelcal.calibrate``: a 6-axis IMU log and a GNSS log given as
tables of columns (a dict of numpy arrays, a pandas DataFrame, a numpy structured array:
anything indexed by column name), checked here and handed to the library as float64 arrays."""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

#: The IMU log's columns when it holds rates (s, m/s², rad/s), as ``calibrate --imu`` reads them.
RATE_COLUMNS = ("t_s", "ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s")
#: Its columns when it holds increments over each step (s, m/s, rad).
INCREMENT_COLUMNS = ("t_s", "dvx_m_s", "dvy_m_s", "dvz_m_s", "dthx_rad", "dthy_rad", "dthz_rad")
#: The GNSS log's required columns (s, °, °, m; WGS-84, ellipsoidal height).
GNSS_COLUMNS = ("t_s", "lat_deg", "lon_deg", "height_m")
#: Its optional columns: velocity NED (m/s), the position's σ's NED (m), the velocity's σ's
#: (m/s); NaN where not measured.
GNSS_OPTIONAL = (
    "vn_m_s",
    "ve_m_s",
    "vd_m_s",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
    "sigma_vn_m_s",
    "sigma_ve_m_s",
    "sigma_vd_m_s",
)

_MISSING = object()


def _get(table: Any, log: str, column: str) -> Any:
    """``table[column]``, or ``_MISSING`` when the table has no such column."""
    if table is None:
        raise ValueError(f"{log}: None; expected a table of columns (a dict of arrays, a DataFrame)")
    not_a_table = ValueError(
        f"{log}: a {type(table).__name__}; expected a table of columns indexed by name "
        "(a dict of arrays, a DataFrame, a numpy structured array)"
    )
    if not hasattr(table, "__getitem__") or isinstance(table, (str, bytes)):
        raise not_a_table
    try:
        return table[column]
    except (KeyError, ValueError):
        # KeyError: a dict, a DataFrame; ValueError: a numpy structured array's missing field.
        return _MISSING
    except (TypeError, IndexError):
        # A list or a plain array: indexed by position, not by name.
        raise not_a_table from None


def _array(name: str, x: Any, allow_nan: bool) -> np.ndarray:
    """``x`` as a 1-D contiguous float64 array (no copy when it is one) of finite numbers, NaN
    allowed where ``allow_nan`` (an optional column's "not measured")."""
    a = np.asarray(x)
    if a.dtype.kind not in "fiu":
        raise ValueError(
            f"{name}: dtype {a.dtype} is not a real number type; expected float64 "
            "(integer and other float types are converted once)"
        )
    if a.ndim != 1:
        raise ValueError(f"{name}: a {a.ndim}-D array of shape {a.shape}; expected a 1-D array")
    a = np.ascontiguousarray(a, dtype=np.float64)
    bad = np.flatnonzero(np.isinf(a) if allow_nan else ~np.isfinite(a))
    if bad.size:
        i = int(bad[0])
        words = "a finite number or NaN (not measured)" if allow_nan else "a finite number"
        raise ValueError(f"{name}[{i}] is {float(a[i])}: expected {words}")
    return a


def increasing(name: str, t: np.ndarray) -> np.ndarray:
    """`t` when its time stamps increase, else the ValueError naming the first that does not
    (the one-axis and the three-axis forms share it)."""
    bad = np.flatnonzero(~(np.diff(t) > 0.0))
    if bad.size:
        i = int(bad[0]) + 1
        raise ValueError(
            f"{name}[{i}] = {float(t[i])!r} s is not after {name}[{i - 1}] = {float(t[i - 1])!r} s: "
            "time stamps must increase"
        )
    return t


def same_length(time_name: str, t: np.ndarray, name: str, x: np.ndarray) -> None:
    """The ValueError of a column `name` whose length is not its time stamps' (`time_name`)."""
    if x.size != t.size:
        raise ValueError(
            f"{name} has {x.size} values and {time_name} has {t.size}: expected one value "
            f"per time stamp (index {min(x.size, t.size)} has no partner)"
        )


def imu_columns(imu: Any) -> Tuple[np.ndarray, List[np.ndarray], str]:
    """The IMU table's time stamps, its six columns and its layout ("rates" or "increments"),
    chosen as the log reader chooses from a header."""
    rate = next((c for c in RATE_COLUMNS[1:] if _get(imu, "imu", c) is not _MISSING), None)
    increment = next((c for c in INCREMENT_COLUMNS[1:] if _get(imu, "imu", c) is not _MISSING), None)
    if rate is not None and increment is not None:
        raise ValueError(
            f"imu: has both {rate!r} (rates) and {increment!r} (increments); expected the "
            f"columns {', '.join(RATE_COLUMNS)} or {', '.join(INCREMENT_COLUMNS)}"
        )
    names, layout = (INCREMENT_COLUMNS, "increments") if increment else (RATE_COLUMNS, "rates")
    arrays = []
    for c in names:
        x = _get(imu, "imu", c)
        if x is _MISSING:
            raise ValueError(
                f"imu: no column {c!r}; expected the columns {', '.join(RATE_COLUMNS)} or "
                f"{', '.join(INCREMENT_COLUMNS)}"
            )
        arrays.append(_array(f"imu[{c!r}]", x, allow_nan=False))
    t = increasing("imu['t_s']", arrays[0])
    for c, x in zip(names[1:], arrays[1:]):
        same_length("imu['t_s']", t, f"imu[{c!r}]", x)
    return t, arrays[1:], layout


def gnss_columns(gnss: Any) -> Tuple[List[np.ndarray], List[Optional[np.ndarray]]]:
    """The GNSS table's required columns and its optional ones (None where absent)."""
    required = []
    for c in GNSS_COLUMNS:
        x = _get(gnss, "gnss", c)
        if x is _MISSING:
            raise ValueError(
                f"gnss: no column {c!r}; expected the columns {', '.join(GNSS_COLUMNS)} and "
                f"optionally {', '.join(GNSS_OPTIONAL)}"
            )
        required.append(_array(f"gnss[{c!r}]", x, allow_nan=False))
    t = increasing("gnss['t_s']", required[0])
    optional: List[Optional[np.ndarray]] = []
    for c in GNSS_OPTIONAL:
        x = _get(gnss, "gnss", c)
        optional.append(None if x is _MISSING else _array(f"gnss[{c!r}]", x, allow_nan=True))
    for c, x in zip(GNSS_COLUMNS[1:] + GNSS_OPTIONAL, required[1:] + optional):
        if x is not None:
            same_length("gnss['t_s']", t, f"gnss[{c!r}]", x)
    return required, optional


def csv_columns(text: str) -> Dict[str, np.ndarray]:
    """A CSV's columns as float64 arrays (``nan`` read as NaN)."""
    head, _, body = text.partition("\n")
    names = head.split(",")
    rows = [line.split(",") for line in body.splitlines() if line]
    data = np.array(rows, dtype=np.float64).reshape(len(rows), len(names))
    return {n: np.ascontiguousarray(data[:, k]) for k, n in enumerate(names)}


def _triad(values: List[Optional[float]]) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


class ImuCalibrationResult:
    """A three-axis calibration (``accelcal calibrate --imu --gnss``): ``summary``
    (summary.json as a dict: the gyro biases rad/s and the accelerometer biases m/s² with σ's,
    intervals and whether the drive determined them, the attitude at the end in °, the NIS and
    whiteness tests, the alignment, the assumptions), ``estimates`` (estimates.csv's columns as
    numpy arrays, one entry per fix: position °/m, velocity m/s, attitude °, biases, their σ's,
    innovations, NIS; then the smoothed attitude and biases), ``gyro_bias_rad_s`` and
    ``accel_bias_m_s2`` (the biases at the end, body x, y, z) and ``html()``."""

    def __init__(self, result: Any, command: str) -> None:
        self._result = result
        self._command = command
        self.summary_json: str = result.summary_json()
        self.estimates_csv: str = result.estimates_csv()
        self.summary: Dict[str, Any] = json.loads(self.summary_json)
        self.estimates: Dict[str, np.ndarray] = csv_columns(self.estimates_csv)
        self.gyro_bias_rad_s = _triad(self.summary["gyro_bias_rad_s"]["value"])
        self.accel_bias_m_s2 = _triad(self.summary["accel_bias_m_s2"]["value"])

    def html(self) -> str:
        """The calibration's page (``index.html``): self-contained HTML."""
        return self._result.html(self._command)

    def __repr__(self) -> str:
        return (
            f"ImuCalibrationResult(gyro_bias_rad_s={self.gyro_bias_rad_s.tolist()}, "
            f"accel_bias_m_s2={self.accel_bias_m_s2.tolist()})"
        )
