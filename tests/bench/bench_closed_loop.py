#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Throughput of the closed loop from Python (impetus.Simulation): simulated ticks per wall second when Python steps
1, 10, 50 or 1000 ticks per call, with the finger pressing on the tap scene's cube (in contact every tick) and with
it in free space; and a per-tick controller (set_target + set_hand_force + step(1)). Asserts nothing.

usage: bench_closed_loop.py [--seconds 2]   (PYTHONPATH=build/python)
"""
import argparse
import sys
import time

import numpy as np

import impetus


def rate(sim, ticks_per_call, targets, seconds):
    """Ticks per second over `seconds` of calls of `ticks_per_call` ticks (the median of three runs)."""
    rates = []
    for _ in range(3):
        block = np.repeat(targets[np.newaxis], ticks_per_call, axis=0)
        done = 0
        start = time.perf_counter()
        while time.perf_counter() - start < seconds / 3:
            sim.step(targets=block)
            done += ticks_per_call
        rates.append(done / (time.perf_counter() - start))
    return sorted(rates)[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="wall time per measurement (default 2)")
    args = parser.parse_args()
    scene = impetus.shipped_scene("tap")
    cases = {"free space": np.array([-0.03, 0.0, 0.025]), "pressing the cube": np.array([0.01, 0.0, 0.025])}
    for name, target in cases.items():
        with impetus.Simulation(scene, start_m=[-0.03, 0.0, 0.025], coupling="local") as sim:
            sim.step(targets=np.linspace([-0.03, 0.0, 0.025], target, 300))
            for ticks in (1, 10, 50, 1000):
                print(f"closed loop, {name}, {ticks:4d} ticks per call: {rate(sim, ticks, target, args.seconds):10.0f} "
                      "ticks/s")
            contact = sim.step(1).active_planes[0, 0]
            print(f"  (finger {'in contact' if contact else 'free'} at the end; goal: >= 200000 ticks/s at 50 a call)")
    with impetus.Simulation(scene, start_m=[-0.03, 0.0, 0.025], coupling="local") as sim:
        finger = np.array([-0.03, 0.0, 0.025])
        done = 0
        start = time.perf_counter()
        while time.perf_counter() - start < args.seconds:
            sim.set_target(finger)
            sim.set_hand_force([0.5, 0.0, 0.0])
            finger = sim.step().finger_m[0, 0]
            done += 1
        print(f"closed loop, a Python controller every tick (set_target, set_hand_force, step(1)): "
              f"{done / (time.perf_counter() - start):.0f} ticks/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
