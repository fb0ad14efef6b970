# SPDX-License-Identifier: Apache-2.0
"""summary.json, a trial's machine-readable outcome (docs/architecture.md §4), on the Python side. scripts/run.sh has
summarize_trial.py merge it from the daemons' own summaries; every other script reads it through Summary.

  {"objects": {NAME: {"mass_kg", "inertia_kgm2" (principal, body frame), "position", "orientation", "velocity",
                      "angular_velocity", "impulse_Ns", "angular_impulse_Nms"}}, world_manager: each dynamic object
   "world":   {"steps", "time_s", "period_s", "cpu_per_step_mean_us", "cpu_per_step_p99_us", "cpu_per_simulated_s",
               "skipped_periods", "rejected_reports", ...},          world_manager
   "haptic":  {"rate_hz", "ticks", "max_force_N", "force_limit_N", "stiffness_Npm", "damping_Nspm", "faults",
               "force_clamps", "saturations", "infeasible_contacts", "cpu_per_tick_mean_ns", "cpu_per_tick_p99_ns",
               "lateness_*_ns", ...},                                haptic_controller
   "device":  {"ticks", "finger_mass_kg", "hand_stiffness_Npm", "hand_damping_Nspm", "metres_per_count",
               "tension_min_N", "tension_max_N", "max_force_N", ...},   spidar_sim
   "config":  {"scene", "coupling", "world_rate_hz", "substeps", "gravity_mps2", "phase_ticks", "clock", ...,
                                                                     world_manager
               "trajectory", "rate", "substeps_override", "duration_s", "wall_time_s"},  run.sh (strings but the last)
   "link":    {"delay_s", "delay_ticks", "dropped"}}                 in-process trials only (the impetus package):
                                                                     the world link's delay line
"""
import json
import math

FILE_NAME = "summary.json"
WORLD_FILE_NAME = "world.json"    # world_manager --summary: "objects", "world", "config"
HAPTIC_FILE_NAME = "haptic.json"  # haptic_controller --summary: "haptic"
DEVICE_FILE_NAME = "device.json"  # spidar_sim --summary: "device"


def merge(world, haptic, device, config_entries):
    """The summary of a trial from world_manager's, haptic_controller's and spidar_sim's --summary documents and
    run.sh's config entries ({key: string}; they override the world's config). run.sh's wall_start and wall_end (Unix time, s) become
    wall_time_s, the trial's wall-clock duration."""
    config = dict(world.get("config", {}))
    config.update(config_entries)
    if "wall_start" in config and "wall_end" in config:
        config["wall_time_s"] = float(config.pop("wall_end")) - float(config.pop("wall_start"))
    return {"objects": world["objects"], "haptic": haptic["haptic"], "device": device["device"], "world": world["world"],
            "config": config}


def to_json(summary):
    """summary.json's text."""
    return json.dumps(summary, indent=2) + "\n"


class Summary:
    """A trial's summary.json. The sections are the document's own dicts; the properties name the fields the
    scripts share."""

    def __init__(self, document):
        self.objects = document["objects"]
        self.world = document["world"]
        self.haptic = document["haptic"]
        self.device = document["device"]
        self.config = document["config"]
        self.link = document.get("link", {})  # in-process trials only

    @classmethod
    def read(cls, trial_dir):
        """The summary run.sh wrote into trial_dir."""
        return cls(json.loads((trial_dir / FILE_NAME).read_text()))

    def final_position_m(self, name):
        """Object `name`'s centre at the end of the trial, [x, y, z]."""
        return self.objects[name]["position"]

    def impulse_Ns(self, name):
        """The impulse the world applied to object `name` over the trial, [x, y, z]."""
        return self.objects[name]["impulse_Ns"]

    @property
    def scene_path(self):
        """The scene file the trial ran (as given to run.sh)."""
        return self.config["scene"]

    @property
    def world_period_s(self):
        return 1.0 / float(self.config["world_rate_hz"])

    @property
    def haptic_period_s(self):
        return 1.0 / float(self.haptic["rate_hz"])

    @property
    def wall_time_s(self):
        """Wall-clock duration of the trial (NaN if the summary was not written by run.sh)."""
        return float(self.config.get("wall_time_s", math.nan))
