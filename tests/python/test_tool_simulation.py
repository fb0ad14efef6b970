# SPDX-License-Identifier: Apache-2.0
"""A tool in the hand from Python (impetus.ToolSimulation): the shipped peg-in-hole scene played through the simulated
8-string grip SPIDAR. The peg goes down the hole and presses its floor, a tilt is pushed back by the walls, a pushed
cube slides with the world applying what the tool rendered, two runs are bitwise equal, a scene dict equals its file,
and bad input is named.

Run by CTest with PYTHONPATH=BUILD/python.
"""
import json
import math
import pathlib
import unittest

import numpy as np

import impetus

PEG = impetus.shipped_scene("peg_in_hole")
START = [0.0, 0.0, 0.1]  # the peg's tip 2 cm above the hole's rim (it hangs 5 cm below the grip)


def line(a, b, ticks):
    """Positions from a to b over `ticks` ticks (the first tick's target one step from a)."""
    return np.linspace(a, b, ticks + 1)[1:]


def turned_y(angle_rad):
    return [math.cos(angle_rad / 2), 0.0, math.sin(angle_rad / 2), 0.0]


class PegInHole(unittest.TestCase):
    def test_down_the_hole_onto_its_floor(self):
        with impetus.ToolSimulation(PEG, start_m=START) as sim:
            step = sim.step(targets=line(START, [0, 0, 0.045], 1000))
            rest = sim.step(500)
        # Inside the hole (tip below its rim at 3 cm) the proxy keeps within the 0.5 mm of clearance, and above the
        # floor.
        tip = step.proxy_m[:, 2] - 0.05
        inside = tip < 0.03
        self.assertTrue(inside.any())
        self.assertLessEqual(np.abs(step.proxy_m[inside, :2]).max(), 0.0005 + 1e-9)
        self.assertGreaterEqual(tip.min(), -1e-9)
        # Held on the floor: pushed straight up, no torque; the strings render it.
        self.assertGreater(rest.force_N[-1, 2], 0.5)
        self.assertLess(np.linalg.norm(rest.force_N[-1, :2]), 1e-6)
        self.assertLess(np.linalg.norm(rest.torque_Nm[-1]), 1e-6)
        self.assertLess(np.linalg.norm(rest.strings_force_N[-1] - rest.force_N[-1]), 1e-3)
        # The driver's pose from the counts against the hand's true grip when they were read.
        self.assertLess(np.linalg.norm(rest.grip_m - rest.hand_m, axis=1).max(), 2e-5)

    def test_a_tilt_in_the_hole_is_pushed_back(self):
        with impetus.ToolSimulation(PEG, start_m=START) as sim:
            sim.step(targets=line(START, [0, 0, 0.07], 600))  # the tip 1 cm deep in the hole
            poses = np.hstack([np.tile([0, 0, 0.07], (400, 1)),
                               np.array([turned_y(0.2 * (i + 1) / 400) for i in range(400)])])
            step = sim.step(targets=poses)
            held = sim.step(300)
        # The hand turns the grip about +y; the walls hold the peg, so the torque on the grip is about -y, and it is
        # what the coupling's spring gives for the turn between grip and proxy, k_r times the angle. Averaged over the
        # last 0.2 s: the grip's turn read from the counts dithers by about a count over the grip's radius (~1 mrad),
        # and the coupling's damper renders the dither's rate.
        torque = held.torque_Nm[-200:]
        self.assertLess(torque[:, 1].max(), -1e-3)
        between = [2 * math.acos(min(1.0, abs(float(np.dot(g, p)))))
                   for g, p in zip(held.grip_wxyz[-200:], held.proxy_wxyz[-200:])]
        self.assertAlmostEqual(-torque[:, 1].mean(), 20.0 * np.mean(between), delta=0.05 * 20.0 * np.mean(between))
        self.assertGreater(len(step), 0)

    def test_a_pushed_cube_slides_and_the_world_applies_what_was_rendered(self):
        for coupling in ("local", "impulse"):
            with self.subTest(coupling=coupling):
                with impetus.ToolSimulation(PEG, start_m=START, coupling=coupling) as sim:
                    sim.step(targets=line(START, [0.04, 0, 0.07], 500))
                    sim.step(targets=line([0.04, 0, 0.07], [0.075, 0, 0.07], 500))
                    sim.step(500)
                    summary = sim.close()
                ledger = summary["ledger"]["cube"]
                self.assertGreater(ledger["rendered_Ns"][0], 0.01)
                np.testing.assert_allclose(ledger["applied_Ns"], ledger["rendered_Ns"], rtol=0, atol=1e-12)
                np.testing.assert_allclose(ledger["applied_Nms"], ledger["rendered_Nms"], rtol=0, atol=1e-12)
                self.assertEqual(summary["device"]["bad_readings"], 0)

    def test_bitwise_reproducible_and_a_dict_scene_equals_its_file(self):
        def run(scene):
            with impetus.ToolSimulation(scene, start_m=START) as sim:
                step = sim.step(targets=line(START, [0.06, 0.005, 0.07], 800))
                return step.force_N, sim.objects()["position_m"]
        a, b = run(PEG), run(PEG)
        c = run(json.loads(PEG.read_text()))
        for x, y in ((a, b), (a, c)):
            np.testing.assert_array_equal(x[0], y[0])
            np.testing.assert_array_equal(x[1], y[1])


