# SPDX-License-Identifier: Apache-2.0
# Types of the impetus package (python/impetus/__init__.py), for editors and type checkers.
import os
import pathlib
from typing import Any, Mapping, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
__all__: list[str]

COUPLINGS: tuple[str, ...]
ENGINES: tuple[str, ...]
LOG_FILES: dict[str, str]

_Path = Union[str, os.PathLike[str]]
_Scene = Union[str, os.PathLike[str], Mapping[str, Any]]
_Points = Union[npt.ArrayLike, Sequence[Sequence[float]]]
_Trajectory = Union[str, os.PathLike[str], npt.ArrayLike, Mapping[str, Union[_Path, npt.ArrayLike]]]
_Point = Union[Sequence[float], npt.ArrayLike]

class Trial:
    summary: dict[str, Any]
    logs: dict[str, dict[str, npt.NDArray[np.float64]]]
    out_dir: pathlib.Path | None
    def __init__(self, summary: dict[str, Any], logs: dict[str, dict[str, npt.NDArray[np.float64]]],
                 out_dir: pathlib.Path | None) -> None: ...

def defaults() -> dict[str, Any]: ...
def scene_dir() -> pathlib.Path: ...
def shipped_scene(name: str) -> pathlib.Path: ...
def read_log(path: _Path) -> dict[str, npt.NDArray[np.float64]]: ...
def sample_trajectory(trajectory: _Path, times_s: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
def run_trial(scene: _Scene, trajectory: _Trajectory, coupling: str = ..., *, passivity: bool = ...,
              users: Sequence[_Trajectory] = ...,
              rate_hz: float | None = ..., phase_ticks: int = ..., substeps: int | None = ...,
              engine: str | None = ..., stiffness_Npm: float | None = ..., damping_Nspm: float | None = ...,
              link_delay_s: float = ..., link_loss: float = ..., link_loss_burst: float = ...,
              duration_s: float = ..., out_dir: _Path | None = ..., logs: bool = ...) -> Trial: ...

class Step:
    time_s: npt.NDArray[np.float64]
    target_m: npt.NDArray[np.float64]
    finger_m: npt.NDArray[np.float64]
    finger_velocity_mps: npt.NDArray[np.float64]
    proxy_m: npt.NDArray[np.float64]
    force_N: npt.NDArray[np.float64]
    object_impulse_Ns: npt.NDArray[np.float64]
    active_planes: npt.NDArray[np.int32]
    def __init__(self, arrays: Mapping[str, Any]) -> None: ...
    def __len__(self) -> int: ...

class Simulation:
    summary: dict[str, Any] | None
    out_dir: pathlib.Path | None
    finger_names: tuple[str, ...]
    object_names: tuple[str, ...]
    tick_period_s: float
    def __init__(self, scene: _Scene, start_m: _Point | None = ..., coupling: str = ..., *, passivity: bool = ...,
                 fingers: Mapping[str, _Point] | None = ..., rate_hz: float | None = ..., phase_ticks: int = ...,
                 substeps: int | None = ..., engine: str | None = ..., stiffness_Npm: float | None = ...,
                 damping_Nspm: float | None = ..., link_delay_s: float = ..., link_loss: float = ...,
                 link_loss_burst: float = ..., out_dir: _Path | None = ...) -> None: ...
    @property
    def ticks(self) -> int: ...
    @property
    def time_s(self) -> float: ...
    def device_times_s(self, ticks: int) -> npt.NDArray[np.float64]: ...
    def step(self, ticks: int | None = ..., targets: _Points | None = ...) -> Step: ...
    def set_target(self, target_m: _Point, finger: int | str = ...) -> None: ...
    def set_hand_force(self, force_N: _Point, finger: int | str = ...) -> None: ...
    def objects(self) -> dict[str, npt.NDArray[np.float64]]: ...
    def close(self) -> dict[str, Any] | None: ...
    def __enter__(self) -> "Simulation": ...
    def __exit__(self, *exc: object) -> bool: ...

class ToolStep:
    time_s: npt.NDArray[np.float64]
    target_m: npt.NDArray[np.float64]
    target_wxyz: npt.NDArray[np.float64]
    grip_m: npt.NDArray[np.float64]
    grip_wxyz: npt.NDArray[np.float64]
    hand_m: npt.NDArray[np.float64]
    hand_wxyz: npt.NDArray[np.float64]
    proxy_m: npt.NDArray[np.float64]
    proxy_wxyz: npt.NDArray[np.float64]
    force_N: npt.NDArray[np.float64]
    torque_Nm: npt.NDArray[np.float64]
    strings_force_N: npt.NDArray[np.float64]
    strings_torque_Nm: npt.NDArray[np.float64]
    active: npt.NDArray[np.int32]
    def __init__(self, arrays: Mapping[str, Any]) -> None: ...
    def __len__(self) -> int: ...

class ToolSimulation:
    summary: dict[str, Any] | None
    object_names: tuple[str, ...]
    tick_period_s: float
    out_dir: pathlib.Path | None
    def __init__(self, scene: _Scene, start_m: _Point, coupling: str = ..., *,
                 start_wxyz: Sequence[float] = ..., rate_hz: float | None = ...,
                 out_dir: _Path | None = ..., device: str = ...) -> None: ...
    @property
    def ticks(self) -> int: ...
    def step(self, ticks: int | None = ..., targets: _Points | None = ...) -> ToolStep: ...
    def set_target(self, target_m: _Point, target_wxyz: Sequence[float] = ...) -> None: ...
    def objects(self) -> dict[str, npt.NDArray[np.float64]]: ...
    def close(self) -> dict[str, Any] | None: ...
    def __enter__(self) -> "ToolSimulation": ...
    def __exit__(self, *exc: object) -> bool: ...
