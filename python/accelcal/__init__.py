"""accelcal: accelerometer calibration with GPS and sensor-noise analysis.

A Rust core with numpy arrays in and out; every function gives the numbers of the command line
(``accelcal allan``, ``accelcal ensemble``, ``accelcal simulate --logs``,
``accelcal calibrate``, ``accelcal calibrate --imu --gnss``) on the same input, bit for bit.

Arrays: a 1-D float64 contiguous array is read in place; any other real dtype (integers,
float32) or a strided view is converted to float64 once. A dtype that is not a real number
(object, string, complex, bool), a 2-D array, arrays of different lengths, a NaN or infinity,
or time stamps that do not increase raise ``ValueError`` naming the argument and the index.
Configurations: ``None`` (the defaults), a path (``str`` or ``os.PathLike``), TOML text, or a
dict with the keys of the TOML file. A configuration file that does not exist raises
``FileNotFoundError``; every other bad input raises ``ValueError`` with the command line's
message. Long work releases the GIL, and Ctrl-C raises KeyboardInterrupt within 0.1 s: an
ensemble or an Allan analysis stops (its workers poll a flag between blocks); a noise estimate
or a three-axis calibration goes on in the background until it ends, its result dropped.
"""

from __future__ import annotations

import io
import json
import os
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from accelcal import _accelcal, _imu
from accelcal._accelcal import __version__
from accelcal._imu import ImuCalibrationResult

__all__ = [
    "__version__",
    "AllanResult",
    "CalibrationResult",
    "ImuCalibrationResult",
    "Term",
    "allan",
    "calibrate",
    "default_config",
    "ensemble",
    "simulate",
]

ConfigLike = Union[None, str, "os.PathLike[str]", Dict[str, Any]]

#: The interval confidence of ``allan`` when none is given: one standard deviation of a normal.
DEFAULT_ALLAN_CONFIDENCE = 0.683


def default_config() -> str:
    """The default configuration file, as ``accelcal config`` prints it (TOML text)."""
    return _accelcal.default_config()


def _config(config: ConfigLike) -> Tuple[Optional[str], Optional[str]]:
    """(kind, value) of a configuration: ("file", path), ("text", toml), ("dict", toml)."""
    if config is None:
        return None, None
    if isinstance(config, dict):
        return "dict", _accelcal.toml_of_json(json.dumps(config, allow_nan=False))
    if isinstance(config, os.PathLike):
        return "file", os.fspath(config)
    if isinstance(config, str):
        # TOML text has a line end, a table or a key; a path has none of them.
        if "\n" in config or "=" in config or config.lstrip().startswith("["):
            return "text", config
        return "file", config
    raise ValueError(
        f"config: a {type(config).__name__}; expected None, a path, TOML text or a dict"
    )


