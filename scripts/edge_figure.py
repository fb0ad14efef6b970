#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""What the finger feels at a box's edge between world frames: a finger 3 mm into the top of a static box slides off
its edge at 0.2 m/s with a 20 Hz world, rendered with the planes as the world sent them and with the planes taken
again at the proxy every tick (haptic_controller/shape_planes.h), against the exact god-object. Runs
build/tests/bench_edge_release and plots the upward force against the finger's distance past the edge.

usage: edge_figure.py [--out DIR]        writes DIR/edge_release.png (default out/edge)
"""
import argparse
import csv
import io
import os
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py.paths import ROOT, build_dir  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/edge")
    args = parser.parse_args()
    program = build_dir() / "tests/bench_edge_release"
    if not program.exists():
        sys.exit(f"edge_figure.py: {program} does not exist; build first (bash scripts/build.sh build)")
    text = subprocess.run([str(program)], check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(text)))
    past_mm = [1e3 * float(r["finger_from_edge_m"]) for r in rows]
    series = {"planes as the world sent them (a face's plane lasts until the next frame)": "force_as_sent_N",
              "planes taken again every tick (at the proxy; at the finger once the way is clear)":
                  "force_retaken_N",
              "exact god-object on the true box": "force_exact_N"}
    held_mm = max((p for p, r in zip(past_mm, rows) if float(r["force_as_sent_N"]) > 0.1), default=0.0)
    retaken_mm = max((p for p, r in zip(past_mm, rows) if float(r["force_retaken_N"]) > 0.1), default=0.0)
    print(f"force held past the edge: as sent {held_mm:.1f} mm ({held_mm / 0.2:.0f} ms at 0.2 m/s), "
          f"taken again {max(retaken_mm, 0.0):.1f} mm")

    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib
    matplotlib.use(os.environ["MPLBACKEND"])
    import matplotlib.pyplot as plt
    figure, axis = plt.subplots(figsize=(7.5, 3.4))
    styles = [dict(color="tab:red", lw=2.0), dict(color="tab:blue", lw=2.0), dict(color="black", lw=1.0, ls="--")]
    for (label, key), style in zip(series.items(), styles):
        axis.plot(past_mm, [float(r[key]) for r in rows], label=label, **style)
    axis.axvline(0.0, color="grey", lw=0.8)
    axis.text(0.3, 6.9, "edge", color="grey")
    axis.set_xlabel("finger past the box's edge (mm), sliding at 0.2 m/s, 3 mm deep")
    axis.set_ylabel("upward force on the finger (N)")
    axis.set_ylim(-0.5, 7.5)
    axis.set_title("A finger slides off a box's edge between 20 Hz world frames", fontsize=10)
    axis.legend(fontsize=8, loc="center left")
    axis.grid(alpha=0.3)
    figure.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "edge_release.png"
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
