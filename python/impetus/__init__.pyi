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
LOG_FILES: dict[str, str]

_Path = Union[str, os.PathLike[str]]
_Trajectory = Union[str, os.PathLike[str], Mapping[str, _Path]]

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
def run_trial(scene: _Path, trajectory: _Trajectory, coupling: str = ..., *, users: Sequence[_Trajectory] = ...,
              rate_hz: float | None = ..., phase_ticks: int = ..., substeps: int | None = ...,
              stiffness_Npm: float | None = ..., damping_Nspm: float | None = ..., link_delay_s: float = ...,
              duration_s: float = ..., out_dir: _Path | None = ..., logs: bool = ...) -> Trial: ...