def _vector(name: str, x: Any) -> np.ndarray:
    """``x`` as a 1-D contiguous float64 array of finite numbers (no copy when it is one)."""
    a = np.asarray(x)
    if a.dtype.kind not in "fiu":
        raise ValueError(
            f"{name}: dtype {a.dtype} is not a real number type; expected float64 "
            "(integer and other float types are converted once)"
        )
    if a.ndim != 1:
        raise ValueError(f"{name}: a {a.ndim}-D array of shape {a.shape}; expected a 1-D array")
    a = np.ascontiguousarray(a, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{name}[{i}] is {float(a[i])}: expected a finite number")
    return a


def _times(name: str, x: Any) -> np.ndarray:
    """A time-stamp vector, s: finite and increasing."""
    return _imu.increasing(name, _vector(name, x))


_same_length = _imu.same_length


def _nan(values: Sequence[Optional[float]]) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


class Term(NamedTuple):
    """A fitted noise term: ``value`` with its interval [``lower``, ``upper``]; an unresolved
    term has ``value`` and ``lower`` None and ``upper`` its upper bound."""

    value: Optional[float]
    lower: Optional[float]
    upper: float


class AllanResult:
    """The Allan analysis of rate samples (``accelcal allan``'s ``allan.json``).

    Arrays (one entry per τ of the octave grid):
      ``tau_s`` (s), ``adev`` (m/s²), ``adev_lower`` / ``adev_upper`` (m/s², the χ² interval;
      NaN where no EDF applies), ``edf`` (Greenhall & Riley; NaN likewise), ``noise_alpha``
      (the power-law exponent α identified; NaN where none).
    Terms (``terms``: a dict of :class:`Term`):
      ``velocity_random_walk_m_s_per_sqrt_s`` (N, m/s/√s), ``bias_instability_m_s2`` (B, m/s²),
      ``acceleration_random_walk_m_s2_per_sqrt_s`` (K, m/s²/√s) and, when the shortest τ shows
      phase noise, ``quantization_m_s`` (Q, m/s).
    """

    def __init__(self, analysis: Any) -> None:
        self._analysis = analysis
        self._json = analysis.json()
        record = json.loads(self._json)
        self.record: Dict[str, Any] = record
        self.samples: int = record["samples"]
        self.sample_period_s: float = record["sample_period_s"]
        self.confidence: float = record["confidence"]
        self.tau_s = np.array(record["tau_s"], dtype=np.float64)
        self.adev = np.array(record["adev_m_s2"], dtype=np.float64)
        self.adev_lower = _nan(record["adev_lower_m_s2"])
        self.adev_upper = _nan(record["adev_upper_m_s2"])
        self.edf = _nan(record["edf"])
        self.noise_alpha = _nan(record["noise_alpha"])
        fit = record["fit"]
        self.fit_tau_s = np.array(fit["tau_s"], dtype=np.float64)
        self.terms: Dict[str, Term] = {}
        for key in (
            "velocity_random_walk_m_s_per_sqrt_s",
            "bias_instability_m_s2",
            "acceleration_random_walk_m_s2_per_sqrt_s",
            "quantization_m_s",
        ):
            t = fit.get(key)
            if t is not None:
                upper = np.nan if t["upper"] is None else t["upper"]
                self.terms[key] = Term(t["value"], t["lower"], upper)

    def to_json(self) -> str:
        """``allan.json`` as ``accelcal allan`` writes it."""
        return self._json

    def to_noise_toml(self, source: str = "numpy array") -> str:
        """``noise.toml`` (the [filter] statistics for calibrate), naming ``source``."""
        return self._analysis.noise_toml(source)

    def to_imu_yaml(self, source: str = "numpy array") -> str:
        """``imu.yaml`` (Kalibr's IMU noise file), naming ``source``."""
        return self._analysis.imu_yaml(source)

    def __repr__(self) -> str:
        return f"AllanResult(samples={self.samples}, sample_period_s={self.sample_period_s}, terms={self.terms})"


def allan(y: Any, rate_hz: float, *, confidence: float = DEFAULT_ALLAN_CONFIDENCE) -> AllanResult:
    """The overlapping Allan deviation of a static log's rate samples ``y`` (m/s²) taken at
    ``rate_hz`` (Hz; τ₀ = 1/rate_hz s), with χ² intervals at ``confidence`` and the fitted
    noise terms N, B, K (and Q): ``accelcal allan`` on a column of samples.

    Raises ValueError for a bad array, a rate that is not a positive finite number, a
    confidence outside (0, 1), fewer samples than the fit needs, or a constant log.
    """
    values = _vector("y", y)
    rate = float(rate_hz)
    if not (np.isfinite(rate) and rate > 0.0):
        raise ValueError(f"rate_hz = {rate_hz}: expected a positive finite number (Hz)")
    return AllanResult(_accelcal.allan_analysis(values, 1.0 / rate, float(confidence)))


def ensemble(
    config: ConfigLike = None,
    *,
    realizations: Optional[int] = None,
    seed: Optional[int] = None,
    engine: str = "sample",
) -> Dict[str, Any]:
    """One Monte Carlo ensemble with its checks' verdicts: the JSON of ``accelcal ensemble``
    (``--realizations``, ``--seed``, ``--engine``) as a dict. ``engine`` is "sample" (every
    accelerometer sample drawn) or "epoch" (one exact draw per GPS interval)."""
    kind, value = _config(config)
    text = _accelcal.ensemble_json(kind, value, _count("realizations", realizations), _count("seed", seed), engine)
    return json.loads(text)


def _count(name: str, n: Optional[int]) -> Optional[int]:
    if n is None:
        return None
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"{name} = {n!r}: expected a whole number ≥ 0")
    return int(n)


