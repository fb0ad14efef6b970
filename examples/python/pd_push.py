#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""A PD controller in Python pushes the cube of scenes/tap.json so that it comes to rest at a chosen mark.

usage: pd_push.py [--mark 0.20] [--coupling local] [--sweep] [--out out/pd_push]

Impetus' closed loop (impetus.Simulation) runs the world, the 1 kHz servo and the simulated finger; this script is
the person. Each tick it pushes the finger with a force F = kp·(x_ref − x) + kd·(v_ref − v) + F_ff about a reference
that accelerates toward the cube, cruises, and brakes to rest with the cube's face on the mark, then backs away.
It brakes at half the deceleration friction gives the cube (μ·g), so the cube never runs ahead of the finger and
stops where the finger stops. The feed-forward F_ff is what the reference's motion needs (the finger's mass, and in
contact the cube's mass and its sliding friction μ·m·g), so the PD only corrects.

(A free tap, let go early to coast to the mark, stops ~1.4 cm long with local coupling: the contact spring still
pushes for ~20 ms while the finger unloads. Pushing to the mark leaves only the servo's and the world's own error.)

It prints where the cube stopped. --sweep runs marks from 10 to 30 cm under every coupling and plots the error
(OUT/sweep.png); without it, OUT/trace.png shows the one push.
"""
import argparse
import json
import math
import pathlib
import sys

import numpy as np

import impetus

# The finger's mass (spidar_sim's hand, spidar_sim/finger.h) and a 10 Hz bandwidth for the controller on it,
# critically damped: a person's reaching movements have their energy below ~10 Hz.
FINGER_MASS_KG = 0.1
OMEGA_RADPS = 2 * math.pi * 10.0
KP_NPM = FINGER_MASS_KG * OMEGA_RADPS ** 2
KD_NSPM = 2 * FINGER_MASS_KG * OMEGA_RADPS
ACCELERATION_MPS2 = 2.0  # the reference's start, ~0.2 g: a calm reach
CRUISE_MPS = 0.3         # the reference's top speed, a light push
STANDOFF_M = 0.03        # the finger starts this far in front of the cube's face
HOLD_S = 0.3             # the finger rests on the cube at the mark before backing away
BACK_MPS = 0.05          # and backs away this slowly (no pull: the finger only ever pushes)


def leg(t, distance_m, braking_mps2):
    """Position (m), speed and acceleration at time t of a move over `distance_m` from rest to rest: speeding up at
    ACCELERATION_MPS2 to at most CRUISE_MPS, braking at braking_mps2; and the time it ends."""
    v = min(CRUISE_MPS, math.sqrt(2 * distance_m / (1 / ACCELERATION_MPS2 + 1 / braking_mps2)))
    t1 = v / ACCELERATION_MPS2
    d1 = v * t1 / 2
    d3 = v * v / (2 * braking_mps2)
    t2 = t1 + (distance_m - d1 - d3) / v
    t3 = t2 + v / braking_mps2
    if t < t1:
        return ACCELERATION_MPS2 * t * t / 2, ACCELERATION_MPS2 * t, ACCELERATION_MPS2, t3
    if t < t2:
        return d1 + v * (t - t1), v, 0.0, t3
    if t < t3:
        s = t - t2
        return distance_m - d3 + v * s - braking_mps2 * s * s / 2, v - braking_mps2 * s, -braking_mps2, t3
    return distance_m, 0.0, 0.0, t3


def reference_at(t, standoff_m, distance_m, braking_mps2):
    """The finger's way (m), speed and acceleration at time t: to the cube's face, arriving at rest (a push that
    starts with an impact would knock the cube away), then on with the cube to the mark, a rest of HOLD_S, and
    backing away at BACK_MPS. Also whether the cube is being moved."""
    way, speed, acceleration, approach_s = leg(t, standoff_m, braking_mps2)
    if t < approach_s:
        return way, speed, acceleration, False
    way, speed, acceleration, move_s = leg(t - approach_s, distance_m - standoff_m, braking_mps2)
    if t < approach_s + move_s + HOLD_S:
        return standoff_m + way, speed, acceleration, True
    return distance_m - BACK_MPS * (t - approach_s - move_s - HOLD_S), -BACK_MPS, 0.0, False


def push(mark_m, coupling="local", rate_hz=None):
    """Pushes the cube's centre toward `mark_m` (x, m); returns (where it came to rest, a trace of the run)."""
    scene = json.loads(impetus.shipped_scene("tap").read_text())
    cube = scene["objects"][0]
    half_m = cube["size_m"][0] / 2
    mass_kg = cube["mass_kg"]
    # The scene combines two surfaces' friction by their geometric mean (docs/scene-format.md).
    mu = math.sqrt(cube["dynamic_friction"] * scene["floor"]["dynamic_friction"])
    g = -scene["gravity_mps2"][2]
    start = np.array([cube["position_m"][0] - half_m - STANDOFF_M, 0.0, cube["position_m"][2]])
    distance_m = mark_m - half_m - start[0]  # the finger's way from its start to the face's place at the mark
    braking_mps2 = mu * g / 2
    finger, velocity = start.copy(), np.zeros(3)
    trace = {key: [] for key in ("time_s", "finger_x_m", "reference_x_m", "force_x_N")}
    with impetus.Simulation(scene, start_m=start, coupling=coupling, rate_hz=rate_hz) as sim:
        dt = sim.tick_period_s
        end_s = 3.0 * distance_m / CRUISE_MPS + HOLD_S + 1.0
        touching = False
        for tick in range(int(end_s / dt)):
            way_m, speed_mps, acceleration_mps2, moving = reference_at(tick * dt, STANDOFF_M, distance_m,
                                                                       braking_mps2)
            reference = start + [way_m, 0.0, 0.0]
            reference_velocity = np.array([speed_mps, 0.0, 0.0])
            feed_forward_N = FINGER_MASS_KG * acceleration_mps2
            if touching and moving:
                feed_forward_N += mass_kg * acceleration_mps2 + mu * mass_kg * g
            force = KP_NPM * (reference - finger) + KD_NSPM * (reference_velocity - velocity)
            force[0] += feed_forward_N
            sim.set_target(finger)      # the hand's own spring stays slack: the controller is the hand
            sim.set_hand_force(force)
            step = sim.step()
            finger, velocity = step.finger_m[0, 0], step.finger_velocity_mps[0, 0]
            touching = step.active_planes[0, 0] > 0
            trace["time_s"].append(tick * dt)
            trace["finger_x_m"].append(finger[0])
            trace["reference_x_m"].append(reference[0])
            trace["force_x_N"].append(step.force_N[0, 0, 0])
        rest_m = float(sim.objects()["position_m"][0, 0])
    return rest_m, {key: np.array(values) for key, values in trace.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mark", type=float, default=0.20, help="where the cube's centre should stop (m, 0.1-0.3)")
    parser.add_argument("--coupling", choices=impetus.COUPLINGS, default="local")
    parser.add_argument("--sweep", action="store_true", help="marks 10-30 cm under every coupling, plotted")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/pd_push"), help="where plots go")
    args = parser.parse_args()
    if not 0.1 <= args.mark <= 0.3:
        parser.error(f"--mark: must be between 0.1 and 0.3 m, not {args.mark}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    args.out.mkdir(parents=True, exist_ok=True)
    if not args.sweep:
        rest_m, trace = push(args.mark, args.coupling)
        print(f"pd_push: {args.coupling} coupling: the cube stopped at {rest_m * 100:.2f} cm for a mark at "
              f"{args.mark * 100:.2f} cm (error {(rest_m - args.mark) * 1000:+.1f} mm)")
        figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
        top.plot(trace["time_s"], trace["finger_x_m"] * 100, label="finger x")
        top.plot(trace["time_s"], trace["reference_x_m"] * 100, "--", lw=1, label="reference")
        top.axhline(args.mark * 100, color="k", lw=0.8, ls="--", label="mark")
        top.set_ylabel("cm")
        top.legend(loc="lower right")
        bottom.plot(trace["time_s"], trace["force_x_N"], lw=1)
        bottom.set_ylabel("force on finger, x (N)")
        bottom.set_xlabel("time (s)")
        figure.suptitle(f"A PD controller in Python pushes the cube to {args.mark * 100:.0f} cm ({args.coupling})")
        figure.tight_layout()
        figure.savefig(args.out / "trace.png", dpi=110)
        print(f"pd_push: plot in {args.out / 'trace.png'}")
        return 0
    marks = np.linspace(0.10, 0.30, 9)
    figure, axes = plt.subplots(figsize=(6, 4.5))
    for coupling in impetus.COUPLINGS:
        rests = np.array([push(mark, coupling)[0] for mark in marks])
        errors_mm = (rests - marks) * 1000
        print(f"pd_push: {coupling:8s} error at marks 10..30 cm: " + " ".join(f"{e:+.1f}" for e in errors_mm) +
              f" mm (largest {np.abs(errors_mm).max():.1f} mm)")
        axes.plot(marks * 100, errors_mm, "o-", label=coupling)
    axes.axhline(0.0, color="k", lw=0.8)
    axes.set_xlabel("mark (cm)")
    axes.set_ylabel("where the cube stopped − mark (mm)")
    axes.set_title("A PD controller in Python pushes the cube to a mark")
    axes.legend()
    figure.tight_layout()
    figure.savefig(args.out / "sweep.png", dpi=110)
    print(f"pd_push: plot in {args.out / 'sweep.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
