# SPDX-License-Identifier: Apache-2.0
"""The closed loop and in-memory inputs of the impetus package: a Simulation steered along a trajectory's own points
equals run_trial on that trajectory bit for bit; scenes from dicts and trajectories from arrays equal their files;
the hand's push meets the contact spring as statics says; log columns carry their units; bad input is named.

Run by CTest with PYTHONPATH=BUILD/python; usage: test_closed_loop.py OUT_DIR
"""
import json
import pathlib
import re
import sys
import unittest
import warnings

import numpy as np

import impetus

OUT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else "/tmp/impetus-closed-loop-test")
TAP = impetus.shipped_scene("tap")


def rows(path, count):
    """The header and the first `count` rows of a log, as text."""
    return path.read_text().split("\n")[:count + 1]


def replay(scene, trajectory, ticks, out_dir, **options):
    """A Simulation steered to `trajectory`'s points at the device's tick ends for `ticks` ticks; its summary."""
    start = impetus.sample_trajectory(trajectory, [0.0])[0]
    with impetus.Simulation(scene, start_m=start, out_dir=out_dir, **options) as sim:
        targets = impetus.sample_trajectory(trajectory, sim.device_times_s(ticks))
        step = sim.step(targets=targets)
        assert len(step) == ticks
        return sim.close(), step


class Replay(unittest.TestCase):
    def check_replay(self, name, scene, trajectory, **options):
        scripted_dir, loop_dir = OUT / f"{name}_scripted", OUT / f"{name}_loop"
        scripted = impetus.run_trial(scene, trajectory, out_dir=scripted_dir, **options)
        # The scripted trial's last tick finds the device gone (its trajectory ended); the loop's device never ends.
        ticks = scripted.summary["haptic"]["ticks"] - 1
        summary, step = replay(scene, trajectory, ticks, loop_dir, **options)
        for log in ("haptic.csv", "device.csv", "world.csv"):
            self.assertEqual(rows(scripted_dir / log, ticks), rows(loop_dir / log, ticks), f"{name}: {log}")
        self.assertEqual(scripted.summary["objects"], summary["objects"], name)
        # The step's arrays are the haptic log's columns.
        haptic = impetus.read_log(loop_dir / "haptic.csv")
        self.assertTrue(np.array_equal(step.force_N[:, 0, 0], haptic["force_x_N"]))
        self.assertTrue(np.array_equal(step.proxy_m[:, 0, 2], haptic["proxy_z_m"]))
        self.assertTrue(np.array_equal(step.object_impulse_Ns[:, 0, 0], haptic["object_impulse_x_Ns"]))
        self.assertTrue(np.array_equal(step.active_planes[:, 0], haptic["active_planes"]))
        self.assertTrue(np.array_equal(step.time_s, haptic["time_s"]))
        self.assertGreater(np.abs(step.force_N).max(), 1.0, f"{name}: the finger never pushed")

    def test_tap_under_every_coupling(self):
        for coupling in impetus.COUPLINGS:
            with self.subTest(coupling=coupling):
                self.check_replay(f"tap_{coupling}", TAP, "tap", coupling=coupling, phase_ticks=17)

    def test_a_slide_at_another_rate_with_a_delayed_link(self):
        self.check_replay("slide", impetus.shipped_scene("shapes"),
                          "slide:x=-0.02,surface_z=0.02,distance=0.04,settle=0.1,hold=0.2", coupling="local",
                          rate_hz=50, link_delay_s=0.003)


