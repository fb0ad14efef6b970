#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Prints one digest per lockstep trial of a fixed set, for checking that a change leaves every result bitwise as it
was: run it before and after and diff the two outputs.

usage: log_digest.py [--out DIR] [--quiet]

The set: the tap under each coupling; every hard case (tests/hard_cases/, scripts/hard_cases.py) under impulse and
local coupling, at most 20 s each; and a scene of every shape kind (scenes/shapes.json) stirred by a circling
finger under each coupling. A digest is the md5 of the trial's CSV logs' rows, without their header rows (so renaming a
column keeps the digest) and with world.csv's haptic_time_s column left out (the clock pairing, not physics). Runs in this process through the impetus package (PYTHONPATH=build/python).
"""
import argparse
import hashlib
import pathlib
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import hard_cases  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.progress import ProgressBar  # noqa: E402
from impetus_py.trial import _impetus_module  # noqa: E402

STIR = "circle:radius=0.03,period=1.5,cx=0,cy=0,cz=0.01,turns=3"


def trials():
    """(name, scene, trajectory, coupling, world rate or None) of every trial in the set."""
    out = [(f"tap_{c}", ROOT / "scenes/tap.json", "tap", c, None) for c in ("impulse", "position", "local")]
    for key, _, scene, trajectory, rate, _ in hard_cases.CASES:
        for coupling in ("impulse", "local"):
            out.append((f"c{key}_{coupling}", hard_cases.CASES_DIR / scene, hard_cases.resolve_trajectory(trajectory),
                        coupling, rate))
    out += [(f"shapes_{c}", ROOT / "scenes/shapes.json", STIR, c, None) for c in ("impulse", "position", "local")]
    return out


def digest(trial_dir):
    h = hashlib.md5()
    for log in sorted(trial_dir.glob("*.csv")):
        lines = log.read_text().split("\n")
        if lines[0].endswith(",haptic_time_s"):
            lines = [line.rsplit(",", 1)[0] if line else line for line in lines]
        h.update("\n".join(lines[1:]).encode())
    return h.hexdigest()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, help="keep the trials here (default: a temporary folder)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args()
    impetus = _impetus_module()
    if impetus is None:
        sys.exit("log_digest: needs the impetus package (bash scripts/build.sh; PYTHONPATH=build/python)")
    with tempfile.TemporaryDirectory() as scratch:
        out = args.out or pathlib.Path(scratch)
        todo = trials()
        progress = ProgressBar(len(todo), len(todo), label="log_digest", quiet=args.quiet)
        try:
            for name, scene, trajectory, coupling, rate in todo:
                impetus.run_trial(scene, trajectory, coupling=coupling, rate_hz=rate, out_dir=out / name, logs=False,
                                  duration_s=20)
                print(name, digest(out / name), flush=True)
                progress.advance()
        finally:
            progress.close()


if __name__ == "__main__":
    main()