class Logs(unittest.TestCase):
    def test_out_dir_gets_the_logs_and_summary_a_replay_reads(self):
        import tempfile
        with tempfile.TemporaryDirectory() as scratch:
            out = pathlib.Path(scratch) / "run"
            with impetus.ToolSimulation(PEG, start_m=START, out_dir=out) as sim:
                step = sim.step(targets=line(START, [0.04, 0, 0.07], 300))
                summary = sim.close()
            self.assertEqual(json.loads((out / "summary.json").read_text()), summary)
            self.assertEqual(summary["config"]["scene"], str(PEG))
            haptic = impetus.read_log(out / "haptic.csv")
            self.assertEqual(len(haptic["tick"]), 300)  # a row a tick: the grip's centre as the finger
            np.testing.assert_allclose(haptic["finger_z_m"][-1], 0.07, atol=1e-3)
            world = impetus.read_log(out / "world.csv")
            self.assertEqual(len(world["time_s"]), 6 + 2)  # a row a world step: 300 ticks at 20 Hz, and close()'s two
            self.assertIn("cube.x_m", world)
            # The tool's own log: the grip's and the proxy's poses and the wrench, a row a tick, as the steps had them.
            tool = impetus.read_log(out / "haptic.tool.csv")
            self.assertEqual(len(tool["tick"]), 300)
            grip = np.column_stack([tool[f"grip_{c}"] for c in ("x_m", "y_m", "z_m", "qw", "qx", "qy", "qz")])
            np.testing.assert_array_equal(grip, np.hstack([step.grip_m, step.grip_wxyz]))
            proxy = np.column_stack([tool[f"proxy_{c}"] for c in ("x_m", "y_m", "z_m", "qw", "qx", "qy", "qz")])
            np.testing.assert_array_equal(proxy, np.hstack([step.proxy_m, step.proxy_wxyz]))
            torque = np.column_stack([tool[f"torque_{c}_Nm"] for c in "xyz"])
            np.testing.assert_array_equal(torque, step.torque_Nm)


