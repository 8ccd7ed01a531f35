# SPDX-License-Identifier: BSD-2-Clause
# Type stubs of the pednav extension module (python/src/module.cpp; docs/python.md). Installed next to the module.
import os
from typing import Any, Callable, Dict, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike]
ArrayLike = npt.ArrayLike
Columns = Dict[str, np.ndarray]

def set_log_level(level: str) -> None:
    """Level of the engine's log lines on stderr: trace, debug, info, warning (default), error, critical, off."""

class Config:
    """A validated run configuration (the YAML of `pednav run`; validated as `pednav config-check` does)."""
    @staticmethod
    def from_yaml(path: PathLike) -> Config:
        """Read and validate; ValueError (the config-check lines, with the YAML key path) or FileNotFoundError."""
    @staticmethod
    def from_dict(d: Dict[str, Any], base_dir: Optional[str] = None) -> Config:
        """A configuration from a dict of the YAML's structure; relative paths resolved against base_dir (default: cwd)."""
    def to_dict(self) -> Dict[str, Any]:
        """The resolved configuration (config.resolved.yaml) as a dict; from_dict(to_dict()) gives it back."""
    def to_yaml(self) -> str:
        """The resolved configuration as YAML text (what `pednav config-check` prints)."""
    @property
    def mode(self) -> str: ...
    @property
    def source_file(self) -> str: ...

class ImuLog:
    """IMU samples in GPS time, IMU body frame (x forward, y right, z down), SI units."""
    def __init__(self, t_s: ArrayLike, gyro_radps: ArrayLike, accel_mps2: ArrayLike,
                 stance_label: Optional[ArrayLike] = None, gps_week: int = 0) -> None:
        """t_s: (N,) strictly increasing seconds of GPS week gps_week (a relative log: its own seconds, week 0);
        gyro_radps, accel_mps2: (N, 3); stance_label: (N,) of 0/1. Any real dtype and layout is converted to float64;
        NaN/inf, unsorted times, empty or misshapen arrays raise ValueError."""
    @property
    def t_s(self) -> np.ndarray:
        """(N,) float64: seconds since the start of GPS week `gps_week`."""
    @property
    def gps_week(self) -> int: ...
    @property
    def gyro_radps(self) -> np.ndarray:
        """(N, 3) float64 angular rate [rad/s]."""
    @property
    def accel_mps2(self) -> np.ndarray:
        """(N, 3) float64 specific force [m/s^2]."""
    @property
    def stance_label(self) -> Optional[np.ndarray]:
        """(N,) uint8 stance labels when the log has them, else None."""
    @property
    def report(self) -> Dict[str, Any]:
        """What the reader found: rows, samples, duplicates_dropped, bad_rows, gaps, rate_hz, duration_s, warnings, ..."""
    @property
    def source(self) -> str: ...
    def __len__(self) -> int: ...

class Result:
    """What `pednav run` computes, in memory."""
    @property
    def forward(self) -> Columns:
        """solution.csv's columns (gps_week, gps_tow_s, lat_deg, ... zupt, hdop, pdop; with carrier also
        solution_status, n_fixed_ambiguities, ar_ratio) as numpy arrays; empty cells are NaN."""
    @property
    def smoothed(self) -> Optional[Columns]:
        """smoothed.csv's columns, or None when the smoother did not run."""
    @property
    def summary(self) -> Dict[str, Any]:
        """summary.json (wall_s: the computation in memory)."""
    @property
    def residuals(self) -> Optional[Columns]:
        """residuals.csv's columns (mode tc), else None."""
    @property
    def evaluation(self) -> Optional[Dict[str, Any]]:
        """evaluation.json when the configuration has a reference."""
    @property
    def evaluation_smoothed(self) -> Optional[Dict[str, Any]]: ...
    @property
    def config(self) -> Config:
        """The configuration with its `auto` settings resolved (config.resolved.yaml)."""
    def write(self, out_dir: str) -> None:
        """Write the files `pednav run -o out_dir` writes (the same writers: byte-identical but wall_s)."""
    def to_pandas(self, which: str = "forward") -> Any:
        """The forward or smoothed columns as a pandas.DataFrame (ImportError without pandas)."""

def read_imu(source: Union[PathLike, Config], format: Union[None, str, Dict[str, Any]] = None) -> ImuLog:
    """Read an IMU CSV log: a file with format= (a preset name such as "pyshoe", or a column map as imu.format), or a
    Config's imu.file with its imu.format."""

def run(config: Config, imu: Optional[ImuLog] = None, mode: Optional[str] = None,
        progress: Union[None, bool, Callable[[float], Any]] = None) -> Result:
    """`pednav run` in memory. imu: samples to use instead of imu.file; mode: "tc" or "ins" (as --mode);
    progress: a callable of the fraction done (0..1), or True for a tqdm bar. The GIL is released while the engine
    runs; Ctrl-C raises KeyboardInterrupt. Errors: ValueError (configuration, inputs), FileNotFoundError,
    RuntimeError (the engine's message)."""

def gnss(config: Config, out_dir: Optional[str] = None) -> Dict[str, Any]:
    """`pednav gnss`: {"solution": gnss.csv columns, "summary": summary.json, "evaluation"?: ..., "out_dir": out_dir or
    None}. Written into out_dir, or into a temporary folder that is removed."""

def simulate(scenario: PathLike, out_dir: Optional[str] = None) -> Dict[str, Any]:
    """`pednav simulate`: {"out_dir", "truth": truth.csv columns, "imu": ImuLog, "config": Config of config.yaml,
    "files": {"truth", "imu", "rover_obs", "base_obs", "nav", "config", ...: paths}, "summary"}. out_dir default: a new
    temporary folder (kept: the RINEX files are used by later runs)."""

def compare(solution: Union[PathLike, Result], reference: PathLike, align: str = "none", loop: bool = False,
            tolerance_s: float = 0.05, segment_s: float = 120.0, solution_format: str = "auto",
            reference_format: str = "auto", which: str = "forward") -> Dict[str, Any]:
    """`pednav compare`: {"evaluation": evaluation.json, "errors": per-epoch columns (gps_week, gps_tow_s, de_m, dn_m,
    du_m, horizontal_m, sd_e_m, sd_n_m, sd_u_m), "markdown": evaluation.md}. align: none, start, start-pyshoe,
    best-fit-2d, best-fit-3d; which: the forward or smoothed solution of a Result."""

def calibrate(imu: ImuLog, config: Optional[Config] = None) -> Dict[str, Any]:
    """`pednav calibrate`: {"calibration": calibration.json, "yaml": calibration.yaml text}."""

def detect_stance(imu: ImuLog, detector: Optional[str] = None, config: Optional[Config] = None) -> Dict[str, Any]:
    """`pednav zupt`: {"t_s", "stance" (bool), "statistic", "gait_state" (hmm: 0..3, else -1), "detector", "steps"}.
    detector: mv, shoe, are, mag, hmm, labels (default: the config's zupt.detector)."""
