# SPDX-License-Identifier: Apache-2.0
"""Where things are: the repository root and the daemons' build directory."""
import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def build_dir():
    """The directory holding world_manager/, haptic_controller/ and spidar_sim/ with their binaries: $IMPETUS_BUILD_DIR
    if set (scripts/run.sh reads the same variable), else ROOT/build."""
    return pathlib.Path(os.environ.get("IMPETUS_BUILD_DIR", ROOT / "build"))
