# SPDX-License-Identifier: Apache-2.0
"""The catch (hard case 12a: a cube slides down a 25° ramp into a finger held still) under impulse coupling with the
passivity layer: caught, settled against the finger, and no energy gained. The push that holds the cube on the ramp
is a force over the world period (world_manager/couplings/impulse_coupling.cpp: what the contacts hold includes the
weight along the slope the supports do not carry); as kicks, each one threw the cube up the ramp with no more energy
than it brought, friction took that on the way up, and the cube crept down through the finger at 15 mm/s
(docs/latency.md, "Catch").

Run by CTest with PYTHONPATH=BUILD/python; usage: test_catch_layer.py OUT_DIR
"""
import pathlib
import sys
import unittest

OUT = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else "/tmp/impetus-catch-layer-test")
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
import latency_experiment as experiment  # noqa: E402  (scripts/: the catch trial and its measures)

SETTLED_M = 1e-4  # the experiment's own measure: under 0.1 mm of motion in the last 0.5 s
PHASES = (0, 31)  # world-clock phases (haptic ticks), one on the period's start and one well inside it


class CatchWithTheLayer(unittest.TestCase):
    def test_a_cube_caught_under_impulse_coupling_with_the_layer_rests_against_the_finger(self):
        for phase in PHASES:
            with self.subTest(phase=phase):
                row = experiment.catch_trial(OUT / f"phase{phase}", "impulse+layer", phase, 0.0)
                self.assertTrue(row["caught"])
                self.assertLess(row["settle_m"], SETTLED_M, f"moved {1e3 * row['settle_m']:.2f} mm in the last 0.5 s")
                self.assertLess(row["leaving_mps"], row["arrival_mps"])  # stopped, not thrown back faster
                self.assertLessEqual(row["energy_gain_J"], row["energy_tolerance_J"])
                self.assertLessEqual(row["ledger_error"], experiment.LEDGER_TOLERANCE)


if __name__ == "__main__":
    unittest.main()
