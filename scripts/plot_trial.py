#!/usr/bin/python3
"""Plots one trial (scripts/run.sh output): the objects' x, the finger and the proxy over time, and the force.

usage: plot_trial.py DIR [--out FILE.png]
"""
import argparse
import csv
import json
import math
import os
import pathlib


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {key: [float(row[key]) for row in rows] for key in rows[0]} if rows else {}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", type=pathlib.Path)
    parser.add_argument("--out", type=pathlib.Path)
    args = parser.parse_args()
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt

    world = columns(args.dir / "world.csv")
    haptic = columns(args.dir / "haptic.csv")
    objects = sorted({key.split(".")[0] for key in world if key.endswith(".x_m")})
    # A box's −x face is what the finger strikes: plot it instead of the centre when the scene says the size.
    half_x = {}
    try:
        scene_path = json.loads((args.dir / "summary.json").read_text())["config"]["scene"]
        for obj in json.loads(pathlib.Path(scene_path).read_text())["objects"]:
            if obj.get("shape") == "box":
                half_x[obj["name"]] = obj["size_m"][0] / 2
    except (OSError, KeyError, ValueError):
        pass
    # The finger is unknown while no device is attached (flags bit 0).
    valid = [int(f) & 1 for f in haptic["flags"]]
    finger_x = [x if v else math.nan for x, v in zip(haptic["finger_x"], valid)]
    proxy_x = [x if v else math.nan for x, v in zip(haptic["proxy_x"], valid)]

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    for name in objects:
        if name in half_x:
            face = [x - half_x[name] for x in world[f"{name}.x_m"]]
            top.plot(world["time_s"], face, lw=2, drawstyle="steps-post", label=f"{name} −x face (world steps)")
        else:
            top.plot(world["time_s"], world[f"{name}.x_m"], lw=2, drawstyle="steps-post", label=f"{name} x")
    top.plot(haptic["time_s"], finger_x, lw=1, label="finger x (device)")
    top.plot(haptic["time_s"], proxy_x, lw=1, ls="--", label="proxy x (god-object)")
    top.set_ylabel("x (m)")
    top.legend(fontsize=8, loc="lower right")
    top.grid(alpha=0.3)
    bottom.plot(haptic["time_s"], haptic["force_x"], lw=1, label="force on finger, x")
    bottom.plot(haptic["time_s"], haptic["force_z"], lw=1, label="force on finger, z")
    bottom.set_xlabel("time (s)")
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
