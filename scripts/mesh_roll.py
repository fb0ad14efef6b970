#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Rolls a ball of 2 cm radius along the floor at 0.5 m/s, as the primitive sphere and as icospheres of 1 280, 5 120
and 20 480 triangles, each on its facets and on its smooth surface ("surface": "smooth"), and prints where each is
and how fast it goes at the end, beside the primitive's (docs/meshes.md, "A smooth surface"). The finger presses far
away and touches nothing. Lockstep, so the numbers repeat.

  PYTHONPATH=build/python /usr/bin/python3 scripts/mesh_roll.py [--out DIR]
"""
import argparse
import importlib.util
import math
import pathlib
import tempfile
import warnings

import impetus

HERE = pathlib.Path(__file__).resolve().parent


def make_meshes_module():
    spec = importlib.util.spec_from_file_location("make_meshes", HERE / "make_meshes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", help="folder for the meshes written (default: a temporary one)")
    args = parser.parse_args()
    out = pathlib.Path(args.out or tempfile.mkdtemp(prefix="impetus-mesh-roll-"))
    out.mkdir(parents=True, exist_ok=True)
    meshes = make_meshes_module()
    radius_m = 0.02
    ball = {"name": "ball", "dynamic": True, "density_kgpm3": 700, "position_m": [0.0, 0.2, radius_m],
            "linear_velocity_mps": [0.5, 0, 0], "static_friction": 0.5, "dynamic_friction": 0.4}
    kinds = [("sphere", dict(ball, shape="sphere", radius_m=radius_m))]
    for subdivisions in (3, 4, 5):
        unit, faces = meshes.icosphere(subdivisions)
        path = out / f"icosphere{subdivisions}.obj"
        meshes.write_obj(path, [tuple(radius_m * x for x in v) for v in unit], faces, "icosphere, 2 cm")
        kinds.append((f"mesh, {len(faces)} triangles", dict(ball, shape="mesh", file=str(path))))
        kinds.append(("  smooth surface", dict(ball, shape="mesh", file=str(path), surface="smooth")))
    print(f"{'ball':<24} {'x (m)':>8} {'y (m)':>8} {'speed (m/s)':>12} {'speed / sphere':>15}")
    sphere_speed = None
    for name, obj in kinds:
        scene = {"floor": {"height_m": 0.0, "static_friction": 0.5, "dynamic_friction": 0.4}, "objects": [obj]}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a 23 g ball is "light for impulse coupling"; the finger never touches it
            trial = impetus.run_trial(scene, "press:x=-0.05,y=-0.05,surface_z=0.2,hold=1.0", "impulse", logs=False)
        state = trial.summary["objects"]["ball"]
        speed = math.hypot(*state["velocity"])
        sphere_speed = sphere_speed or speed
        print(f"{name:<24} {state['position'][0]:8.4f} {state['position'][1]:8.4f} {speed:12.5f} "
              f"{speed / sphere_speed:15.5f}")


if __name__ == "__main__":
    main()
