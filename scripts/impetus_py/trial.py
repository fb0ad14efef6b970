# SPDX-License-Identifier: Apache-2.0
"""Running one lockstep trial into a directory of its own (logs, summary.json), in one of two ways:

  module     the impetus Python package (python/, built into BUILD/python): the three nodes in this process, no
             process started; the default whenever the package is built
  processes  the three daemons through scripts/run.sh (docs/architecture.md §3); used when the package is not built
             (sanitizer builds do not build it: their daemons are what such a run checks) or when
             IMPETUS_TRIALS=processes

Both give the same trial bit for bit (tests/python/test_impetus_module.py); the module is several times faster per
trial (README, "From Python").
"""
import importlib
import os
import subprocess
import sys

from .paths import ROOT, build_dir
from .summary import Summary

# COUPLINGS: the couplings world_manager --coupling accepts (README "What runs"), read from the C++ side
# (daemon_defaults) when first used:
#   impulse   force integration, the paper's method: the world applies the impulse the haptic side integrated since
#             its last step;
#   position  the paper's previous method: a penalty force from the finger sampled at the world step, held for the
#             whole world period;
#   local     impulse coupling plus the paper's §6.3: the haptic side moves the touched objects between world steps.


def __getattr__(name):  # PEP 562
    if name == "COUPLINGS":
        from . import daemon_defaults
        return daemon_defaults.COUPLINGS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


_module = None


def _impetus_module():
    """The impetus package from BUILD/python, or None when trials are to run as processes."""
    global _module
    if _module is None:
        _module = False
        choice = os.environ.get("IMPETUS_TRIALS", "module")
        if choice not in ("module", "processes"):
            raise RuntimeError(f"IMPETUS_TRIALS must be 'module' or 'processes', not '{choice}'")
        package = build_dir() / "python"
        if choice == "module" and (package / "impetus").is_dir():
            sys.path.insert(0, str(package))
            try:
                _module = importlib.import_module("impetus")
            except ImportError as error:
                raise RuntimeError(f"cannot import the impetus package built in {package}: {error}; rebuild it "
                                   f"(scripts/build.sh) or run the trials as processes (IMPETUS_TRIALS=processes)")
    return _module or None


def backend():
    """'module' or 'processes': how run_trial runs trials in this process."""
    return "module" if _impetus_module() else "processes"


def engine_choice():
    """The rigid-body engine the scripts' trials run on: $IMPETUS_ENGINE if set (world_manager --engine, e.g. bullet),
    else None (each scene's own). scripts/engines.py sets it to run the experiments on every engine."""
    return os.environ.get("IMPETUS_ENGINE") or None


def run_trial(out_dir, scene, trajectory, coupling, rate_hz=None, phase_ticks=None, substeps=None,
              stiffness_Npm=None, damping_Nspm=None, link_delay_s=None, passivity=False, link_loss=0.0,
              link_loss_burst=1.0):
    """Runs one lockstep trial of `scene` (a path) driven by `trajectory` (a spidar_sim --trajectory spec or file, or
    a dict {finger name: spec or file} for a device of several fingers)
    into out_dir and returns its Summary. rate_hz, phase_ticks and substeps are world_manager's --rate, --phase and
    --substeps, stiffness_Npm and damping_Nspm haptic_controller's --stiffness and --damping (None: the scene's
    values, phase 0). link_delay_s is the world link's one-way delay (s, both ways; None or 0: none): only the
    in-process link has a delay line, so a nonzero delay needs the impetus package, and so do link_loss and
    link_loss_burst (the fraction of frames and reports lost, and the mean run of losses). passivity is world_manager's
    --passivity (False: the paper's couplings as they are). The engine is engine_choice().
    Raises RuntimeError naming the trial if it failed."""
    out_dir.mkdir(parents=True, exist_ok=True)
    module = _impetus_module()
    engine = engine_choice()
    if module:
        try:
            trial = module.run_trial(scene, trajectory, coupling, passivity=passivity, rate_hz=rate_hz,
                                     phase_ticks=phase_ticks or 0,
                                     substeps=substeps, engine=engine, stiffness_Npm=stiffness_Npm,
                                     damping_Nspm=damping_Nspm, link_delay_s=link_delay_s or 0.0,
                                     link_loss=link_loss, link_loss_burst=link_loss_burst, out_dir=out_dir,
                                     logs=False)
        except (ValueError, RuntimeError, OSError) as error:
            raise RuntimeError(f"trial failed ({scene}, {trajectory}, {coupling} coupling, rate {rate_hz}, "
                               f"phase {phase_ticks}, link delay {link_delay_s or 0.0} s, loss {link_loss}): "
                               f"{error}") from None
        return Summary(trial.summary)
    if link_loss:
        raise RuntimeError(f"link loss ({link_loss}) needs the in-process link of the impetus package (build it, do "
                           f"not set IMPETUS_TRIALS=processes)")
    if link_delay_s:
        raise RuntimeError(f"a link delay ({link_delay_s} s) needs the in-process link of the impetus package; the "
                           f"daemons' links have no delay line (build the package, do not set "
                           f"IMPETUS_TRIALS=processes)")
    # A dict {finger name: trajectory} is a device of several fingers (run.sh --finger NAME=SPEC each).
    fingers = [["--finger", f"{name}={each}"] for name, each in trajectory.items()] if isinstance(trajectory, dict) \
        else [["--trajectory", str(trajectory)]]
    command = ["bash", str(ROOT / "scripts/run.sh"), "--scene", str(scene), *[arg for pair in fingers for arg in pair],
               "--coupling", coupling, "--passivity", "on" if passivity else "off", "--clock", "lockstep",
               "--out", str(out_dir), "--quiet"]
    for flag, value in (("--rate", rate_hz), ("--phase", phase_ticks), ("--substeps", substeps), ("--engine", engine)):
        if value is not None:
            command += [flag, str(value)]
    haptic_flags = []
    for flag, value in (("--stiffness", stiffness_Npm), ("--damping", damping_Nspm)):
        if value is not None:
            haptic_flags += [flag, str(value)]
    if haptic_flags:
        command += ["--"] + haptic_flags
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"trial failed ({' '.join(command)}):\n{result.stdout}{result.stderr}")
    return Summary.read(out_dir)
