"""Type stubs of accelcal. Units: s, m, m/s, m/s², Hz as the names say."""

import os
from typing import Any, Dict, NamedTuple, Optional, Sequence, Union

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
    summary_json: str
    estimates_csv: str
    summary: Dict[str, Any]
    estimates: Dict[str, FloatArray]
    bias_m_s2: float
    bias_sigma_m_s2: float
    def html(self) -> str: ...

def calibrate(
    accel_t: ArrayLike,
    accel: ArrayLike,
    gps_t: ArrayLike,
    gps_position: ArrayLike,
    gps_velocity: ArrayLike,
    *,
    config: ConfigLike = None,
    estimate_noise: Union[None, bool, Sequence[str]] = None,
    confidence: float = 0.95,
) -> CalibrationResult: ...