class Steering(unittest.TestCase):
    def wall_scene(self):
        """A static wall whose -x face is at x = 0 (a dict, as a user builds one in code)."""
        return {"objects": [{"name": "wall", "shape": "box", "size_m": [0.02, 0.2, 0.2], "dynamic": False,
                             "position_m": [0.01, 0.0, 0.1]}]}

    def test_a_hand_push_meets_the_contact_spring_as_statics_says(self):
        # Target on the face, the hand pushing 3 N into a static wall: at rest the finger sinks p with
        # 3 = (k_contact + k_hand)·p, and the device pushes back k_contact·p.
        with impetus.Simulation(self.wall_scene(), start_m=[-0.01, 0, 0.1]) as sim:
            sim.step(targets=np.linspace([-0.01, 0, 0.1], [0.0, 0, 0.1], 200))
            sim.set_hand_force([3.0, 0, 0])
            step = sim.step(1500)
            summary = sim.close()
        k_contact = summary["haptic"]["stiffness_Npm"]
        k_hand = summary["device"]["hand_stiffness_Npm"]
        expected_N = -3.0 * k_contact / (k_contact + k_hand)
        self.assertAlmostEqual(step.force_N[-1, 0, 0], expected_N, delta=0.02 * abs(expected_N))
        self.assertEqual(step.active_planes[-1, 0], 1)
        self.assertLess(abs(step.finger_velocity_mps[-1, 0, 0]), 1e-3)

    def test_targets_hold_between_calls_and_the_finger_follows(self):
        with impetus.Simulation(TAP, start_m=[-0.03, 0, 0.025]) as sim:
            sim.set_target([-0.03, 0.02, 0.03])
            step = sim.step(600)
            self.assertTrue(np.array_equal(step.target_m[-1, 0], [-0.03, 0.02, 0.03]))
            self.assertLess(np.linalg.norm(step.finger_m[-1, 0] - [-0.03, 0.02, 0.03]), 1e-3)
            self.assertEqual(sim.ticks, 600)
            self.assertAlmostEqual(sim.time_s, 0.6)

    def test_two_fingers_and_interleaved_simulations(self):
        fingers = {"thumb": [-0.03, 0.0, 0.025], "index": [0.06, 0.0, 0.025]}
        path = np.linspace([[-0.03, 0.0, 0.025], [0.06, 0.0, 0.025]], [[0.0, 0.0, 0.025], [0.03, 0.0, 0.025]], 400)
        alone = impetus.Simulation(TAP, fingers=fingers, coupling="local")
        expected = alone.step(targets=path)
        alone.close()
        first = impetus.Simulation(TAP, fingers=fingers, coupling="local")
        second = impetus.Simulation(TAP, fingers=fingers, coupling="local")
        halves = []
        for sim in (first, second, first, second):
            halves.append(sim.step(targets=path[:200] if sim.ticks == 0 else path[200:]))
        first.close()
        second.close()
        self.assertEqual(expected.force_N.shape, (400, 2, 3))
        for a, b in ((halves[0], halves[2]), (halves[1], halves[3])):
            self.assertTrue(np.array_equal(np.concatenate((a.force_N, b.force_N)), expected.force_N))
        self.assertGreater(np.abs(expected.force_N[:, 1, 0]).max(), 0.5, "the index finger never touched the cube")

    def test_objects_are_the_worlds(self):
        with impetus.Simulation(TAP, start_m=[-0.03, 0, 0.025], coupling="impulse") as sim:
            sim.step(targets=np.linspace([-0.03, 0, 0.025], [0.02, 0, 0.025], 300))
            sim.step(700)
            objects = sim.objects()
            self.assertEqual(sim.object_names, ("cube",))
            self.assertEqual(objects["orientation_wxyz"].shape, (1, 4))
            summary = sim.close()
        self.assertEqual(objects["position_m"][0].tolist(), summary["objects"]["cube"]["position"])
        self.assertGreater(objects["position_m"][0, 0], 0.04, "the push did not move the cube")


class InMemory(unittest.TestCase):
    def test_a_scene_dict_equals_its_file(self):
        from_file = impetus.run_trial(TAP, "tap", logs=False)
        scene = json.loads(TAP.read_text())
        scene["objects"][0]["mass_kg"] = np.float64(1.0)  # numpy numbers are JSON numbers
        scene["objects"][0]["position_m"] = np.array(scene["objects"][0]["position_m"])
        from_dict = impetus.run_trial(scene, "tap", logs=False)
        self.assertEqual(from_file.summary["objects"], from_dict.summary["objects"])
        self.assertEqual(from_dict.summary["config"]["scene"], "(dict)")

    def test_a_bad_scene_dict_is_named_by_its_json_path(self):
        scene = json.loads(TAP.read_text())
        scene["objects"][0]["mass_kg"] = -1.0
        with self.assertRaises(RuntimeError) as raised:
            impetus.run_trial(scene, "tap")
        self.assertIn("scene: /objects/0/mass_kg", str(raised.exception))
        with self.assertRaises(RuntimeError) as raised:
            impetus.Simulation(scene, start_m=[0, 0, 0.05])
        self.assertIn("scene: /objects/0/mass_kg", str(raised.exception))
        with self.assertRaises(TypeError):
            impetus.run_trial({"objects": [{"name": object()}]}, "tap")

    def test_an_array_trajectory_equals_its_csv_file(self):
        waypoints = np.array([[0.0, -0.03, 0.0, 0.025], [0.2, -0.03, 0.0, 0.025], [0.4, 0.01, 0.0, 0.025],
                              [0.8, -0.03, 0.0, 0.025], [1.5, -0.03, 0.0, 0.025]])
        OUT.mkdir(parents=True, exist_ok=True)
        csv = OUT / "push.csv"
        csv.write_text("t,x,y,z\n" + "".join(",".join(repr(v) for v in row) + "\n" for row in waypoints.tolist()))
        from_file = impetus.run_trial(TAP, str(csv), logs=False)
        from_array = impetus.run_trial(TAP, waypoints, logs=False)
        self.assertEqual(from_file.summary["objects"], from_array.summary["objects"])
        self.assertGreater(from_array.summary["objects"]["cube"]["position"][0], 0.031)
        two = impetus.run_trial(TAP, {"a": waypoints, "b": "tap"}, logs=False)
        self.assertEqual(len(two.summary["haptic"]["endpoints"]), 2)

    def test_a_bad_array_trajectory_is_named(self):
        backwards = np.array([[0.0, 0, 0, 0.05], [0.5, 0, 0, 0.05], [0.4, 0, 0, 0.05]])
        with self.assertRaises(ValueError) as raised:
            impetus.run_trial(TAP, backwards)
        self.assertIn("waypoint 2", str(raised.exception))
        with self.assertRaises(ValueError) as raised:
            impetus.run_trial(TAP, np.zeros((3, 3)))
        self.assertIn("N x 4", str(raised.exception))


