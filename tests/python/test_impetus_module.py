# SPDX-License-Identifier: Apache-2.0
"""The impetus Python package against the three daemons: a trial run from Python must equal the same trial run by
scripts/run.sh in lockstep bit for bit (logs and final state), its options must reach the nodes, and bad arguments
must be refused with the argument's name.

Run by CTest with PYTHONPATH=BUILD/python and IMPETUS_BUILD_DIR=BUILD; usage: test_impetus_module.py OUT_DIR
"""
import json
import math
import os
import pathlib
import subprocess
import sys
import threading
import unittest
import warnings

import numpy as np

import impetus

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else "/tmp/impetus-python-test")


def run_sh(out_dir, scene, trajectory, coupling, rate, phase, substeps, haptic_flags):
    command = ["bash", str(ROOT / "scripts/run.sh"), "--scene", str(scene), "--trajectory", trajectory,
               "--coupling", coupling, "--clock", "lockstep", "--phase", str(phase), "--out", str(out_dir), "--quiet"]
    if rate is not None:
        command += ["--rate", str(rate)]
    if substeps is not None:
        command += ["--substeps", str(substeps)]
    command += ["--"] + haptic_flags
    subprocess.run(command, check=True, env=dict(os.environ))
    return json.loads((out_dir / "summary.json").read_text())


class SameAsRunSh(unittest.TestCase):
    def check_same(self, name, scene, trajectory, coupling, rate=None, phase=0, substeps=None, stiffness=None,
                   damping=None):
        flags = []
        if stiffness is not None:
            flags += ["--stiffness", str(stiffness)]
        if damping is not None:
            flags += ["--damping", str(damping)]
        processes = run_sh(OUT / f"{name}-processes", scene, trajectory, coupling, rate, phase, substeps, flags)
        trial = impetus.run_trial(scene, trajectory, coupling, rate_hz=rate, phase_ticks=phase, substeps=substeps,
                                  stiffness_Npm=stiffness, damping_Nspm=damping, out_dir=OUT / f"{name}-python")
        for log in impetus.LOG_FILES.values():
            with self.subTest(log=log):
                text = (trial.out_dir / log).read_text()
                self.assertGreater(len(text), 1000)  # a real trial, not two empty logs
                self.assertEqual(text, (OUT / f"{name}-processes" / log).read_text())
        self.assertEqual(trial.summary["objects"], processes["objects"])
        for key in ("world_rate_hz", "substeps", "phase_ticks", "coupling"):
            self.assertEqual(trial.summary["config"][key], processes["config"][key] if key != "phase_ticks"
                             else phase)
        # The arrays are the log's columns: as many rows as ticks, the same numbers as the file.
        haptic = trial.logs["haptic"]
        self.assertEqual(len(haptic["force_x_N"]), trial.summary["haptic"]["ticks"])
        first_row = (trial.out_dir / "haptic.csv").read_text().splitlines()[1].split(",")
        header = (trial.out_dir / "haptic.csv").read_text().splitlines()[0].split(",")
        self.assertEqual([float(v) for v in first_row], [float(haptic[c][0]) for c in header])
        return trial

    def test_defaults(self):
        trial = self.check_same("defaults", ROOT / "scenes/tap.json", "tap", "impulse")
        self.assertGreater(trial.summary["objects"]["cube"]["position"][0], 0.05)  # the tap pushed the cube

    def test_every_option(self):
        # A 10 Hz world (100-tick period) at phase 37 with 12 substeps and a softer, more damped contact than the
        # scene's: each option changes the trial, so a dropped one shows as a different log.
        trial = self.check_same("options", ROOT / "scenes/tap.json", "tap:speed=0.15", "local", rate=10, phase=37,
                                substeps=12, stiffness=3000, damping=4)
        self.assertEqual(trial.summary["haptic"]["stiffness_Npm"], 3000)
        self.assertEqual(trial.summary["haptic"]["damping_Nspm"], 4)
        self.assertEqual(trial.summary["config"]["world_rate_hz"], 10)


