# SPDX-License-Identifier: Apache-2.0
"""Impetus from Python: run a haptic trial in this process and get its outcome.

    import impetus
    trial = impetus.run_trial(impetus.shipped_scene("tap"), "tap", coupling="local")
    print(trial)                                      # the outcome in one line per object
    trial.summary["objects"]["cube"]["position"]      # summary.json as a dict
    trial.logs["haptic"]["force_x"]                   # each log column as a numpy array

A trial is the world, haptic and device nodes of the three daemons, run in this process under the lockstep schedule:
bitwise the same outcome as `scripts/run.sh --clock lockstep` with the same arguments, and no process is started.
The call releases the GIL while the trial runs. Trials in one process take turns (the physics engine's state is
process-wide), so calls from several threads are safe but not parallel: a process pool runs several at once.
Ctrl-C (SIGINT in the main thread) ends a running trial between two ticks and raises KeyboardInterrupt.
"""
import json
import numbers
import os
import pathlib
import sys
import tempfile
import time
import warnings

try:
    from . import _impetus
except ImportError as _error:
    # The compiled half is built for one CPython minor version (its ABI tag) and needs numpy.
    _built_for = "@Python3_VERSION_MAJOR@.@Python3_VERSION_MINOR@"
    _running = f"{sys.version_info.major}.{sys.version_info.minor}"
    if _running != _built_for:
        raise ImportError(f"impetus: its compiled module was built for CPython {_built_for}, and this is "
                          f"{_running} ({sys.executable}): run it with /usr/bin/python3 (Debian's {_built_for}) or "
                          "rebuild Impetus for this Python") from _error
    raise ImportError(f"impetus: its compiled module cannot be loaded: {_error}") from _error

__version__ = "@PROJECT_VERSION@"
__all__ = ["COUPLINGS", "LOG_FILES", "Trial", "defaults", "read_log", "run_trial", "scene_dir", "shipped_scene"]



def defaults():
    """What the C++ side decides before any trial (world_manager --defaults): "couplings", "engines", "shapes",
    "haptic_rate_hz", and "scene", what a scene's left-out keys become. A new dict each call."""
    return json.loads(_impetus.defaults())


# The couplings (world_manager --coupling), from the C++ side:
#   impulse   force integration, the paper's method: the world applies the impulse the haptic side integrated since
#             its last step;
#   position  the paper's previous method: a penalty force from the finger sampled at the world step, held for the
#             whole world period;
#   local     impulse coupling plus the paper's §6.3: the haptic side moves the touched objects between world steps.
COUPLINGS = tuple(defaults()["couplings"])

# The logs a trial writes, by the key Trial.logs uses.
LOG_FILES = {"world": "world.csv", "haptic": "haptic.csv", "device": "device.csv"}

# Where the shipped scenes are: the source tree's scenes/ next to the build tree's package, or
# PREFIX/share/impetus/scenes for an installed one (both filled in by CMake).
_SCENE_DIRS = [pathlib.Path(p) for p in "@IMPETUS_PY_SCENE_DIRS@".split(";") if p]


def scene_dir():
    """The directory of the shipped scenes (scenes/*.json)."""
    here = pathlib.Path(__file__).resolve().parent
    for directory in _SCENE_DIRS:
        directory = directory if directory.is_absolute() else (here / directory).resolve()
        if directory.is_dir():
            return directory
    raise FileNotFoundError(f"impetus: no shipped scenes next to {here} (looked in {_SCENE_DIRS})")


def shipped_scene(name):
    """The path of the shipped scene `name` ("tap" for scenes/tap.json)."""
    path = scene_dir() / f"{name}.json"
    if not path.is_file():
        known = ", ".join(sorted(p.stem for p in scene_dir().glob("*.json")))
        raise FileNotFoundError(f"impetus: no shipped scene '{name}'; the shipped scenes are: {known}")
    return path


