#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Grasp and lift with two fingers under each coupling (hard case 14, docs/endpoints.md): the cube's height and
each finger's force over time, from lockstep trials. Prints the lift height per coupling and world phase.

usage: grasp_figure.py [--out DIR] [--phases N] [--jobs N]
Writes DIR/grasp.png and DIR/grasp.md.
"""
import argparse
import os
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

SCENE = ROOT / "scenes/grasp.json"
FINGERS = {"thumb": str(ROOT / "scenes/grasp_thumb.csv"), "index": str(ROOT / "scenes/grasp_index.csv")}
COUPLINGS = ("local", "impulse", "position")
WORLD_TICKS = 50  # 1 kHz haptic, the scene's 20 Hz world: phases 0..49
HOLD_S = (2.5, 7.0)  # the fingers hold the cube up over this window


def lift_mm(out_dir):
    """The cube's height above its rest at the start of the hold, mm, and its largest change during the hold."""
    world = logs.read_log(out_dir / logs.WORLD)
    t, z = world["time_s"], world["cube.z_m"]
    hold = z[(t >= HOLD_S[0]) & (t <= HOLD_S[1])]
    return 1e3 * (hold[0] - z[0]), 1e3 * (hold.max() - hold.min())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/grasp")
    parser.add_argument("--phases", type=int, default=5, help="world phases per coupling (default 5)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    if not 1 <= args.phases <= WORLD_TICKS:
        sys.exit(f"grasp_figure: --phases must be 1 to {WORLD_TICKS}, not {args.phases}")
    args.out.mkdir(parents=True, exist_ok=True)
    phases = [k * WORLD_TICKS // args.phases for k in range(args.phases)]
    tasks = []
    for coupling in COUPLINGS:
        for phase in phases:
            out_dir = args.out / f"{coupling}-phase{phase}"
            tasks.append(((coupling, phase), run_trial, (out_dir, SCENE, FINGERS, coupling, None, phase)))
    try:
        for _ in run_parallel(tasks, args.jobs):
            pass
    except RuntimeError as error:  # a trial that failed names itself
        sys.exit(f"grasp_figure: {error}")

    lines = ["| coupling | lift at the hold's start (mm), over phases | spread (mm) | largest slip in the hold (mm) |",
             "|---|---|---|---|"]
    for coupling in COUPLINGS:
        lifts = [lift_mm(args.out / f"{coupling}-phase{phase}") for phase in phases]
        heights = [lift for lift, _ in lifts]
        lines.append(f"| {coupling} | {min(heights):.1f} to {max(heights):.1f} | {max(heights) - min(heights):.2f} | "
                     f"{max(slip for _, slip in lifts):.3f} |")
    table = "\n".join(lines) + "\n"
    (args.out / "grasp.md").write_text(table)
    print(table, end="")

    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, len(COUPLINGS), figsize=(11, 5.2), sharex=True, sharey="row")
    for column, coupling in enumerate(COUPLINGS):
        out_dir = args.out / f"{coupling}-phase0"
        world = logs.read_log(out_dir / logs.WORLD)
        device = logs.read_log(out_dir / logs.DEVICE)
        top, bottom = axes[0][column], axes[1][column]
        top.plot(world["time_s"], 1e3 * (world["cube.z_m"] - world["cube.z_m"][0]), lw=2, drawstyle="steps-post",
                 label="cube height (world steps)")
        top.plot(device["time_s"], 1e3 * (device["target_z_m"] - device["target_z_m"][0]), lw=1, ls="--",
                 label="fingers' target height")
        top.set_title(f"{coupling} coupling")
        top.set_ylim(-5, 80)
        top.grid(alpha=0.3)
        for name, log_name in (("thumb", logs.HAPTIC), ("index", "haptic.endpoint1.csv")):
            haptic = logs.read_log(out_dir / log_name)
            force = np.linalg.norm(haptic.vectors("force_", "_N"), axis=1)
            bottom.plot(haptic["time_s"], force, lw=0.8, label=f"{name}: |force| (N)")
        bottom.set_xlabel("time (s)")
        bottom.grid(alpha=0.3)
    axes[0][0].set_ylabel("height above rest (mm)")
    axes[1][0].set_ylabel("force on the finger (N)")
    axes[0][0].legend(fontsize=8, loc="upper right")
    axes[1][0].legend(fontsize=8, loc="upper right")
    fig.suptitle("Grasp and lift: two fingers squeeze a 0.2 kg cube, lift 5 cm, hold, put it down (20 Hz world)")
    fig.tight_layout()
    fig.savefig(args.out / "grasp.png", dpi=80)
    print(f"wrote {args.out / 'grasp.png'} and {args.out / 'grasp.md'}")


if __name__ == "__main__":
    main()
