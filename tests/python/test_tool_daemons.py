#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""A tool in the hand on the three daemons (scripts/run.sh --device grip): spidar_sim plays the 8-string grip SPIDAR
along a trajectory that turns, the haptic controller renders the scene's tool (--tool-from) and the world moves what
it pushes. In lockstep: the peg goes down its hole and presses the floor, is pushed back when turned, hangs by its
weight in the air and pushes the cube; the world applies what was rendered; two runs are bitwise equal; and the
in-process tool loop (impetus.ToolSimulation) steered along the same trajectory agrees.

usage: test_tool_daemons.py [OUT_DIR]   (IMPETUS_BUILD_DIR names the build, as for run.sh)"""

import json
import math
import os
import pathlib
import subprocess
import sys
import unittest

import numpy as np

import impetus

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else "/tmp/impetus-tool-daemons-test")
SCENE = ROOT / "scenes" / "peg_in_hole.json"
TRAJECTORY = ROOT / "scenes" / "peg_in_hole.csv"
PEG_WEIGHT_N = 2700 * 0.01 * 0.01 * 0.04 * 9.81  # the aluminium peg of the scene
TIP_BELOW_GRIP_M = 0.05                            # placed 3 cm below the grip, 4 cm long


def run_sh(out_dir, *extra):
    subprocess.run(["bash", str(ROOT / "scripts/run.sh"), "--scene", str(SCENE), "--device", "grip",
                    "--trajectory", str(TRAJECTORY), "--coupling", "local", "--clock", "lockstep",
                    "--out", str(out_dir), "--quiet", *extra], check=True, env=dict(os.environ))
    return json.loads((out_dir / "summary.json").read_text())


def between(log, t0, t1):
    """The rows of a log whose time is in [t0, t1)."""
    mask = (log["time_s"] >= t0) & (log["time_s"] < t1)
    return {name: column[mask] for name, column in log.items()}


def waypoints():
    """The trajectory's waypoints: times, positions and orientations (w, x, y, z)."""
    table = np.loadtxt(TRAJECTORY, delimiter=",", skiprows=1)
    return table[:, 0], table[:, 1:4], table[:, 4:8]


def target_at(t_s):
    """Where the trajectory's hand aims at t_s: positions linear, orientations along the shorter arc."""
    times, positions, turns = waypoints()
    if t_s >= times[-1]:
        return np.concatenate([positions[-1], turns[-1]])
    k = int(np.searchsorted(times, t_s, side="right")) - 1
    a = (t_s - times[k]) / (times[k + 1] - times[k])
    position = positions[k] + a * (positions[k + 1] - positions[k])
    # Each of these turns is about y from level or back (w, 0, s, 0): its angle interpolates.
    angle0 = 2 * math.atan2(turns[k][2], turns[k][0])
    angle1 = 2 * math.atan2(turns[k + 1][2], turns[k + 1][0])
    angle = angle0 + a * (angle1 - angle0)
    return np.concatenate([position, [math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0]])


class Daemons(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.summary = run_sh(OUT / "first")
        cls.tool = impetus.read_log(OUT / "first" / "haptic.tool.csv")

    def test_the_peg_goes_down_the_hole_and_presses_its_floor(self):
        pressing = between(self.tool, 1.7, 2.0)
        self.assertGreater(pressing["force_z_N"].min(), 1.0)  # the hand's 300 N/m 5 mm past the floor, in series
        self.assertLess(np.abs(pressing["torque_y_Nm"]).max(), 1e-3)
        tip_m = pressing["proxy_z_m"] - TIP_BELOW_GRIP_M
        self.assertGreater(tip_m.min(), -1e-9)  # never into the floor of the hole

    def test_turned_in_the_hole_it_is_pushed_back(self):
        held = between(self.tool, 2.8, 3.0)
        self.assertLess(held["torque_y_Nm"].max(), -0.01)

    def test_in_the_air_the_hand_holds_the_weight(self):
        out = between(self.tool, 3.8, 4.0)
        np.testing.assert_allclose(out["force_z_N"], -PEG_WEIGHT_N, rtol=1e-9)
        np.testing.assert_allclose(out["force_x_N"], 0.0, atol=1e-12)
        # Its moment: the peg hangs 3 cm below the grip, whose tilt read from the counts dithers by ~1 mrad.
        np.testing.assert_allclose(out["torque_y_Nm"], 0.0, atol=0.03 * PEG_WEIGHT_N * 1e-3)

    def test_the_cube_is_pushed_and_the_world_applies_what_was_rendered(self):
        cube = self.summary["objects"]["cube"]
        self.assertGreater(cube["position"][0], 0.085)  # from 8 cm
        rendered = np.array(self.summary["haptic"]["impulse_by_object_Ns"]["4"])
        np.testing.assert_allclose(cube["impulse_Ns"], rendered, rtol=1e-12, atol=1e-15)
        angular = np.array(self.summary["haptic"]["angular_impulse_by_object_Nms"]["4"])
        np.testing.assert_allclose(cube["angular_impulse_Nms"], angular, rtol=1e-12, atol=1e-15)
        self.assertEqual(self.summary["haptic"]["device"]["bad_readings"], 0)

    def test_two_runs_are_bitwise_equal(self):
        run_sh(OUT / "second")
        for name in ("world.csv", "haptic.csv", "haptic.tool.csv", "device.csv"):
            with self.subTest(log=name):
                self.assertEqual((OUT / "first" / name).read_bytes(), (OUT / "second" / name).read_bytes())

    def test_the_in_process_loop_on_the_same_trajectory_agrees(self):
        # The daemon's hand samples the trajectory every 0.1 ms sub-step, the loop's moves straight between the
        # tick ends: the same path up to the turns' chords, so the cube ends where it does to a fraction of a mm.
        ticks = int(round(waypoints()[0][-1] * 1000))
        targets = np.array([target_at((k + 1) * 1e-3) for k in range(ticks)])
        with impetus.ToolSimulation(SCENE, start_m=targets[0][:3], coupling="local") as sim:
            step = sim.step(targets=targets)
            cube_m = sim.objects()["position_m"][sim.object_names.index("cube")]
        self.assertLess(abs(cube_m[0] - self.summary["objects"]["cube"]["position"][0]), 1e-3)
        daemon = between(self.tool, 1.7, 2.0)["force_z_N"].mean()
        loop = step.force_N[(step.time_s >= 1.7) & (step.time_s < 2.0), 2].mean()
        self.assertAlmostEqual(daemon, loop, delta=0.02 * loop)


class BadInput(unittest.TestCase):
    def test_named(self):
        for extra, words in (((), "give no --finger"), (("--coupling", "position"), "position coupling")):
            with self.subTest(words=words):
                command = ["bash", str(ROOT / "scripts/run.sh"), "--scene", str(SCENE), "--device", "grip",
                           "--trajectory", str(TRAJECTORY), "--clock", "lockstep", "--out", str(OUT / "bad"),
                           "--quiet", *extra]
                if words == "give no --finger":
                    command += ["--user", "tap"]
                result = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ))
                self.assertNotEqual(result.returncode, 0)
                self.assertIn(words, result.stderr)


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    unittest.main()