def _columns(text: bytes) -> Dict[str, np.ndarray]:
    """A CSV log's columns as float64 arrays (the text holds shortest round-trip numbers: the
    arrays are the doubles the library computed)."""
    head, _, body = text.partition(b"\n")
    names = head.decode().split(",")
    data = np.loadtxt(io.BytesIO(body), delimiter=",", dtype=np.float64, ndmin=2)
    if data.size == 0:
        data = np.empty((0, len(names)))
    return {n: np.ascontiguousarray(data[:, k]) for k, n in enumerate(names)}


def simulate(
    config: ConfigLike = None, *, realization: int = 0, seed: Optional[int] = None
) -> Dict[str, Dict[str, np.ndarray]]:
    """One simulated drive's sensor logs, as ``accelcal simulate --logs`` writes them:
    ``{"accel": {"t_s", "accel_m_s2"}, "gps": {"t_s", "position_m", "velocity_m_s"},
    "truth": {"t_s", "position_m", "velocity_m_s", "bias_m_s2"}}`` of numpy arrays (s, m/s²,
    m, m/s). Realization ``realization`` of the random streams of ``seed``."""
    kind, value = _config(config)
    r = _count("realization", realization)
    accel, gps, truth = _accelcal.simulate_logs(kind, value, r, _count("seed", seed))
    return {"accel": _columns(accel), "gps": _columns(gps), "truth": _columns(truth)}


class CalibrationResult:
    """A calibration (``accelcal calibrate``): ``summary`` (summary.json as a dict),
    ``estimates`` (estimates.csv's columns as numpy arrays, one entry per GPS fix: estimates in
    m, m/s, m/s², their σ in the same units, innovations and NIS), ``bias_m_s2`` and
    ``bias_sigma_m_s2`` (the bias and its σ at the end of the log, m/s²) and ``html()``."""

    def __init__(self, result: Any, command: str) -> None:
        self._result = result
        self._command = command
        self.summary_json: str = result.summary_json()
        self.estimates_csv: str = result.estimates_csv()
        self.summary: Dict[str, Any] = json.loads(self.summary_json)
        self.estimates: Dict[str, np.ndarray] = _columns(self.estimates_csv.encode())
        self.bias_m_s2: float = self.summary["bias_m_s2"]
        self.bias_sigma_m_s2: float = self.summary["bias_sigma_m_s2"]

    def html(self) -> str:
        """The calibration's page (``index.html``): self-contained HTML."""
        return self._result.html(self._command)

    def __repr__(self) -> str:
        return f"CalibrationResult(bias_m_s2={self.bias_m_s2}, bias_sigma_m_s2={self.bias_sigma_m_s2})"