class Arguments(unittest.TestCase):
    def scene(self):
        return impetus.shipped_scene("tap")

    def test_options_change_the_outcome(self):
        base = impetus.run_trial(self.scene(), "tap", logs=False)
        stiff = impetus.run_trial(self.scene(), "tap", stiffness_Npm=6000, logs=False)
        self.assertNotEqual(base.summary["objects"], stiff.summary["objects"])
        self.assertEqual(base.logs, {})
        self.assertIsNone(base.out_dir)

    def test_passivity_layer_reaches_the_world(self):
        # Impulse coupling's tap gives the cube more energy than the hand put in; the world's books say so with the
        # layer off, and with it on the cube gets no more than the input, the rest counted as withheld. The switch
        # is the daemon's --passivity: run.sh with it gives the same logs bit for bit.
        off = impetus.run_trial(self.scene(), "tap", logs=False)
        on = impetus.run_trial(self.scene(), "tap", passivity=True, out_dir=OUT / "passivity-python")
        self.assertIs(off.summary["config"]["passivity"], False)
        self.assertIs(on.summary["config"]["passivity"], True)
        port_off, port_on = off.summary["world"]["port"], on.summary["world"]["port"]
        self.assertGreater(port_off["overdraft_J"], 0.01)
        self.assertEqual(port_off["withheld_J"] + port_off["damped_J"], 0.0)
        self.assertLessEqual(port_on["port_work_J"], port_on["hand_input_J"] + 1e-12)
        self.assertGreater(port_on["withheld_J"] + port_on["damped_J"], 0.0)
        self.assertLess(on.summary["objects"]["cube"]["position"][0], off.summary["objects"]["cube"]["position"][0])
        # The hand's half keeps books only with the layer on; what the world handed back came out of its budget.
        hand_off, hand_on = off.summary["haptic"]["hand_port"], on.summary["haptic"]["hand_port"]
        self.assertEqual(hand_off["input_J"] + hand_off["output_J"] + hand_off["credited_J"], 0.0)
        self.assertGreater(hand_on["input_J"], 0.0)
        self.assertGreater(hand_on["credited_J"], 0.0)
        self.assertLessEqual(hand_on["returned_J"], port_on["returned_J"] + 1e-12)  # the last frame may be in flight
        self.assertLessEqual(port_on["port_work_J"] + port_on["returned_J"], port_on["hand_input_J"] + 1e-12)
        processes = OUT / "passivity-processes"
        subprocess.run(["bash", str(ROOT / "scripts/run.sh"), "--scene", str(self.scene()), "--trajectory", "tap",
                        "--passivity", "on", "--clock", "lockstep", "--out", str(processes), "--quiet"], check=True)
        for log in impetus.LOG_FILES.values():
            with self.subTest(log=log):
                self.assertEqual((on.out_dir / log).read_text(), (processes / log).read_text())
        with self.assertRaisesRegex(ValueError, "passivity"):
            impetus.run_trial(self.scene(), "tap", passivity="on")

    def test_link_loss_reaches_the_link(self):
        # Half the packets lost in runs of 20: the summary counts what was lost, the same in a second run.
        lossy = impetus.run_trial(self.scene(), "tap", link_loss=0.5, link_loss_burst=20, logs=False)
        again = impetus.run_trial(self.scene(), "tap", link_loss=0.5, link_loss_burst=20, logs=False)
        self.assertGreater(lossy.summary["link"]["lost_frames"], 0)
        self.assertGreater(lossy.summary["link"]["lost_reports"], 0)
        self.assertEqual(lossy.summary["link"], again.summary["link"])
        self.assertEqual(lossy.summary["objects"], again.summary["objects"])
        for bad in ({"link_loss": 0.6}, {"link_loss": -0.1}, {"link_loss_burst": 0.5}):
            with self.subTest(bad=bad), self.assertRaisesRegex(ValueError, next(iter(bad))):
                impetus.run_trial(self.scene(), "tap", **bad)

    def test_link_delay_reaches_the_link(self):
        # 20 ms each way at 1 kHz is 20 ticks; the delay changes the trial (the cube starts later and stops elsewhere),
        # and the summary says what the link held back.
        base = impetus.run_trial(self.scene(), "tap", logs=False)
        delayed = impetus.run_trial(self.scene(), "tap", link_delay_s=0.02, logs=False)
        self.assertEqual(base.summary["link"], {"delay_s": 0.0, "delay_ticks": 0, "dropped": 0, "loss": 0.0,
                                                "loss_burst_packets": 1.0, "lost_frames": 0, "lost_reports": 0})
        self.assertEqual(delayed.summary["link"]["delay_ticks"], 20)
        self.assertEqual(delayed.summary["link"]["dropped"], 0)
        self.assertNotEqual(base.summary["objects"], delayed.summary["objects"])

    def test_users_same_as_run_sh(self):
        # run.sh --user: a second user's controller and device as processes of their own, following the first's
        # lockstep ticks; the same world as run_trial(users=...) in one process, every log byte for byte.
        paths = []
        for name, from_x, to_x in (("a", -0.01, 0.012), ("b", 0.07, 0.05)):
            path = OUT / f"users-sh-{name}.csv"
            path.write_text(f"t,x,y,z\n0,{from_x},0,0.025\n0.5,{to_x},0,0.025\n2,{to_x},0,0.025\n")
            paths.append(str(path))
        out = OUT / "users-sh-processes"
        subprocess.run(["bash", str(ROOT / "scripts/run.sh"), "--scene", str(impetus.shipped_scene("tap")),
                        "--trajectory", paths[0], "--user", paths[1], "--coupling", "local", "--out", str(out),
                        "--quiet"], check=True, env=dict(os.environ))
        trial = impetus.run_trial(impetus.shipped_scene("tap"), paths[0], "local", users=[paths[1]],
                                  out_dir=OUT / "users-sh-python", logs=False)
        for log in ("world.csv", "haptic.csv", "device.csv", "user1.haptic.csv", "user1.device.csv"):
            with self.subTest(log=log):
                text = (trial.out_dir / log).read_text()
                self.assertGreater(len(text), 1000)
                self.assertEqual(text, (out / log).read_text())
        processes = json.loads((out / "summary.json").read_text())
        self.assertEqual(len(processes["followers"]), 1)
        self.assertEqual(processes["followers"][0]["haptic"]["impulse_by_object_Ns"],
                         trial.summary["followers"][0]["haptic"]["impulse_by_object_Ns"])

    def test_a_mesh_scene_runs(self):
        # The shipped mesh scene: its files named relative to it, read by the world; the tap pushes the mesh cube.
        trial = impetus.run_trial(impetus.shipped_scene("meshes"), "tap", "local", out_dir=OUT / "meshes",
                                  logs=False)
        self.assertEqual(set(trial.summary["objects"]), {"cube", "pebble"})  # the dynamic ones
        self.assertGreater(trial.summary["objects"]["cube"]["position"][0], 0.13)

    def test_clay_is_dented_and_logged(self):
        # The shipped clay: a press dents it; the summary and the world log say how deep, and the dent's volume is the
        # push beyond yield over the flow resistance (docs/deformation.md).
        trial = impetus.run_trial(impetus.shipped_scene("clay"), "press:surface_z=0.03,depth=0.006,hold=0.5",
                                  "impulse", out_dir=OUT / "clay")
        clay = trial.summary["world"]["deformable"]["clay"]
        self.assertGreater(clay["max_dent_m"], 1e-3)
        self.assertAlmostEqual(clay["dent_volume_m3"] * 1e6, clay["yielding_Ns"], delta=1e-12)
        dent = trial.logs["world"]["clay.dent_m"]
        self.assertEqual(dent[0], 0.0)
        self.assertEqual(dent[-1], clay["max_dent_m"])

    def test_users_on_one_world(self):
        # Two users squeeze the tap scene's cube (sides at x = 0.005 and 0.055 m) 10 mm deep from either side: the
        # pushes cancel, the cube stays, and the world applied for each user exactly what that user rendered.
        paths = {}
        for name, from_x, to_x in (("a", -0.01, 0.015), ("b", 0.07, 0.045)):
            paths[name] = OUT / f"users-{name}.csv"
            paths[name].write_text(f"t,x,y,z\n0,{from_x},0,0.025\n0.5,{to_x},0,0.025\n3,{to_x},0,0.025\n")
        trial = impetus.run_trial(impetus.shipped_scene("tap"), str(paths["a"]), "local", users=[str(paths["b"])],
                                  out_dir=OUT / "users", logs=False)
        self.assertTrue((trial.out_dir / "user1.haptic.csv").is_file())
        self.assertEqual(len(trial.summary["followers"]), 1)
        moved_mm = 1e3 * abs(trial.summary["objects"]["cube"]["position"][0] - 0.03)
        self.assertLess(moved_mm, 1.0)
        applied = {(entry["haptic_session"], entry["endpoint"]): entry["impulse_by_object_Ns"]["0"]
                   for entry in trial.summary["world"]["endpoints"]}
        for haptic in (trial.summary["haptic"], trial.summary["followers"][0]["haptic"]):
            rendered = haptic["impulse_by_object_Ns"]["0"]
            self.assertGreater(abs(rendered[0]), 0.5)  # each pushed for seconds
            world_side = applied[(haptic["haptic_session"], 0)]
            for axis in range(3):
                self.assertAlmostEqual(world_side[axis], rendered[axis], delta=1e-12 * max(1.0, abs(rendered[axis])))
        with self.assertRaises(ValueError):
            impetus.run_trial(impetus.shipped_scene("tap"), "tap", users="tap")

    def test_out_of_range_values_name_the_argument(self):
        cases = [(dict(rate_hz=1e300), "rate_hz"), (dict(rate_hz=math.nan), "rate_hz"),
                 # Too large for any C type, or not finite: named by Python, never a TypeError listing signatures.
                 (dict(phase_ticks=2**70), "phase_ticks"), (dict(substeps=2**40), "substeps"),
                 (dict(stiffness_Npm=10**400), "stiffness_Npm"), (dict(stiffness_Npm=math.nan), "stiffness_Npm"),
                 (dict(damping_Nspm=-math.inf), "damping_Nspm"), (dict(duration_s="5"), "duration_s"),
                 (dict(rate_hz=True), "rate_hz"),
                 (dict(substeps=0), "substeps"), (dict(stiffness_Npm=-5.0), "stiffness_Npm"),
                 (dict(damping_Nspm=1e9), "damping_Nspm"), (dict(duration_s=math.inf), "duration_s"),
                 (dict(phase_ticks=50), "phase"), (dict(phase_ticks=-1), "phase_ticks"),
                 (dict(coupling="springy"), "coupling"), (dict(link_delay_s=1.5), "link_delay_s"),
                 (dict(link_delay_s=-0.001), "link_delay_s"), (dict(link_delay_s=math.nan), "link_delay_s")]
        for kwargs, name in cases:
            with self.subTest(**{k: str(v) for k, v in kwargs.items()}):
                with self.assertRaises(ValueError) as raised:
                    impetus.run_trial(self.scene(), "tap", logs=False, **kwargs)
                self.assertIn(name, str(raised.exception))

    def test_wrong_types_name_the_argument(self):
        for kwargs, name in [(dict(scene=123, trajectory="tap"), "scene"), (dict(trajectory=5.0), "trajectory"),
                             (dict(out_dir=7), "out_dir")]:
            with self.subTest(name=name):
                arguments = dict(scene=self.scene(), trajectory="tap")
                arguments.update(kwargs)
                with self.assertRaises(TypeError) as raised:
                    impetus.run_trial(**arguments)
                self.assertTrue(str(raised.exception).startswith(name + ":"), str(raised.exception))

    def test_bad_files_name_the_file(self):
        with self.assertRaises(FileNotFoundError):
            impetus.run_trial(OUT / "no-such-scene.json", "tap")
        bad_scene = OUT / "bad-scene.json"
        bad_scene.parent.mkdir(parents=True, exist_ok=True)
        bad_scene.write_text('{"objects": [{"name": "c", "shape": "box", "size_m": [0.05, 0.05, -1]}]}')
        with self.assertRaises(RuntimeError) as raised:
            impetus.run_trial(bad_scene, "tap")
        self.assertIn("bad-scene.json", str(raised.exception))
        with self.assertRaises(RuntimeError) as raised:
            impetus.run_trial(self.scene(), OUT / "no-such-trajectory.csv")
        self.assertIn("no-such-trajectory.csv", str(raised.exception))
        with self.assertRaises(FileNotFoundError) as raised:
            impetus.shipped_scene("no_such_scene")
        self.assertIn("tap", str(raised.exception))  # the message lists the scenes there are

    def test_threads_take_turns(self):
        # Four threads running trials at once: each gets the outcome of a trial run alone (before the turns, two
        # worlds stepping together aborted inside ODE).
        reference = impetus.run_trial(self.scene(), "tap", logs=False).summary["objects"]
        outcomes, errors = [], []

        def run():
            try:
                for _ in range(3):
                    outcomes.append(impetus.run_trial(self.scene(), "tap", logs=False).summary["objects"])
            except Exception as error:  # noqa: BLE001 — reported below
                errors.append(error)

        threads = [threading.Thread(target=run) for _ in range(4)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        self.assertEqual(errors, [])
        self.assertEqual(len(outcomes), 12)
        for outcome in outcomes:
            self.assertEqual(outcome, reference)

    def test_numpy_numbers_are_numbers(self):
        trial = impetus.run_trial(self.scene(), "tap", logs=False, rate_hz=np.float64(25.0), substeps=np.int64(4),
                                  phase_ticks=np.uint8(3), duration_s=np.float32(0.5))
        self.assertEqual(trial.summary["config"]["world_rate_hz"], 25.0)
        self.assertEqual(trial.summary["config"]["substeps"], 4)

    def test_threads_in_a_fresh_interpreter_do_not_deadlock(self):
        # Four threads whose first trial reads its logs into numpy arrays at once, in an interpreter that had not
        # imported numpy before: numpy's C API used to be looked up on first use under a lock, while holding the GIL.
        code = ("import sys, threading, impetus\n"
                "errors = []\n"
                "def run():\n"
                "    try:\n"
                "        impetus.run_trial(impetus.shipped_scene('tap'), 'tap', duration_s=0.5)\n"
                "    except Exception as error:\n"
                "        errors.append(error)\n"
                "threads = [threading.Thread(target=run) for _ in range(4)]\n"
                "[t.start() for t in threads]\n"
                "[t.join() for t in threads]\n"
                "print('errors', errors)\n")
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                                env=dict(os.environ))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("errors []", result.stdout)

    def test_ctrl_c_ends_a_long_trial(self):
        # A trial of 10^4 s of pressing (minutes of work) and SIGINT a second after it starts: the trial stops between
        # two ticks and KeyboardInterrupt reaches the caller, long before the trial would have ended.
        code = ("import time, impetus\n"
                "start = time.monotonic()\n"
                "try:\n"
                "    impetus.run_trial(impetus.shipped_scene('tap'), 'press:hold=10000', duration_s=10000, logs=False)\n"
                "    print('ran to the end')\n"
                "except KeyboardInterrupt:\n"
                "    print(f'interrupted after {time.monotonic() - start:.2f} s')\n")
        child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True, env=dict(os.environ))
        threading.Event().wait(3.0)  # the import and the trial's start
        child.send_signal(2)  # SIGINT, as Ctrl-C in a terminal
        try:
            out, err = child.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            child.kill()
            self.fail("the trial went on after Ctrl-C")
        print(f"  {out.strip()}")
        self.assertIn("interrupted after", out, err)

    def test_warnings_reach_python(self):
        # What the daemons print as warnings reaches a Python user as RuntimeWarning: a body placed inside the floor,
        # and a trajectory cut at duration_s (it ended with exit 0 and no word before).
        scene = OUT / "sunk.json"
        scene.parent.mkdir(parents=True, exist_ok=True)
        scene.write_text(json.dumps({"objects": [{"name": "ball", "shape": "sphere", "radius_m": 0.02, "dynamic": True,
                                                  "mass_kg": 0.1, "position_m": [0.1, 0.1, 0.01]}]}))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            impetus.run_trial(scene, "tap", logs=False, duration_s=0.3)
        messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
        self.assertTrue(any("'ball' starts 10 mm inside the floor" in m for m in messages), messages)
        self.assertTrue(any("duration_s=0.3" in m for m in messages), messages)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            impetus.run_trial(self.scene(), "tap", "local", logs=False)
        self.assertEqual([str(w.message) for w in caught], [])  # the shipped tap, local coupling: nothing to warn
        # A smooth mesh on an engine that collides its facets.
        pebble = {"name": "pebble", "shape": "mesh", "file": str(ROOT / "scenes" / "meshes" / "pebble.obj"),
                  "surface": "smooth", "dynamic": True, "density_kgpm3": 2600, "position_m": [0.1, 0.1, 0.03]}
        scene.write_text(json.dumps({"physics": {"engine": "bullet"}, "objects": [pebble]}))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            impetus.run_trial(scene, "tap", "local", logs=False, duration_s=0.2)
        messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
        self.assertTrue(any("'pebble' has a smooth surface, but the bullet engine collides its triangles" in m
                            for m in messages), messages)

    def test_the_public_names_and_their_types(self):
        # __all__ names what exists; the stub (PEP 561) declares each of them and every argument of run_trial.
        import ast
        import inspect
        for name in impetus.__all__:
            self.assertTrue(hasattr(impetus, name), name)
        stub = ast.parse((pathlib.Path(impetus.__file__).parent / "__init__.pyi").read_text())
        declared = {node.name for node in stub.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
        declared |= {node.target.id for node in stub.body if isinstance(node, ast.AnnAssign)}
        self.assertLessEqual(set(impetus.__all__), declared)
        self.assertTrue((pathlib.Path(impetus.__file__).parent / "py.typed").is_file())
        stub_run = next(n for n in stub.body if isinstance(n, ast.FunctionDef) and n.name == "run_trial")
        stub_args = [a.arg for a in stub_run.args.args + stub_run.args.kwonlyargs]
        self.assertEqual(stub_args, list(inspect.signature(impetus.run_trial).parameters))

    def test_another_python_is_told_which_it_needs(self):
        # The package without its compiled module, imported by an interpreter that says it is CPython 3.99: the
        # ImportError names the version the module was built for, not a bare "No module named _impetus".
        package = OUT / "no-module" / "impetus"
        package.mkdir(parents=True, exist_ok=True)
        (package / "__init__.py").write_text((pathlib.Path(impetus.__file__)).read_text())
        code = ("import collections, sys\n"
                "V = collections.namedtuple('V', 'major minor micro releaselevel serial')\n"
                "sys.version_info = V(3, 99, 0, 'final', 0)\n"
                f"sys.path.insert(0, {str(package.parent)!r})\n"
                "import impetus\n")
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("was built for CPython 3.", result.stderr)
        self.assertIn("this is 3.99", result.stderr)

    def test_read_log_refuses_a_damaged_file(self):
        damaged = OUT / "damaged.csv"
        damaged.parent.mkdir(parents=True, exist_ok=True)
        damaged.write_text("time_s,force_x_N\n0.0,1.0\n0.001,oops\n")
        with self.assertRaises(RuntimeError) as raised:
            impetus.read_log(damaged)
        self.assertIn("line 3", str(raised.exception))
        self.assertIn("force_x_N", str(raised.exception))
        damaged.write_text("time_s,force_x_N\n0.0,1.0\n0.001,2.0\n")
        self.assertTrue(np.array_equal(impetus.read_log(damaged)["force_x_N"], [1.0, 2.0]))


class Defaults(unittest.TestCase):
    """The package and the scripts take the C++ side's defaults from it, never from a copy."""

    def test_the_package_and_the_daemon_give_the_same_defaults(self):
        binary = pathlib.Path(os.environ["IMPETUS_BUILD_DIR"]) / "world_manager" / "world_manager"
        printed = json.loads(subprocess.run([str(binary), "--defaults"], check=True, capture_output=True,
                                            text=True).stdout)
        self.assertEqual(impetus.defaults(), printed)
        self.assertEqual(impetus.COUPLINGS, ("impulse", "position", "local"))
        self.assertIn("ode", printed["engines"])
        self.assertEqual(printed["shapes"], ["box", "sphere", "capsule", "cylinder", "mesh"])
        # A scene that leaves its haptic and physics keys out runs with what the defaults say.
        OUT.mkdir(parents=True, exist_ok=True)
        bare = OUT / "bare-scene.json"
        tap = json.loads((ROOT / "scenes/tap.json").read_text())
        bare.write_text(json.dumps({"objects": tap["objects"]}))
        trial = impetus.run_trial(bare, "tap", "impulse", duration_s=0.5, logs=False)
        self.assertEqual(trial.summary["haptic"]["damping_Nspm"], printed["scene"]["haptic"]["damping_Nspm"])
        self.assertEqual(trial.summary["haptic"]["stiffness_Npm"], printed["scene"]["haptic"]["stiffness_Npm"])
        self.assertEqual(trial.summary["haptic"]["rate_hz"], printed["haptic_rate_hz"])
        self.assertEqual(trial.summary["config"]["substeps"], printed["scene"]["physics"]["substeps"])
        self.assertEqual(trial.summary["config"]["engine"], printed["scene"]["physics"]["engine"])

    def test_the_scripts_read_the_defaults_from_the_cpp_side(self):
        sys.path.insert(0, str(ROOT / "scripts"))
        from impetus_py import daemon_defaults, trial  # noqa: E402  (the scripts' package)
        document = impetus.defaults()
        self.assertEqual(daemon_defaults.HAPTIC_RATE_HZ, document["haptic_rate_hz"])
        self.assertEqual(daemon_defaults.SCENE_SUBSTEPS, document["scene"]["physics"]["substeps"])
        self.assertEqual(trial.COUPLINGS, tuple(document["couplings"]))


if __name__ == "__main__":
    unittest.main(verbosity=2)