class Trial:
    """The outcome of one trial.

    summary  summary.json's document as a dict: "objects" (each dynamic object at the end: "position", "velocity",
             "impulse_Ns", ...), "world", "haptic", "device" and "config" (README, "Where the results are").
    logs     {"world", "haptic", "device"} -> {column name -> numpy float64 array, one value per row}: the world's
             state per step, the servo's finger, proxy and force per tick, the device's per tick. Column names carry
             their units (docs/architecture.md §4). Empty when run_trial was called with logs=False.
    out_dir  where the logs and summary.json were written, or None (a temporary directory, removed).
    """

    def __init__(self, summary, logs, out_dir):
        self.summary = summary
        self.logs = logs
        self.out_dir = out_dir

    def __repr__(self):
        config = self.summary["config"]
        parts = [f"{config['coupling']} coupling at {config['world_rate_hz']:g} Hz, phase {config['phase_ticks']}"]
        for name, state in self.summary["objects"].items():
            x, y, z = state["position"]
            jx, jy, jz = state["impulse_Ns"]
            parts.append(f"{name} at [{x:+.4f} {y:+.4f} {z:+.4f}] m after [{jx:+.4f} {jy:+.4f} {jz:+.4f}] N·s")
        haptic = self.summary["haptic"]
        parts.append(f"{haptic['ticks']} haptic ticks, max force {haptic['max_force_N']:.2f} N")
        return "Trial(" + "; ".join(parts) + ")"


def read_log(path):
    """A log file the nodes wrote (world.csv, haptic.csv, device.csv) as {column name -> numpy float64 array}."""
    header, table = _impetus.read_log(str(path))
    return {name: table[:, i] for i, name in enumerate(header)}


