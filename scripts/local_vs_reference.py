#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Rotation and several bodies at a slow world, against the single-rate reference (the world at the haptic rate, 1 kHz):

  off-centre   the paper's tap struck 15 mm off the cube's centre line, at two speeds: the cube turns as it slides.
               Measured: its final yaw and travel.
  two cubes    the tapped cube slides into a second, lighter one (tests/hard_cases/c13b_two_cubes.json). Measured: the
               second cube's travel. Three worlds: the scene as it is; with the world's substep as short as the
               reference's (500 substeps at 20 Hz: 0.1 ms), which leaves the coupling's own error; and without
               speculative contacts (physics.speculative_contacts = false), where the impact sinks one cube into the
               other and ODE's correction of that kicks them apart (world_manager/engine/speculative_contact.h).

Each at --phases world-clock phases per coupling at --rate (local, impulse, position), the reference once per case
(a world at the haptic rate has one phase). Prints a table: mean error against the reference as a
percentage of the reference's value, and the spread over the phases. --check exits 1 unless local coupling's yaw is
within --max-yaw-error of the reference's in every off-centre case and the second cube's travel is within
--max-travel-error of the reference's in the scene as it is.

usage: local_vs_reference.py [--check] [--off-centre-only] [--out DIR] [--phases N] [--rate HZ] [--jobs N]
"""
import argparse
import json
import os
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

TAP_SCENE = ROOT / "scenes/tap.json"
TWO_CUBES = ROOT / "tests/hard_cases/c13b_two_cubes.json"
COUPLINGS = ("local", "impulse", "position")


def final_pose(trial_dir, name):
    """(x, yaw in degrees) of object `name` at the end of the trial's world log; the yaw unwrapped over the trial, so
    a cube that turned 200 degrees reads 200, not -160."""
    world = logs.read_log(trial_dir / logs.WORLD)
    qw, qx, qy, qz = (world[f"{name}.q{k}"] for k in "wxyz")
    yaw = np.unwrap(np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)))
    return float(world[f"{name}.x_m"][-1]), float(np.degrees(yaw[-1]))


def without_speculative_contacts(out):
    """The two-cube scene with ODE's contacts only once bodies overlap, written into `out`."""
    scene = json.loads(TWO_CUBES.read_text())
    scene.setdefault("physics", {})["speculative_contacts"] = False
    path = out / "c13b_two_cubes_no_speculative.json"
    path.write_text(json.dumps(scene, indent=2))
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/local_vs_reference")
    parser.add_argument("--rate", type=float, default=20.0, help="world rate under test, Hz")
    parser.add_argument("--phases", type=int, default=5, help="phases spread evenly over one world period")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--off-centre-only", action="store_true", help="run only the off-centre taps (not the two cubes)")
    parser.add_argument("--max-yaw-error", type=float, default=0.10,
                        help="--check: largest |mean yaw - reference yaw| / |reference yaw| of local coupling")
    parser.add_argument("--max-travel-error", type=float, default=0.02,
                        help="--check: largest |mean travel - reference travel| / reference travel of the second "
                             "cube under local coupling")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # case: (label, scene, trajectory, object, measure, substeps under test)
    cases = [
        ("off-centre tap 0.5 m/s", TAP_SCENE, "tap:y=0.015", "cube", "yaw", None),
        ("off-centre tap 0.4 m/s", TAP_SCENE, "tap:y=0.015,speed=0.4", "cube", "yaw", None),
        ("two cubes", TWO_CUBES, "tap", "cube2", "travel", None),
        ("two cubes, 0.1 ms substeps", TWO_CUBES, "tap", "cube2", "travel", round(10 * HAPTIC_RATE_HZ / args.rate)),
        ("two cubes, no speculative contacts", without_speculative_contacts(args.out), "tap", "cube2", "travel",
         None),
    ]
    if args.off_centre_only:
        cases = [case for case in cases if case[0].startswith("off-centre")]
    ticks_per_step = round(HAPTIC_RATE_HZ / args.rate)
    phases = sorted({round(k * ticks_per_step / args.phases) for k in range(args.phases)})
    def trial_dir(index, label, phase):
        return args.out / f"case{index}" / ("reference" if label == "reference" else f"{label}-phase{phase:03d}")

    tasks = []
    for index, (label, scene, trajectory, name, _, substeps) in enumerate(cases):
        tasks.append(((index, "reference", 0), run_trial,
                      (trial_dir(index, "reference", 0), scene, trajectory, "impulse", HAPTIC_RATE_HZ)))
        for coupling in COUPLINGS:
            for phase in phases:
                tasks.append(((index, coupling, phase), run_trial,
                              (trial_dir(index, coupling, phase), scene, trajectory, coupling, args.rate, phase,
                               substeps)))
    results = {}
    for key, _ in track(run_parallel(tasks, args.jobs), [key for key, _, _ in tasks], "local vs reference",
                        args.quiet):
        results[key] = final_pose(trial_dir(*key), cases[key[0]][3])

    lines = [f"World {args.rate:g} Hz, {len(phases)} phases per coupling, against the {HAPTIC_RATE_HZ:g} Hz reference "
             "(impulse coupling, the scene's substeps).", "",
             "| case | measure | reference | coupling | mean | error (% of reference) | phase spread |",
             "|---|---|---|---|---|---|---|"]
    failures = []
    for index, (label, scene, _, name, measure, _) in enumerate(cases):
        start_x = Scene(scene).start_position_m(name)[0]
        value = (lambda r: r[1]) if measure == "yaw" else (lambda r: r[0] - start_x)
        unit = "deg" if measure == "yaw" else "mm"
        scale = 1.0 if measure == "yaw" else 1e3
        reference = value(results[(index, "reference", 0)])
        for coupling in COUPLINGS:
            values = [value(results[(index, coupling, p)]) for p in phases]
            mean = sum(values) / len(values)
            error = (mean - reference) / abs(reference)
            lines.append(f"| {label} | {name} {measure} ({unit}) | {scale * reference:.2f} | {coupling} | "
                         f"{scale * mean:.2f} | {100 * error:+.1f} | {scale * (max(values) - min(values)):.2f} |")
            if coupling == "local" and measure == "yaw" and abs(error) > args.max_yaw_error:
                failures.append(f"{label}: local yaw off by {100 * error:+.1f} %")
            if coupling == "local" and label == "two cubes" and abs(error) > args.max_travel_error:
                failures.append(f"{label}: local travel off by {100 * error:+.1f} %")
    text = "\n".join(lines) + "\n"
    (args.out / "table.md").write_text(text)
    print(text)
    if args.check:
        if failures:
            print("CHECK FAILED: " + "; ".join(failures))
            sys.exit(1)
        print("check passed")


if __name__ == "__main__":
    main()
