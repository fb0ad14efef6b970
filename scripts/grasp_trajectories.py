#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the two fingers' trajectories of the grasp scene (scenes/grasp.json): thumb and index finger close on the
5 cm cube from either side, squeeze it, lift it 5 cm, hold it, put it down and let go.

usage: grasp_trajectories.py [--out DIR]      writes DIR/grasp_thumb.csv and DIR/grasp_index.csv (default scenes/)

Each move is a half-cosine ramp (zero speed at both ends, so the hand's impedance follows it without a jerk), sampled
every 20 ms. The targets stop 15 mm from the cube's centre, 10 mm inside its faces at ±25 mm: the proxies rest on the
faces and the fingers squeeze the cube between them (the scene's description gives the friction budget).
"""
import argparse
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py.paths import ROOT  # noqa: E402

SAMPLE_S = 0.02
END_S = 10.0
OPEN_X_M = 0.045     # fingertip beside the cube, 2 cm clear of its face
CLOSED_X_M = 0.015   # 10 mm inside the face: the squeeze
LOW_Z_M = 0.028      # just above the cube's middle
HIGH_Z_M = 0.078     # lifted 5 cm
# (start, end) of each move, s.
CLOSE = (0.0, 0.5)
LIFT = (1.0, 2.0)
LOWER = (7.0, 8.0)
OPEN = (8.0, 8.5)


def ramp(t, start_end, a, b):
    """a before the move, b after it, a half-cosine between."""
    start, end = start_end
    if t <= start:
        return a
    if t >= end:
        return b
    return a + (b - a) * 0.5 * (1.0 - math.cos(math.pi * (t - start) / (end - start)))


def fingertip(t, side):
    """side +1: the index finger at +x; −1: the thumb at −x."""
    x = ramp(t, CLOSE, OPEN_X_M, CLOSED_X_M) if t < OPEN[0] else ramp(t, OPEN, CLOSED_X_M, OPEN_X_M)
    z = ramp(t, LIFT, LOW_Z_M, HIGH_Z_M) if t < LOWER[0] else ramp(t, LOWER, HIGH_Z_M, LOW_Z_M)
    return side * x, z


def write(path, side):
    lines = ["t,x,y,z"]
    for k in range(int(round(END_S / SAMPLE_S)) + 1):
        t = k * SAMPLE_S
        x, z = fingertip(t, side)
        lines.append(f"{t:.3f},{x:.6f},0,{z:.6f}")
    path.write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "scenes", help="folder to write to (default scenes/)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    write(args.out / "grasp_thumb.csv", -1.0)
    write(args.out / "grasp_index.csv", +1.0)
    print(f"wrote {args.out / 'grasp_thumb.csv'} and {args.out / 'grasp_index.csv'}")


if __name__ == "__main__":
    sys.exit(main())