def _real(name, value, optional=False):
    """`value` as a finite float, or None if it is None and `optional`; ValueError naming `name` otherwise (the C++
    side then checks its range). NaN is refused: it would otherwise read as "not given"."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}: must be a number{' or None' if optional else ''}, not {value!r}")
    try:
        number = float(value)
    except OverflowError:
        number = float("inf")
    if number != number or number in (float("inf"), float("-inf")):
        shown = value if isinstance(value, float) or abs(value) < 10**20 else f"an integer of {len(str(value))} digits"
        raise ValueError(f"{name}: must be a finite number, not {shown}")
    return number


def run_trial(scene, trajectory, coupling="impulse", *, users=(), rate_hz=None, phase_ticks=0, substeps=None,
              stiffness_Npm=None, damping_Nspm=None, link_delay_s=0.0, duration_s=60.0, out_dir=None, logs=True):
    """Runs one trial and returns its Trial.

    scene          a scene file (str or path; shipped_scene("tap") for a shipped one)
    trajectory     the finger's path: a built-in ("tap", "tap:speed=0.2", "press", ...) or a trajectory CSV file, as
                   spidar_sim --trajectory takes; or, for a device of several fingers, a dict {name: path} in finger
                   order (spidar_sim --finger NAME=PATH), each finger an endpoint of the world (Trial.logs holds
                   the first finger's logs)
    coupling       one of COUPLINGS
    users          other users on the same world, each a haptic controller of its own following this trial's lockstep
                   ticks: a list whose items are a trajectory (one finger) or a dict {name: trajectory} (several).
                   User u's logs are userU.haptic.csv and userU.device.csv in out_dir, its summary
                   summary["followers"][u - 1] (its haptic_session tells its ledger apart in
                   summary["world"]["endpoints"])
    rate_hz        the world rate (world_manager --rate); None: the scene's
    phase_ticks    the world clock's lockstep phase in haptic ticks, within one world period (world_manager --phase)
    substeps       ODE steps per world period (world_manager --substeps); None: the scene's
    stiffness_Npm, damping_Nspm   the contact spring and damper (haptic_controller --stiffness, --damping); None:
                   the scene's
    link_delay_s   a one-way delay of the world link, the same both ways, 0 to 1 s, rounded to the nearest whole
                   haptic tick: frames reach the haptic side and reports reach the world that much later (latency
                   experiments; the daemons have no delay line). summary["link"] records it.
    duration_s     the longest trial; it ends earlier when the trajectory does (run.sh --duration, default 60)
    out_dir        a directory for world.csv, haptic.csv, device.csv and summary.json, created if missing; None: a
                   temporary one, removed before returning
    logs           whether to read the logs into Trial.logs (False saves the parsing for sweeps that need only the
                   summary; the files are still written to out_dir)

    Raises ValueError for an argument out of range (naming it, its value and the range) and RuntimeError for a file
    that cannot be used (naming the file and the field).
    """
    if not isinstance(scene, (str, os.PathLike)):
        raise TypeError(f"scene: must be a path (str or os.PathLike), not {type(scene).__name__}")
    if not isinstance(trajectory, (str, os.PathLike, dict)):
        raise TypeError(f"trajectory: must be a built-in spec, a path or a {{name: trajectory}} dict, not "
                        f"{type(trajectory).__name__}")
    if out_dir is not None and not isinstance(out_dir, (str, os.PathLike)):
        raise TypeError(f"out_dir: must be a path or None, not {type(out_dir).__name__}")
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling: must be one of {', '.join(COUPLINGS)}, not {coupling!r}")
    if isinstance(users, (str, dict)) or not all(isinstance(user, (str, dict, pathlib.Path)) for user in users):
        raise ValueError(f"users: must be a list of trajectories or {{name: trajectory}} dicts, not {users!r}")
    if isinstance(phase_ticks, bool) or not isinstance(phase_ticks, numbers.Integral) or not 0 <= phase_ticks < 2**64:
        raise ValueError(f"phase_ticks: must be a whole number of ticks, 0 or more, not {phase_ticks!r}")
    phase_ticks = int(phase_ticks)
    if substeps is not None:
        if isinstance(substeps, bool) or not isinstance(substeps, numbers.Integral) or substeps < 1:
            raise ValueError(f"substeps: must be a whole number, 1 or more, or None, not {substeps!r}")
        if substeps >= 2**31:
            raise ValueError(f"substeps: {substeps} is beyond the world's range (world_manager --help states it)")
        substeps = int(substeps)
        substeps = int(substeps)
    rate_hz = _real("rate_hz", rate_hz, optional=True)
    stiffness_Npm = _real("stiffness_Npm", stiffness_Npm, optional=True)
    damping_Nspm = _real("damping_Nspm", damping_Nspm, optional=True)
    link_delay_s = _real("link_delay_s", link_delay_s)
    duration_s = _real("duration_s", duration_s)
    scene = pathlib.Path(scene)
    if not scene.is_file():
        raise FileNotFoundError(f"scene: no such file '{scene}'")
    with tempfile.TemporaryDirectory(prefix="impetus-trial-") as scratch:
        directory = pathlib.Path(out_dir) if out_dir is not None else pathlib.Path(scratch)
        directory.mkdir(parents=True, exist_ok=True)
        start = time.monotonic()
        fingers = [f"{name}={path}" for name, path in trajectory.items()] if isinstance(trajectory, dict) else []
        followers = [[f"{name}={path}" for name, path in user.items()] if isinstance(user, dict)
                     else [f"finger={user}"] for user in users]
        summary = json.loads(_impetus.run_trial(str(scene), "" if fingers else str(trajectory), fingers, followers,
                                                coupling,
                                                phase_ticks, rate_hz, substeps,
                                                stiffness_Npm, damping_Nspm, float(link_delay_s), float(duration_s),
                                                str(directory) if (out_dir is not None or logs) else ""))
        # What run.sh adds to the daemons' config (impetus_py/summary.py): the trial's own arguments.
        trajectory_text = " ".join(fingers) if fingers else str(trajectory)
        summary["config"].update({"scene": str(scene), "trajectory": trajectory_text, "duration_s": float(duration_s),
                                  "wall_time_s": time.monotonic() - start})
        # What the daemons print as warnings, where a Python user looks: the world's start-up warnings (objects placed
        # inside each other, too light for the coupling) and a trajectory cut at duration_s.
        for warning in summary.get("world", {}).get("warnings", []):
            warnings.warn(f"impetus: {warning}", RuntimeWarning, stacklevel=2)
        if summary.get("haptic", {}).get("duration_reached"):
            warnings.warn(f"impetus: the trial stopped at duration_s={float(duration_s):g} s, before the trajectory "
                          "ended", RuntimeWarning, stacklevel=2)
        if out_dir is not None:
            (directory / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        table = {key: read_log(directory / name) for key, name in LOG_FILES.items()} if logs else {}
    return Trial(summary, table, directory if out_dir is not None else None)
