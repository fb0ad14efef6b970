#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""How deep the spheres scene's balls go into the floor per ODE substep count and contact model, under each coupling.

For each substep count, the spheres scene (scenes/spheres.json) runs with ODE's per-substep ERP and CFM (the
default, "ode") and with the contact as a spring and a damper ("spring": physics.contact_stiffness_Npm 4e6 and
contact_damping_Nspm 8e4, which agree with "ode" at 20 Hz x 10 substeps), on the speed-vs-error report's spheres
trajectory, over --phases world phases. Prints the worst floor penetration (summary world.floor_penetration_max_m) in
mm per coupling, and the world's CPU per simulated second.

usage: penetration_sweep.py [--substeps 10,20,25,40] [--phases 10] [--jobs N] [--out DIR]
"""
import argparse
import json
import os
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

SCENE = ROOT / "scenes/spheres.json"
TRAJECTORY = "slide:x=-0.12,y=0,surface_z=0.04,depth=0.02,distance=0.2,speed=0.2,settle=0.3,hold=0.5"
COUPLINGS = ("impulse", "local", "position")
MODELS = {"ode": {}, "spring": {"contact_stiffness_Npm": 4e6, "contact_damping_Nspm": 8e4}}
WORLD_TICKS = 50  # the scene's 20 Hz world under the 1 kHz haptic clock: phases 0..49


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--substeps", default="10,20,25,40", help="comma-separated substep counts")
    parser.add_argument("--phases", type=int, default=10, help=f"world phases per cell, 1 to {WORLD_TICKS}")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/penetration")
    args = parser.parse_args()
    try:
        substeps = [int(n) for n in args.substeps.split(",")]
    except ValueError:
        sys.exit(f"penetration_sweep: --substeps must be whole numbers separated by commas, not '{args.substeps}'")
    if any(n < 1 for n in substeps) or not 1 <= args.phases <= WORLD_TICKS:
        sys.exit(f"penetration_sweep: substeps must be >= 1 and --phases 1 to {WORLD_TICKS}")
    args.out.mkdir(parents=True, exist_ok=True)
    base = json.loads(SCENE.read_text())
    phases = [k * WORLD_TICKS // args.phases for k in range(args.phases)]
    tasks = []
    for model, physics in MODELS.items():
        scene = json.loads(json.dumps(base))
        scene["physics"].update(physics)
        path = args.out / f"spheres-{model}.json"
        path.write_text(json.dumps(scene))
        for n in substeps:
            for coupling in COUPLINGS:
                for phase in phases:
                    out_dir = args.out / f"{model}-{n}-{coupling}-{phase}"
                    tasks.append(((model, n, coupling, phase), run_trial,
                                  (out_dir, path, TRAJECTORY, coupling, None, phase, n)))
    results = {}
    try:
        for key, summary in run_parallel(tasks, args.jobs):
            results[key] = summary
    except RuntimeError as error:
        sys.exit(f"penetration_sweep: {error}")

    print(f"spheres at 20 Hz, {args.phases} phases: worst floor penetration (mm), impulse / local / position; "
          "world CPU per simulated s (ms)")
    for model in MODELS:
        for n in substeps:
            worst = [max(results[(model, n, c, p)].world["floor_penetration_max_m"] for p in phases) * 1e3
                     for c in COUPLINGS]
            cpu_ms = 1e3 * sum(results[(model, n, "impulse", p)].world["cpu_per_simulated_s"]
                               for p in phases) / len(phases)
            print(f"  {model:6s} {n:3d} substeps: {worst[0]:.2f} / {worst[1]:.2f} / {worst[2]:.2f}; {cpu_ms:.1f}")


if __name__ == "__main__":
    main()
