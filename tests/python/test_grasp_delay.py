# SPDX-License-Identifier: Apache-2.0
"""The two-finger grasp over a delayed world link under local coupling, on a table: the cube is lifted, held and set
back on the table's top, and the trial gains no energy beyond its tolerance. The table is a static box whose top is
where the shipped scene's floor is (the floor itself 10 cm lower), so the fingers' paths are the shipped ones; the
local model must know the table as what the cube lands on (world_manager/couplings/local_coupling.h), or it holds the
cube in the air a round trip after the world's has landed and the fingers throw it (docs/latency.md, the grasp).

Run by CTest with PYTHONPATH=BUILD/python; usage: test_grasp_delay.py OUT_DIR
"""
import json
import pathlib
import sys
import unittest

OUT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else "/tmp/impetus-grasp-delay-test")
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
import latency_experiment as experiment  # noqa: E402  (scripts/: the grasp trial and its measures)

DELAY_MS = 20.0  # one way; docs/latency.md holds local coupling passive up to it
PHASES = (0, 23)  # world-clock phases (haptic ticks), one on the period's start and one well inside it


def table_scene():
    """scenes/grasp.json with its floor 10 cm down and a 40 cm table whose top is where the floor was."""
    scene = json.loads(experiment.GRASP_SCENE.read_text())
    floor = scene["floor"]
    scene["floor"] = dict(floor, height_m=-0.1)
    scene["objects"].append({"name": "table", "shape": "box", "size_m": [0.4, 0.4, 0.1], "dynamic": False,
                             "position_m": [0.0, 0.0, -0.05], "static_friction": floor["static_friction"],
                             "dynamic_friction": floor["dynamic_friction"], "restitution": 0.0})
    path = OUT / "grasp_on_table.json"
    path.write_text(json.dumps(scene, indent=2))
    return path


class GraspOnTable(unittest.TestCase):
    def test_delayed_grasp_on_a_table_is_passive_and_lands_on_the_table(self):
        OUT.mkdir(parents=True, exist_ok=True)
        scene = table_scene()
        rest_z_m = json.loads(scene.read_text())["objects"][0]["position_m"][2]
        for phase in PHASES:
            with self.subTest(phase=phase):
                row = experiment.grasp_trial(OUT / f"phase{phase}", "local", phase, DELAY_MS, scene=scene)
                self.assertEqual(row["delay_ticks"], round(DELAY_MS))
                self.assertGreater(row["lift_mm"], 30.0)  # lifted (the fingers' targets rise 50 mm)
                self.assertGreater(row["lift_end_mm"], 0.5 * row["lift_mm"])  # and held
                # Set back down on the table's top, not sunk into it or left in the air (ODE's contact slop: 1 mm).
                self.assertAlmostEqual(row["final_z_m"], rest_z_m, delta=1e-3)
                self.assertLessEqual(row["energy_gain_J"], row["energy_tolerance_J"],
                                     f"phase {phase}: gain {1e3 * row['energy_gain_J']:.2f} mJ")
                self.assertLessEqual(row["ledger_error"], experiment.LEDGER_TOLERANCE)


if __name__ == "__main__":
    unittest.main()
