# SPDX-License-Identifier: Apache-2.0
"""The daemons' CSV logs of one trial (docs/architecture.md §4: a header row, time first, units in the column names):

  world.csv   world_manager: one row per world step, the state after it; per object NAME.x_m .. NAME.z_m,
              NAME.qw .. NAME.qz, NAME.vx_mps .., NAME.wx_radps .., and the impulses NAME.jx_Ns .., NAME.jx_total_Ns ..;
              haptic_time_s: the haptic clock's time of the report the step applied (NaN before the first)
  haptic.csv  haptic_controller: one row per tick: finger_x_m .., proxy_x_m .., force_x_N .. (on the finger),
              object_impulse_x_Ns .., static_impulse_x_Ns .. (running totals), interpolation_weight,
              active_planes, flags (bit 0: a device is attached, bit 1: the force was clamped), ...
  device.csv  spidar_sim: one row per device tick: target_x_m .., finger_x_m .., finger_vx_mps .., tensions, counts
"""
import csv

import numpy as np

WORLD = "world.csv"
HAPTIC = "haptic.csv"
DEVICE = "device.csv"
NAMES = (WORLD, HAPTIC, DEVICE)


class Log:
    """A log's columns as float arrays, by header name."""

    def __init__(self, header, rows):
        table = np.array(rows, dtype=float).reshape(len(rows), len(header))
        self.columns = {name: table[:, i] for i, name in enumerate(header)}

    def __getitem__(self, column):
        return self.columns[column]

    def __len__(self):
        return len(self.columns["time_s"])

    @property
    def finite(self):
        """Whether every value is a finite number (no NaN or Inf). The world log's haptic_time_s is left out: it is
        NaN, "none yet", until the world applies its first report."""
        return all(np.isfinite(values).all() for name, values in self.columns.items() if name != "haptic_time_s")

    def vectors(self, prefix, suffix=""):
        """The columns PREFIX{x,y,z}SUFFIX as one row per log row: vectors("finger_", "_m") for haptic.csv's finger,
        vectors("cube.v", "_mps") for world.csv's velocity of the cube."""
        return np.stack([self.columns[f"{prefix}{axis}{suffix}"] for axis in "xyz"], axis=1)

    def object_names(self):
        """The objects a world log tracks, in column order."""
        return [column[:-len(".x_m")] for column in self.columns if column.endswith(".x_m")]

    def rows(self, selected):
        """A log of the rows `selected` (a boolean array or an index array) picks."""
        log = Log.__new__(Log)
        log.columns = {name: values[selected] for name, values in self.columns.items()}
        return log


def world_clock_offset_s(world):
    """How far the world's clock (world.csv's time_s) runs ahead of the haptic side's (haptic.csv's time_s), s: the
    median over the world's steps of (the world time the step started at) − (the haptic time of the report it applied).
    A world started before the finger (run.sh --view-wait) is ahead by the wait; in lockstep the offset is the world
    clock's phase, −phase ticks. Subtract it from world times to put the world on the finger's clock. 0 for a log
    without haptic_time_s or before any report."""
    if "haptic_time_s" not in world.columns or len(world) < 2:
        return 0.0
    times = world["time_s"]
    period_s = float(np.median(np.diff(times)))
    offsets = (times - period_s) - world["haptic_time_s"]
    offsets = offsets[np.isfinite(offsets)]
    return float(np.median(offsets)) if len(offsets) else 0.0


def read_log(path, keep_time_s=None):
    """The log at `path`. With `keep_time_s`, a predicate on a row's time (s), only the rows it accepts are kept, and
    only those are converted to numbers: a 1 kHz world log of many objects is large."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        rows = []
        for line in reader:
            if keep_time_s is not None and not keep_time_s(float(line[0])):
                continue
            rows.append([float(value) for value in line])
    return Log(header, rows)
