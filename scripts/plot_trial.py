#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Plots one trial (scripts/run.sh output): the objects' x, the finger and the proxy over time, and the force.

usage: plot_trial.py DIR [--out FILE.png]
"""
import argparse
import os
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.summary import Summary  # noqa: E402


def box_half_x_m(trial_dir):
    """Half the x size of every box in the trial's scene, by name; {} if the summary or the scene cannot be read."""
    try:
        scene = Scene(Summary.read(trial_dir).scene_path)
    except (OSError, KeyError, ValueError):
        return {}
    return {name: obj["size_m"][0] / 2 for name, obj in scene.objects.items() if obj.get("shape") == "box"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", type=pathlib.Path)
    parser.add_argument("--out", type=pathlib.Path)
    args = parser.parse_args()
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt

    world = logs.read_log(args.dir / logs.WORLD)
    haptic = logs.read_log(args.dir / logs.HAPTIC)
    # One clock: the finger's. The world's steps are moved onto it (a world started before the finger, as the demo's
    # --view-wait does, runs ahead by the wait), and steps before the finger came are left out.
    world_time_s = world["time_s"] - logs.world_clock_offset_s(world)
    start_s = haptic["time_s"][0] - (world["time_s"][1] - world["time_s"][0] if len(world) > 1 else 0.0)
    world = world.rows(world_time_s >= start_s)
    world_time_s = world_time_s[world_time_s >= start_s]
    objects = sorted(world.object_names())
    # A box's −x face is what the finger strikes: plot it instead of the centre when the scene says the size.
    half_x = box_half_x_m(args.dir)
    # The finger is unknown while no device is attached (flags bit 0).
    attached = haptic["flags"].astype(int) & 1 == 1
    finger_x = np.where(attached, haptic["finger_x_m"], np.nan)
    proxy_x = np.where(attached, haptic["proxy_x_m"], np.nan)

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    for name in objects:
        if name in half_x:
            top.plot(world_time_s, world[f"{name}.x_m"] - half_x[name], lw=2, drawstyle="steps-post",
                     label=f"{name} −x face (world steps)")
        else:
            top.plot(world_time_s, world[f"{name}.x_m"], lw=2, drawstyle="steps-post", label=f"{name} x")
    top.plot(haptic["time_s"], finger_x, lw=1, label="finger x (device)")
    top.plot(haptic["time_s"], proxy_x, lw=1, ls="--", label="proxy x (god-object)")
    top.set_ylabel("x (m)")
    top.legend(fontsize=8, loc="lower right")
    top.grid(alpha=0.3)
    bottom.plot(haptic["time_s"], haptic["force_x_N"], lw=1, label="force on finger, x")
    bottom.plot(haptic["time_s"], haptic["force_z_N"], lw=1, label="force on finger, z")
    bottom.set_xlabel("time since the finger started (s)")
    bottom.set_ylabel("force (N)")
    bottom.legend(fontsize=8)
    bottom.grid(alpha=0.3)
    fig.suptitle(f"trial {args.dir.name}")
    fig.tight_layout()
    out = args.out or args.dir / "trial.png"
    fig.savefig(out, dpi=90)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()