def calibrate(
    accel_t: Any = None,
    accel: Any = None,
    gps_t: Any = None,
    gps_position: Any = None,
    gps_velocity: Any = None,
    *,
    imu: Any = None,
    gnss: Any = None,
    config: ConfigLike = None,
    estimate_noise: Union[None, bool, Sequence[str]] = None,
    confidence: float = 0.95,
) -> Union[CalibrationResult, ImuCalibrationResult]:
    """Calibrates an accelerometer or a whole IMU with GPS: ``accelcal calibrate``.

    One axis: the accelerometer's samples (``accel_t`` s, ``accel`` m/s²) and the GPS fixes
    (``gps_t`` s, ``gps_position`` m, ``gps_velocity`` m/s): the filter, the smoother and the
    NIS test of ``accelcal calibrate --accel --gps``; returns a :class:`CalibrationResult`.

    Three axes (``accelcal calibrate --imu --gnss``): ``imu`` and ``gnss`` are tables of
    columns (a dict of 1-D arrays, a pandas DataFrame: anything indexed by column name) with
    the logs' columns. ``imu``: ``t_s`` (s) and either the rates ``ax_m_s2, ay_m_s2, az_m_s2``
    (m/s²), ``gx_rad_s, gy_rad_s, gz_rad_s`` (rad/s) or the increments ``dvx_m_s, dvy_m_s,
    dvz_m_s`` (m/s), ``dthx_rad, dthy_rad, dthz_rad`` (rad) over the step ending at ``t_s``.
    ``gnss``: ``t_s`` (s), ``lat_deg``, ``lon_deg`` (°, WGS-84), ``height_m`` (m, ellipsoidal)
    and optionally ``vn_m_s, ve_m_s, vd_m_s`` (m/s) and the σ's ``sigma_n_m, sigma_e_m,
    sigma_d_m`` (m), ``sigma_vn_m_s, sigma_ve_m_s, sigma_vd_m_s`` (m/s), NaN where not
    measured. Returns an :class:`ImuCalibrationResult`. Messages call the logs ``imu`` and
    ``gnss`` and row ``i`` their line ``i + 2`` (as in the CSV, after its header).

    ``config``: the configuration (for three axes, the keys of ``calibrate --imu --config``).
    ``estimate_noise``: None or False for the configured statistics; True for
    ``--estimate-noise`` (the default statistics); a list of keys for ``--estimate-noise
    --estimate KEYS``. ``confidence``: of the noise estimate's intervals, in (0, 1).

    Ctrl-C raises KeyboardInterrupt within 0.1 s; a noise estimate or a three-axis filter then
    ends in the background (their loops poll no flag), its result dropped.
    """
    if imu is not None or gnss is not None:
        given = [n for n, x in zip(_ONE_AXIS, (accel_t, accel, gps_t, gps_position, gps_velocity)) if x is not None]
        if given:
            raise ValueError(
                f"{given[0]} given with imu/gnss: the one-axis arrays and the three-axis tables "
                "are two forms of the call; give one"
            )
        return _calibrate_imu(imu, gnss, config, estimate_noise, confidence)
    missing = [n for n, x in zip(_ONE_AXIS, (accel_t, accel, gps_t, gps_position, gps_velocity)) if x is None]
    if missing:
        raise ValueError(
            f"{missing[0]} is missing: give accel_t, accel, gps_t, gps_position, gps_velocity "
            "(one axis) or imu=…, gnss=… (three axes)"
        )
    at = _times("accel_t", accel_t)
    a = _vector("accel", accel)
    _same_length("accel_t", at, "accel", a)
    gt = _times("gps_t", gps_t)
    gp = _vector("gps_position", gps_position)
    gv = _vector("gps_velocity", gps_velocity)
    _same_length("gps_t", gt, "gps_position", gp)
    _same_length("gps_t", gt, "gps_velocity", gv)
    keys = _keys(estimate_noise)
    kind, value = _config(config)
    command = "accelcal.calibrate(accel_t, accel, gps_t, gps_position, gps_velocity"
    command += _command_options(kind, value, keys, confidence) + ")"
    result = _accelcal.calibrate_arrays(at, a, gt, gp, gv, kind, value, keys, float(confidence))
    return CalibrationResult(result, command)


_ONE_AXIS = ("accel_t", "accel", "gps_t", "gps_position", "gps_velocity")


def _keys(estimate_noise: Union[None, bool, str, Sequence[str]]) -> Optional[List[str]]:
    """The keys of ``--estimate`` (empty: the defaults), or None for no estimation."""
    if estimate_noise is None or estimate_noise is False:
        return None
    if estimate_noise is True:
        return []
    if isinstance(estimate_noise, str):
        return [k.strip() for k in estimate_noise.split(",") if k.strip()]
    return [str(k) for k in estimate_noise]


def _command_options(kind: Optional[str], value: Optional[str], keys: Optional[List[str]], confidence: float) -> str:
    """The keyword arguments of the call, as the page's command line shows them."""
    out = ""
    if kind == "file":
        out += f", config={value!r}"
    elif kind is not None:
        out += ", config=…"
    if keys is not None:
        out += f", estimate_noise={keys if keys else True!r}"
        if confidence != 0.95:
            out += f", confidence={confidence!r}"
    return out


def _calibrate_imu(
    imu: Any, gnss: Any, config: ConfigLike, estimate_noise: Any, confidence: float
) -> ImuCalibrationResult:
    t, columns, layout = _imu.imu_columns(imu)
    required, optional = _imu.gnss_columns(gnss)
    keys = _keys(estimate_noise)
    kind, value = _config(config)
    command = "accelcal.calibrate(imu=imu, gnss=gnss" + _command_options(kind, value, keys, confidence) + ")"
    result = _accelcal.calibrate_imu_arrays(
        t, columns, layout, required, optional, kind, value, keys, float(confidence)
    )
    return ImuCalibrationResult(result, command)