class Example(unittest.TestCase):
    def test_the_peg_in_hole_example_feels_each_stage(self):
        import sys
        sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"))
        import peg_in_hole
        stages, cube_m, summary = peg_in_hole.run()
        felt = {name: (step.force_N[-1], step.torque_Nm[-1]) for name, step in stages}
        self.assertGreater(felt["pressing its floor"][0][2], 0.5)
        self.assertLess(felt["held turned"][1][1], -1e-3)
        # Out of the hole the hand holds the aluminium peg's weight, straight down under the grip: no torque.
        weight_N = 2700 * 0.01 * 0.01 * 0.04 * 9.81
        np.testing.assert_allclose(felt["out"][0], [0, 0, -weight_N], rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(felt["out"][1], [0, 0, 0], atol=1e-12)
        self.assertGreater(cube_m[0], 0.085)
        self.assertEqual(summary["device"]["bad_readings"], 0)


class DeviceFile(unittest.TestCase):
    def test_a_grip_device_file_is_the_frame_the_tool_is_held_in(self):
        # The shipped file is the built-in frame: the same run, bit for bit. A wider frame with a finer count reads
        # the grip as well, and still renders the floor's push through its own strings.
        import tempfile
        shipped = pathlib.Path(__file__).resolve().parents[2] / "common" / "spidar" / "desktop_grip.json"
        runs = []
        for device in ("grip", f"grip:{shipped}"):
            with impetus.ToolSimulation(PEG, start_m=START, device=device) as sim:
                runs.append(sim.step(targets=line(START, [0, 0, 0.045], 600)))
        np.testing.assert_array_equal(runs[0].force_N, runs[1].force_N)
        np.testing.assert_array_equal(runs[0].grip_m, runs[1].grip_m)
        with tempfile.TemporaryDirectory() as scratch:
            wide = pathlib.Path(scratch) / "wide_grip.json"
            wide.write_text(json.dumps({"frame_side_m": 0.6, "metres_per_count": 5e-6}))
            with impetus.ToolSimulation(PEG, start_m=START, device=f"grip:{wide}") as sim:
                step = sim.step(targets=line(START, [0, 0, 0.045], 600))
                step = sim.step(300)
                summary = sim.close()
        self.assertLess(np.abs(step.grip_m - step.hand_m).max(), 5e-6)  # within a count of the finer encoders
        self.assertGreater(step.force_N[-1][2], 0.5)                     # the hole's floor pushes back
        np.testing.assert_allclose(step.strings_force_N[-1], step.force_N[-2], atol=2e-3)
        self.assertEqual(summary["device"]["bad_readings"], 0)


class BadInput(unittest.TestCase):
    def test_named(self):
        cases = [
            (lambda: impetus.ToolSimulation(impetus.shipped_scene("tap"), start_m=START), 'no "tool" block'),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, coupling="position"), "position coupling"),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, coupling="glue"), "coupling"),
            (lambda: impetus.ToolSimulation(PEG, start_m=[0, 0, 0.9]), "start"),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, start_wxyz=[1, 1, 0, 0]), "start_wxyz"),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, rate_hz=30), "whole number of 1 ms ticks"),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, device="spidar"), "'grip' or 'grip:FILE.json'"),
            (lambda: impetus.ToolSimulation(PEG, start_m=START, device="grip:/nonexistent/grip.json"),
             "/nonexistent/grip.json"),
        ]
        for make, words in cases:
            with self.subTest(words=words):
                with self.assertRaises(ValueError) as caught:
                    make()
                self.assertIn(words, str(caught.exception))
        with impetus.ToolSimulation(PEG, start_m=START) as sim:
            for targets, words in (([[0, 0]], "ticks x 3 or ticks x 7"), ([[0, 0, 0.1, 2, 0, 0, 0]], "not unit"),
                                   ([[0, 0, 0.9]], "target"), ([[0, 0, float("nan")]], "finite")):
                with self.subTest(words=words):
                    with self.assertRaises(ValueError) as caught:
                        sim.step(targets=targets)
                    self.assertIn(words, str(caught.exception))
            self.assertEqual(sim.ticks, 0)  # a refused call takes no tick
        with self.assertRaises(RuntimeError):
            sim.step(1)


if __name__ == "__main__":
    unittest.main()
