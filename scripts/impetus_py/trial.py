# SPDX-License-Identifier: Apache-2.0
"""Running one trial: the three daemons in lockstep through scripts/run.sh (DESIGN.md §3), into a directory of its
own (logs, the daemons' summaries and summary.json)."""
import subprocess

from .paths import ROOT
from .summary import Summary

# The couplings world_manager --coupling accepts (README "What runs"):
#   impulse   force integration, the paper's method: the world applies the impulse the haptic side integrated since
#             its last step;
#   position  the paper's previous method: a penalty force from the finger sampled at the world step, held for the
#             whole world period;
#   local     impulse coupling plus the paper's §6.3: the haptic side moves the touched objects between world steps.
COUPLINGS = ("impulse", "position", "local")


def run_trial(out_dir, scene, trajectory, coupling, rate_hz=None, phase_ticks=None, substeps=None, haptic_flags=()):
    """Runs one lockstep trial of `scene` (a path) driven by `trajectory` (a spidar_sim --trajectory spec or file)
    into out_dir and returns its Summary. rate_hz, phase_ticks and substeps are world_manager's --rate, --phase and
    --substeps (None: the scene's rate and substeps, phase 0); haptic_flags are extra haptic_controller flags (e.g.
    ["--stiffness", 5000]). Raises RuntimeError with run.sh's output if the trial failed."""
    out_dir.mkdir(parents=True, exist_ok=True)
    command = ["bash", str(ROOT / "scripts/run.sh"), "--scene", str(scene), "--trajectory", str(trajectory),
               "--coupling", coupling, "--clock", "lockstep", "--out", str(out_dir), "--quiet"]
    for flag, value in (("--rate", rate_hz), ("--phase", phase_ticks), ("--substeps", substeps)):
        if value is not None:
            command += [flag, str(value)]
    if haptic_flags:
        command += ["--"] + [str(flag) for flag in haptic_flags]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"trial failed ({' '.join(command)}):\n{result.stdout}{result.stderr}")
    return Summary.read(out_dir)
