#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""A tool in the hand: a square peg put into a hole, tilted there, taken out, and used to push a cube.

usage: peg_in_hole.py [--coupling local] [--rate-hz 20] [--out out/peg_in_hole]

impetus.ToolSimulation plays scenes/peg_in_hole.json's tool (a 10 x 10 x 40 mm peg held 3 cm below the grip) on the
simulated 8-string SPIDAR: a hand holds the grip with its own impedance and aims at the poses this script gives; the
tool servo renders the peg against the hole (11 mm square, 0.5 mm of clearance each side, 3 cm deep) and the cube.
The script is the person: it lowers the peg into the hole until it presses the floor, turns the grip 0.2 rad while
the peg is in, lifts it out, and sweeps it into the cube's side.

It prints what the hand felt at each stage and where the cube went, and plots the peg's path (side view) and the
force and torque on the grip against time (OUT/peg_in_hole.png; docs/peg_in_hole.png is this script's with --out
docs).
"""
import argparse
import math
import pathlib
import sys

import numpy as np

import impetus

TIP_BELOW_GRIP_M = 0.05  # the peg's tip, 3 cm + half its 4 cm length below the grip's centre
HOLE_HALF_M = 0.0055     # the hole's half width
RIM_M = 0.03             # the hole's rim height


def line(a, b, seconds):
    """Target positions from a to b over `seconds` of 1 ms ticks, orientation level: ticks x 7."""
    ticks = int(round(seconds * 1000))
    points = np.linspace(a, b, ticks + 1)[1:]
    return np.hstack([points, np.tile([1.0, 0.0, 0.0, 0.0], (ticks, 1))])


def turn(at, angle_from, angle_to, seconds):
    """The grip held at `at` while turned about +y from one angle to another (rad)."""
    ticks = int(round(seconds * 1000))
    angles = np.linspace(angle_from, angle_to, ticks + 1)[1:]
    return np.array([[*at, math.cos(a / 2), 0.0, math.sin(a / 2), 0.0] for a in angles])


def script():
    """The stages: (name, targets ticks x 7)."""
    above, bottom, in_hole = [0, 0, 0.1], [0, 0, 0.045], [0, 0, 0.07]
    return [
        ("down the hole", line(above, bottom, 1.0)),
        ("pressing its floor", line(bottom, bottom, 0.5)),
        ("up to 1 cm deep", line(bottom, in_hole, 0.3)),
        ("turned 0.2 rad", turn(in_hole, 0.0, 0.2, 0.4)),
        ("held turned", turn(in_hole, 0.2, 0.2, 0.3)),
        ("turned back", turn(in_hole, 0.2, 0.0, 0.3)),
        ("out", line(in_hole, above, 0.4)),
        ("over to the cube", line(above, [0.04, 0, 0.1], 0.3)),
        ("down beside it", line([0.04, 0, 0.1], [0.04, 0, 0.07], 0.3)),
        ("pushing the cube", line([0.04, 0, 0.07], [0.075, 0, 0.07], 0.5)),
        ("held", line([0.075, 0, 0.07], [0.075, 0, 0.07], 0.5)),
    ]


def run(coupling="local", rate_hz=None):
    """Plays the script; returns (stages as (name, ToolStep)), the cube's end position, the summary)."""
    stages = []
    with impetus.ToolSimulation(impetus.shipped_scene("peg_in_hole"), start_m=[0, 0, 0.1], coupling=coupling,
                                rate_hz=rate_hz) as sim:
        for name, targets in script():
            stages.append((name, sim.step(targets=targets)))
        cube_m = sim.objects()["position_m"][sim.object_names.index("cube")]
        summary = sim.close()
    return stages, cube_m, summary


def plot(stages, cube_m, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    time = np.concatenate([s.time_s for _, s in stages])
    proxy = np.concatenate([s.proxy_m for _, s in stages])
    grip = np.concatenate([s.grip_m for _, s in stages])
    force = np.concatenate([s.force_N for _, s in stages])
    torque = np.concatenate([s.torque_Nm for _, s in stages])
    fig, (side, wrench) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [1, 1.6]})
    # Side view: the hole's walls and the cube's start, the peg tip's path (proxy) and the grip's.
    for x0 in (-HOLE_HALF_M - 0.02, HOLE_HALF_M):
        side.add_patch(plt.Rectangle((x0 * 1e3, 0), 20, RIM_M * 1e3, color="0.75"))
    side.add_patch(plt.Rectangle((65, 0), 30, 30, color="tab:orange", alpha=0.3, label="cube at start"))
    side.add_patch(plt.Rectangle(((cube_m[0] - 0.015) * 1e3, 0), 30, 30, fill=False, ls="--", ec="tab:orange",
                                 label="cube at the end"))
    side.plot(proxy[:, 0] * 1e3, (proxy[:, 2] - TIP_BELOW_GRIP_M) * 1e3, color="tab:blue", label="peg tip (proxy)")
    side.plot(grip[:, 0] * 1e3, (grip[:, 2] - TIP_BELOW_GRIP_M) * 1e3, color="tab:red", lw=0.8, ls="--",
              label="where the grip would put it")
    side.axhline(0, color="k", lw=0.8)
    side.set_xlabel("x (mm)")
    side.set_ylabel("z of the peg's tip (mm)")
    side.set_title("side view: the hole's walls (grey)")
    side.set_aspect("equal")
    side.set_xlim(-30, 120)
    side.set_ylim(-5, 90)  # room for the legend above the objects
    side.legend(loc="upper right", fontsize=7)
    wrench.plot(time, force[:, 0], label="force x (N)")
    wrench.plot(time, force[:, 2], label="force z (N)")
    wrench.plot(time, torque[:, 1] * 10, label="torque y (N·m × 10)")
    start = 0.0
    for name, step in stages:
        end = step.time_s[-1]
        wrench.axvline(end, color="0.8", lw=0.6)
        wrench.text((start + end) / 2, 1.02, name, rotation=60, fontsize=7, ha="left", va="bottom",
                    transform=wrench.get_xaxis_transform())
        start = end
    wrench.set_xlabel("time (s)")
    wrench.legend(loc="lower left", fontsize=8)
    wrench.set_title(title, pad=70, fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--coupling", choices=("local", "impulse"), default="local", help="how the world couples")
    parser.add_argument("--rate-hz", type=float, default=None, help="the world's rate (default: the scene's, 20 Hz)")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/peg_in_hole"), help="where the plot goes")
    args = parser.parse_args()
    stages, cube_m, summary = run(args.coupling, args.rate_hz)
    for name, step in stages:
        f, t = step.force_N[-1], step.torque_Nm[-1]
        print(f"peg_in_hole: {name:22s} force [{f[0]:+.3f} {f[1]:+.3f} {f[2]:+.3f}] N, torque y {t[1]:+.4f} N·m")
    print(f"peg_in_hole: the cube went from x = 8.0 cm to {cube_m[0] * 100:.2f} cm; device: "
          f"{summary['device']['bad_readings']} bad readings, {summary['device']['saturations']} saturations")
    plot(stages, cube_m, args.out / "peg_in_hole.png", f"peg in hole, {args.coupling} coupling, "
         f"world at {summary['world_rate_hz']:g} Hz")
    print(f"peg_in_hole: plot in {args.out / 'peg_in_hole.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