class Example(unittest.TestCase):
    def test_the_pd_example_pushes_the_cube_to_its_mark(self):
        sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "examples/python"))
        import pd_push
        rest_m, trace = pd_push.push(0.20, "local")
        # The cube stops where the finger stops: what is left is the contact's compression under the held push
        # (μ·m·g / k = 0.59 N / 2000 N/m = 0.3 mm) and the PD's tracking error; 2 mm is 1 % of the way.
        self.assertAlmostEqual(rest_m, 0.20, delta=0.002)
        self.assertLess(trace["force_x_N"].min(), -0.5, "the finger never pushed")


class Engines(unittest.TestCase):
    def test_every_engine_runs_the_trial_and_the_closed_loop_and_says_so(self):
        self.assertEqual(impetus.ENGINES[0], "ode")
        self.assertIn("bullet", impetus.ENGINES)
        for engine in impetus.ENGINES:
            with self.subTest(engine=engine):
                trial = impetus.run_trial(TAP, "tap", "local", engine=engine, logs=False)
                self.assertEqual(trial.summary["config"]["engine"], engine)
                self.assertGreater(trial.summary["objects"]["cube"]["position"][0], 0.1)
                with impetus.Simulation(TAP, start_m=[-0.03, 0, 0.025], engine=engine) as sim:
                    sim.step(targets=np.linspace([-0.03, 0, 0.025], [0.01, 0, 0.025], 300))
                    self.assertEqual(sim.close()["config"]["engine"], engine)
        with self.assertRaises(ValueError) as raised:
            impetus.run_trial(TAP, "tap", engine="havok")
        self.assertIn("engine", str(raised.exception))


class LogColumns(unittest.TestCase):
    # A column's name ends in its unit; the only names without one are counts, flags, ratios and unit quaternions.
    UNIT = re.compile(r"_(m|mps|radps|N|Ns|Nms|s|ns)$")
    UNITLESS = re.compile(r"^(tick|interpolation_weight|active_planes|flags|count_\d|.*\.q[wxyz])$")

    def test_every_log_column_names_its_unit(self):
        trial = impetus.run_trial(TAP, "tap", coupling="local")
        for log, columns in trial.logs.items():
            for name in columns:
                with self.subTest(log=log, column=name):
                    self.assertTrue(self.UNIT.search(name) or self.UNITLESS.match(name), f"{log}: {name}")


class BadInput(unittest.TestCase):
    def test_refused_with_the_arguments_name(self):
        with self.assertRaises(RuntimeError) as raised:
            impetus.Simulation(TAP, start_m=[5.0, 0, 0.05])
        self.assertIn("outside the device's frame", str(raised.exception))
        with self.assertRaises(ValueError) as raised:
            impetus.Simulation(TAP, start_m=[0, float("nan"), 0.05])
        self.assertIn("start_m", str(raised.exception))
        with self.assertRaises(ValueError) as raised:
            impetus.Simulation(TAP)
        self.assertIn("start_m", str(raised.exception))
        with self.assertRaises(ValueError) as raised:
            impetus.Simulation(TAP, start_m=[0, 0, 0.05], coupling="spring")
        self.assertIn("coupling", str(raised.exception))
        sim = impetus.Simulation(TAP, start_m=[0, 0, 0.05], rate_hz=np.float64(50), phase_ticks=np.int64(3))
        for call, argument in ((lambda: sim.step(targets=np.zeros((5, 2))), "targets"),
                               (lambda: sim.step(targets=[[0, np.inf, 0]]), "targets"),
                               (lambda: sim.step(ticks=2, targets=np.zeros((3, 3))), "ticks"),
                               (lambda: sim.step(-1), "ticks"),
                               (lambda: sim.set_target([0, 0]), "target_m"),
                               (lambda: sim.set_target([0, 0, 0.05], finger=1), "finger"),
                               (lambda: sim.set_hand_force([0, 0, 1], finger="thumb"), "finger")):
            with self.subTest(argument=argument):
                with self.assertRaises(ValueError) as raised:
                    call()
                self.assertIn(argument, str(raised.exception))
        self.assertEqual(len(sim.step(np.int64(3))), 3)
        sim.close()
        with self.assertRaises(RuntimeError):
            sim.step()
        self.assertIsNotNone(sim.close())

    def test_start_up_warnings_reach_python(self):
        scene = {"objects": [{"name": "a", "shape": "sphere", "radius_m": 0.02, "dynamic": True, "mass_kg": 0.1,
                              "position_m": [0.0, 0.0, 0.01]}]}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            impetus.Simulation(scene, start_m=[0, 0.1, 0.05]).close()
        self.assertTrue(any("floor" in str(w.message) for w in caught), [str(w.message) for w in caught])


if __name__ == "__main__":
    unittest.main(verbosity=2)
