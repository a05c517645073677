"""Type stubs of accelcal. Units: s, m, m/s, m/s², Hz as the names say."""

import os
from typing import Any, Dict, NamedTuple, Optional, Protocol, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
DEFAULT_ALLAN_CONFIDENCE: float

ConfigLike = Union[None, str, os.PathLike[str], Dict[str, Any]]
FloatArray = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike

def default_config() -> str: ...

class Term(NamedTuple):
    value: Optional[float]
    lower: Optional[float]
    upper: float

class AllanResult:
    record: Dict[str, Any]
    samples: int
    sample_period_s: float
    confidence: float
    tau_s: FloatArray
    adev: FloatArray
    adev_lower: FloatArray
    adev_upper: FloatArray
    edf: FloatArray
    noise_alpha: FloatArray
    fit_tau_s: FloatArray
    terms: Dict[str, Term]
    def to_json(self) -> str: ...
    def to_noise_toml(self, source: str = ...) -> str: ...
    def to_imu_yaml(self, source: str = ...) -> str: ...

def allan(y: ArrayLike, rate_hz: float, *, confidence: float = ...) -> AllanResult: ...
def ensemble(
    config: ConfigLike = None,
    *,
    realizations: Optional[int] = None,
    seed: Optional[int] = None,
    engine: str = "sample",
) -> Dict[str, Any]: ...
def simulate(
    config: ConfigLike = None, *, realization: int = 0, seed: Optional[int] = None
) -> Dict[str, Dict[str, FloatArray]]: ...

class CalibrationResult:
    """``accelcal calibrate --accel --gps``: summary.json as a dict, estimates.csv's columns
    (one entry per GPS fix; m, m/s, m/s² and their σ's, innovations, NIS), the bias at the end
    (m/s²) and its σ (m/s²)."""

    summary_json: str
    estimates_csv: str
    summary: Dict[str, Any]
    estimates: Dict[str, FloatArray]
    bias_m_s2: float
    bias_sigma_m_s2: float
    def html(self) -> str: ...

class ImuCalibrationResult:
    """``accelcal calibrate --imu --gnss``: summary.json as a dict, estimates.csv's columns (one
    entry per fix: position °/m, velocity m/s, attitude °, gyro biases rad/s, accelerometer
    biases m/s², their σ's, innovations, NIS, then the smoothed attitude and biases), and the
    biases at the end in body x, y, z (rad/s, m/s²)."""

    summary_json: str
    estimates_csv: str
    summary: Dict[str, Any]
    estimates: Dict[str, FloatArray]
    gyro_bias_rad_s: FloatArray
    accel_bias_m_s2: FloatArray
    def html(self) -> str: ...

class ColumnTable(Protocol):
    """A table indexed by column name: a dict of 1-D arrays, a pandas DataFrame."""

    def __getitem__(self, column: str, /) -> Any: ...

@overload
def calibrate(
    accel_t: ArrayLike,
    accel: ArrayLike,
    gps_t: ArrayLike,
    gps_position: ArrayLike,
    gps_velocity: ArrayLike,
    *,
    config: ConfigLike = None,
    estimate_noise: Union[None, bool, str, Sequence[str]] = None,
    confidence: float = 0.95,
) -> CalibrationResult:
    """One axis: accelerometer samples (accel_t s, accel m/s²), GPS fixes (gps_t s,
    gps_position m, gps_velocity m/s)."""

@overload
def calibrate(
    *,
    imu: ColumnTable,
    gnss: ColumnTable,
    config: ConfigLike = None,
    estimate_noise: Union[None, bool, str, Sequence[str]] = None,
    confidence: float = 0.95,
) -> ImuCalibrationResult:
    """Three axes: imu with t_s (s) and ax_m_s2, ay_m_s2, az_m_s2 (m/s²), gx_rad_s, gy_rad_s,
    gz_rad_s (rad/s) or dvx_m_s, dvy_m_s, dvz_m_s (m/s), dthx_rad, dthy_rad, dthz_rad (rad);
    gnss with t_s (s), lat_deg, lon_deg (°), height_m (m) and optionally vn_m_s, ve_m_s, vd_m_s
    (m/s), sigma_n_m, sigma_e_m, sigma_d_m (m), sigma_vn_m_s, sigma_ve_m_s, sigma_vd_m_s (m/s),
    NaN where not measured."""
