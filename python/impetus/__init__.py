# SPDX-License-Identifier: Apache-2.0
"""Impetus from Python: run a haptic trial in this process and get its outcome.

    import impetus
    trial = impetus.run_trial(impetus.shipped_scene("tap"), "tap", coupling="local")
    print(trial)                                      # the outcome in one line per object
    trial.summary["objects"]["cube"]["position"]      # summary.json as a dict
    trial.logs["haptic"]["force_x_N"]                   # each log column as a numpy array

Or drive the finger yourself, tick by tick (a controller, a policy, a model of a person):

    with impetus.Simulation(impetus.shipped_scene("tap"), start_m=[-0.025, 0, 0.025]) as sim:
        step = sim.step(50, targets=...)              # ticks x fingers x 3 targets; forces, proxy, ... come back
        sim.objects()["position_m"]                   # where the objects are

Or hold a tool (the scene's "tool" block) on the simulated 8-string grip SPIDAR, pose by pose:

    with impetus.ToolSimulation(impetus.shipped_scene("peg_in_hole"), start_m=[0, 0, 0.1]) as sim:
        step = sim.step(targets=...)                  # ticks x 3 positions, or ticks x 7 poses (x, y, z, w, qx, qy, qz)
        step.force_N, step.torque_Nm                  # the wrench on the grip

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
__all__ = ["COUPLINGS", "ENGINES", "LOG_FILES", "Simulation", "Step", "ToolSimulation", "ToolStep", "Trial",
           "defaults", "read_log", "run_trial", "sample_trajectory", "scene_dir", "shipped_scene"]



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

# The rigid-body engines a scene or a run can choose (world_manager --engine), the default first.
ENGINES = tuple(defaults()["engines"])

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


def _scene_argument(scene):
    """(path, JSON text) for `scene`: a file (text "") or a dict in the scene file's schema (path "scene", the name
    its messages use). TypeError or FileNotFoundError naming the argument otherwise."""
    if isinstance(scene, dict):
        def plain(value):  # numpy numbers and arrays as the JSON numbers and lists they stand for
            if hasattr(value, "tolist"):
                return value.tolist()
            raise TypeError(f"scene: {type(value).__name__} is not a JSON value")
        return "scene", json.dumps(scene, default=plain)
    if not isinstance(scene, (str, os.PathLike)):
        raise TypeError(f"scene: must be a path (str or os.PathLike) or a dict, not {type(scene).__name__}")
    path = pathlib.Path(scene)
    if not path.is_file():
        raise FileNotFoundError(f"scene: no such file '{path}'")
    return str(path), ""


def _options(coupling, passivity, rate_hz, phase_ticks, substeps, engine, stiffness_Npm, damping_Nspm, link_delay_s,
             link_loss, link_loss_burst):
    """The options every run takes, checked and converted (ValueError naming the argument)."""
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling: must be one of {', '.join(COUPLINGS)}, not {coupling!r}")
    if not isinstance(passivity, bool):
        raise ValueError(f"passivity: must be True or False, not {passivity!r}")
    if engine is not None and engine not in ENGINES:
        raise ValueError(f"engine: must be one of {', '.join(ENGINES)} or None, not {engine!r}")
    if isinstance(phase_ticks, bool) or not isinstance(phase_ticks, numbers.Integral) or not 0 <= phase_ticks < 2**64:
        raise ValueError(f"phase_ticks: must be a whole number of ticks, 0 or more, not {phase_ticks!r}")
    if substeps is not None:
        if isinstance(substeps, bool) or not isinstance(substeps, numbers.Integral) or substeps < 1:
            raise ValueError(f"substeps: must be a whole number, 1 or more, or None, not {substeps!r}")
        if substeps >= 2**31:
            raise ValueError(f"substeps: {substeps} is beyond the world's range (world_manager --help states it)")
        substeps = int(substeps)
    return (coupling, passivity, int(phase_ticks), _real("rate_hz", rate_hz, optional=True), substeps, engine,
            _real("stiffness_Npm", stiffness_Npm, optional=True), _real("damping_Nspm", damping_Nspm, optional=True),
            _real("link_delay_s", link_delay_s), _real("link_loss", link_loss),
            _real("link_loss_burst", link_loss_burst))


def _waypoints(name, value):
    """`value` as an N x 4 float64 array of waypoints (t_s, x_m, y_m, z_m); ValueError naming `name` otherwise."""
    import numpy as np
    table = np.asarray(value, dtype=np.float64)
    if table.ndim != 2 or table.shape[1] != 4 or table.shape[0] == 0:
        raise ValueError(f"{name}: an array trajectory must be N x 4 (t_s, x_m, y_m, z_m), N >= 1, not shape "
                         f"{table.shape}")
    return np.ascontiguousarray(table)


def _is_path_like(value):
    return isinstance(value, (str, os.PathLike))


def run_trial(scene, trajectory, coupling="impulse", *, passivity=False, users=(), rate_hz=None, phase_ticks=0,
              substeps=None, engine=None, stiffness_Npm=None, damping_Nspm=None, link_delay_s=0.0, link_loss=0.0,
              link_loss_burst=1.0, duration_s=60.0, out_dir=None, logs=True):
    """Runs one trial and returns its Trial.

    scene          a scene file (str or path; shipped_scene("tap") for a shipped one), or a dict in the scene file's
                   schema (docs/scene-format.md), checked with the same messages, which then name it "scene"
    trajectory     the finger's path: a built-in ("tap", "tap:speed=0.2", "press", ...) or a trajectory CSV file, as
                   spidar_sim --trajectory takes, or an N x 4 array of waypoints (t_s, x_m, y_m, z_m; straight lines
                   between them, as a CSV file's); or, for a device of several fingers, a dict {name: trajectory}
                   in finger order (spidar_sim --finger NAME=PATH), each finger an endpoint of the world (Trial.logs
                   holds the first finger's logs)
    coupling       one of COUPLINGS
    passivity      the passivity layer on the impulse port (world_manager --passivity): True, the energy the
                   couplings give a body never exceeds what the hand put in; False (default), the paper's couplings
                   exactly as the paper has them. summary["world"]["port"] keeps the books either way
    users          other users on the same world, each a haptic controller of its own following this trial's lockstep
                   ticks: a list whose items are a trajectory (one finger) or a dict {name: trajectory} (several).
                   User u's logs are userU.haptic.csv and userU.device.csv in out_dir, its summary
                   summary["followers"][u - 1] (its haptic_session tells its ledger apart in
                   summary["world"]["endpoints"])
    rate_hz        the world rate (world_manager --rate); None: the scene's
    phase_ticks    the world clock's lockstep phase in haptic ticks, within one world period (world_manager --phase)
    substeps       engine steps per world period (world_manager --substeps); None: the scene's
    engine         the rigid-body engine, one of ENGINES (world_manager --engine); None: the scene's
    stiffness_Npm, damping_Nspm   the contact spring and damper (haptic_controller --stiffness, --damping); None:
                   the scene's
    link_delay_s   a one-way delay of the world link, the same both ways, 0 to 1 s, rounded to the nearest whole
                   haptic tick: frames reach the haptic side and reports reach the world that much later (latency
                   experiments; the daemons have no delay line). summary["link"] records it.
    link_loss, link_loss_burst   the fraction of frames and of reports the link loses (0 to 0.5) and the mean run of
                   consecutive losses in packets (1 to 1000; 1: independent), from a seeded Gilbert-Elliott model, so
                   a lossy trial is repeatable. summary["link"] counts lost_frames and lost_reports.
    duration_s     the longest trial; it ends earlier when the trajectory does (run.sh --duration, default 60)
    out_dir        a directory for world.csv, haptic.csv, device.csv and summary.json, created if missing; None: a
                   temporary one, removed before returning
    logs           whether to read the logs into Trial.logs (False saves the parsing for sweeps that need only the
                   summary; the files are still written to out_dir)

    Raises ValueError for an argument out of range (naming it, its value and the range) and RuntimeError for a file
    that cannot be used (naming the file and the field).
    """
    scene_path, scene_text = _scene_argument(scene)
    named = trajectory if isinstance(trajectory, dict) else {"finger": trajectory}
    for name, path in named.items():
        if not isinstance(name, str) or not (_is_path_like(path) or hasattr(path, "__len__")):
            raise TypeError(f"trajectory: must be a built-in spec, a path, an N x 4 array or a {{name: trajectory}} "
                            f"dict, not {type(trajectory).__name__}")
    if out_dir is not None and not isinstance(out_dir, (str, os.PathLike)):
        raise TypeError(f"out_dir: must be a path or None, not {type(out_dir).__name__}")
    if isinstance(users, (str, dict)) or not all(isinstance(user, (str, dict, pathlib.Path)) for user in users):
        raise ValueError(f"users: must be a list of trajectories or {{name: trajectory}} dicts, not {users!r}")
    (coupling, passivity, phase_ticks, rate_hz, substeps, engine, stiffness_Npm, damping_Nspm, link_delay_s,
     link_loss, link_loss_burst) = _options(coupling, passivity, rate_hz, phase_ticks, substeps, engine, stiffness_Npm,
                                            damping_Nspm, link_delay_s, link_loss, link_loss_burst)
    duration_s = _real("duration_s", duration_s)
    # Specs and files go by name, as spidar_sim --finger NAME=PATH takes them; with an array among them every finger
    # goes as (name, spec, waypoints). One finger given as a spec or file keeps the single-trajectory form, so its
    # summary reads as run.sh's.
    arrays = any(not _is_path_like(path) for path in named.values())
    single = not isinstance(trajectory, dict) and not arrays
    fingers = [] if single or arrays else [f"{name}={path}" for name, path in named.items()]
    paths = [(name, str(path), None) if _is_path_like(path) else
             (name, "", _waypoints("trajectory" if not isinstance(trajectory, dict) else f"trajectory '{name}'", path))
             for name, path in named.items()] if arrays else []
    with tempfile.TemporaryDirectory(prefix="impetus-trial-") as scratch:
        directory = pathlib.Path(out_dir) if out_dir is not None else pathlib.Path(scratch)
        directory.mkdir(parents=True, exist_ok=True)
        start = time.monotonic()
        followers = [[f"{name}={path}" for name, path in user.items()] if isinstance(user, dict)
                     else [f"finger={user}"] for user in users]
        summary = json.loads(_impetus.run_trial(scene_path, scene_text, str(trajectory) if single else "", fingers,
                                                paths, followers, coupling, passivity, phase_ticks, rate_hz,
                                                substeps,
                                                engine, stiffness_Npm, damping_Nspm, float(link_delay_s),
                                                float(link_loss), float(link_loss_burst),
                                                float(duration_s),
                                                str(directory) if (out_dir is not None or logs) else ""))
        # What run.sh adds to the daemons' config (impetus_py/summary.py): the trial's own arguments.
        if single:
            trajectory_text = str(trajectory)
        else:
            trajectory_text = " ".join(f"{name}={path if _is_path_like(path) else '(array)'}"
                                       for name, path in named.items())
        summary["config"].update({"scene": scene_path if not scene_text else "(dict)", "trajectory": trajectory_text,
                                  "duration_s": float(duration_s), "wall_time_s": time.monotonic() - start})
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


def sample_trajectory(trajectory, times_s):
    """Where a trajectory (a built-in spec or a CSV file, as run_trial takes it) puts the target at each of `times_s`
    (seconds from its start): an N x 3 float64 array in metres. With Simulation.device_times_s it replays a
    trajectory in a closed loop."""
    import numpy as np
    if not _is_path_like(trajectory):
        raise TypeError(f"trajectory: must be a built-in spec or a path, not {type(trajectory).__name__}")
    times = np.ascontiguousarray(np.asarray(times_s, dtype=np.float64).reshape(-1))
    return _impetus.sample_trajectory(str(trajectory), times)


class _Ticks:
    """A call's records, one numpy array per quantity (the subclass's __slots__), one row per tick."""

    __slots__ = ()

    def __init__(self, arrays):
        for name in self.__slots__:
            setattr(self, name, arrays[name])

    def __len__(self):
        return len(self.time_s)


class Step(_Ticks):
    """What the servo did in the ticks of one Simulation.step call, as numpy arrays, one row per tick:

    time_s               ticks               the tick's time t·T (s)
    target_m             ticks x fingers x 3 the hand's target at the tick's end
    finger_m             ticks x fingers x 3 the fingertip as the device measured it
    finger_velocity_mps  ticks x fingers x 3 the fingertip's velocity
    proxy_m              ticks x fingers x 3 the god-object (where the finger would be if it could not go in)
    force_N              ticks x fingers x 3 the force on the finger
    object_impulse_Ns    ticks x fingers x 3 running total of the reaction the finger gave the objects
    active_planes        ticks x fingers     constraints holding the proxy: 0 free, 1 face, 2 edge, 3 corner
    """

    __slots__ = ("time_s", "target_m", "finger_m", "finger_velocity_mps", "proxy_m", "force_N", "object_impulse_Ns",
                 "active_planes")

    def __repr__(self):
        if not len(self):
            return "Step(0 ticks)"
        force = self.force_N[-1, 0]
        return (f"Step({len(self)} ticks to t = {self.time_s[-1]:.3f} s; finger 0 at {self.finger_m[-1, 0]} m, "
                f"force [{force[0]:+.3f} {force[1]:+.3f} {force[2]:+.3f}] N)")


class _Closable:
    """What both closed loops share about their lifetime: a `with` block closes them, and so does collection."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __del__(self):
        if getattr(self, "_loop", None) is not None:
            self.close()


class Simulation(_Closable):
    """A closed loop: the trial of run_trial advanced tick by tick by the caller, who moves each finger's target (or
    pushes with the hand) and reads back what the servo rendered and where the objects are.

        sim = impetus.Simulation(impetus.shipped_scene("tap"), start_m=[-0.025, 0, 0.025], coupling="local")
        for _ in range(2000):
            step = sim.step(1, targets=[[x, 0.0, 0.025]])   # the target at the end of the coming tick
            ...                                            # step.force_N[0, 0] is the force on the finger
        summary = sim.close()                              # summary.json's document, as Trial.summary

    The physics is run_trial's: the same nodes under the same lockstep schedule. Steering a finger to a trajectory's
    own points at the tick ends (sample_trajectory at device_times_s(n)) reproduces that trajectory's run_trial
    bitwise, tick for tick. The world steps every n ticks (n = tick rate / world rate), at ticks i·n + phase_ticks.

    scene        a scene file or a dict in its schema (as run_trial takes it)
    start_m      where the one finger starts, at rest (x, y, z in metres); or fingers=
    fingers      several fingers: {name: start point} in endpoint order
    coupling, passivity, rate_hz, phase_ticks, substeps, engine, stiffness_Npm, damping_Nspm, link_delay_s,
    link_loss, link_loss_burst
                 as run_trial
                 takes them
    out_dir      a directory for world.csv, haptic.csv, device.csv and (at close) summary.json; None: no logs

    A Simulation holds a physics world: use it in a `with` block or call close() (which it also does when
    collected). Simulations in one process step one at a time (the engine's state is process-wide); each keeps its
    own state, so several may be interleaved.
    """

    def __init__(self, scene, start_m=None, coupling="impulse", *, passivity=False, fingers=None, rate_hz=None,
                 phase_ticks=0, substeps=None, engine=None, stiffness_Npm=None, damping_Nspm=None, link_delay_s=0.0,
                 link_loss=0.0, link_loss_burst=1.0, out_dir=None):
        import numpy as np
        self._loop = None
        self.summary = None
        scene_path, scene_text = _scene_argument(scene)
        if (start_m is None) == (fingers is None):
            raise ValueError("start_m, fingers: give the start point of one finger (start_m) or {name: start point} "
                             "for several (fingers), one of them")
        named = {"finger": start_m} if fingers is None else fingers
        if not isinstance(named, dict) or not named:
            raise TypeError(f"fingers: must be a non-empty dict {{name: start point}}, not {type(fingers).__name__}")
        starts = []
        for name, point in named.items():
            label = "start_m" if fingers is None else f"fingers['{name}']"
            starts.append((str(name), self._point(label, point)))
        if out_dir is not None and not isinstance(out_dir, (str, os.PathLike)):
            raise TypeError(f"out_dir: must be a path or None, not {type(out_dir).__name__}")
        options = _options(coupling, passivity, rate_hz, phase_ticks, substeps, engine, stiffness_Npm,
                           damping_Nspm, link_delay_s, link_loss, link_loss_burst)
        self.out_dir = pathlib.Path(out_dir) if out_dir is not None else None
        if self.out_dir is not None:
            self.out_dir.mkdir(parents=True, exist_ok=True)
        self._scene_name = scene_path if not scene_text else "(dict)"
        self.finger_names = tuple(name for name, _ in starts)
        self._np = np
        self._loop = _impetus.ClosedLoop(scene_path, scene_text, starts, *options,
                                         str(self.out_dir) if self.out_dir is not None else "")
        self.object_names = tuple(self._loop.object_names)
        self.tick_period_s = self._loop.tick_period_s
        for warning in self._loop.warnings:
            warnings.warn(f"impetus: {warning}", RuntimeWarning, stacklevel=2)

    @staticmethod
    def _point(name, value):
        import numpy as np
        try:
            point = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: must be three numbers (x, y, z), not {value!r}") from None
        if point.shape != (3,) or not np.all(np.isfinite(point)):
            raise ValueError(f"{name}: must be three finite numbers (x, y, z), not {value!r}")
        return tuple(float(v) for v in point)

    def _open(self):
        if self._loop is None or self._loop.finished:
            raise RuntimeError("impetus.Simulation: closed; make a new one")
        return self._loop

    @property
    def ticks(self):
        """Ticks taken so far."""
        return self._loop.ticks if self._loop is not None else 0

    @property
    def time_s(self):
        """The time of the next tick, ticks · tick_period_s (s)."""
        return self.ticks * self.tick_period_s

    def device_times_s(self, ticks):
        """The device's clock at the end of each of the next `ticks` ticks: the running sum of tick_period_s, as the
        simulated device keeps it (sample a trajectory at these times to replay it exactly)."""
        np = self._np
        increments = np.full(int(ticks) + 1, self.tick_period_s)
        increments[0] = self._open().device_time_s
        return np.cumsum(increments)[1:]

    def step(self, ticks=None, targets=None):
        """Takes `ticks` ticks (default 1, or as many as `targets` has rows) and returns their Step.

        targets   None (the targets hold where they are), or the target of every finger at the end of each tick:
                  ticks x 3 for one finger, ticks x fingers x 3 for several (metres)
        Ctrl-C ends a long call between two ticks and raises KeyboardInterrupt; the ticks taken stay taken."""
        np = self._np
        loop = self._open()
        fingers = len(self.finger_names)
        if targets is not None:
            try:
                table = np.asarray(targets, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"targets: must be an array of points, not {type(targets).__name__}") from None
            if table.ndim == 2 and fingers == 1:
                table = table[:, np.newaxis, :]
            if table.ndim != 3 or table.shape[1:] != (fingers, 3):
                want = "ticks x 3" if fingers == 1 else f"ticks x {fingers} x 3"
                raise ValueError(f"targets: must be {want} (a point per finger per tick), not shape {table.shape}")
            if not np.all(np.isfinite(table)):
                raise ValueError("targets: must be finite")
            if ticks is not None and int(ticks) != table.shape[0]:
                raise ValueError(f"ticks: {ticks} but targets has {table.shape[0]} rows")
            ticks = table.shape[0]
            table = np.ascontiguousarray(table)
        else:
            table = None
            ticks = 1 if ticks is None else ticks
        if isinstance(ticks, bool) or not isinstance(ticks, numbers.Integral) or not 0 <= ticks < 2**32:
            raise ValueError(f"ticks: must be a whole number from 0 to 2**32 - 1, not {ticks!r}")
        return Step(loop.step(int(ticks), table))

    def set_target(self, target_m, finger=0):
        """Moves finger `finger`'s target (an index or a name) to `target_m` over the next tick; it holds there."""
        self._open().set_target(self._finger_index(finger), self._point("target_m", target_m))

    def set_hand_force(self, force_N, finger=0):
        """A force (N) the hand adds on the finger from the next tick on, on top of its pull toward the target, held
        until set again: a controller that pushes instead of aiming."""
        self._open().set_hand_force(self._finger_index(finger), self._point("force_N", force_N))

    def _finger_index(self, finger):
        if isinstance(finger, str):
            if finger not in self.finger_names:
                raise ValueError(f"finger: no finger '{finger}'; the fingers are {', '.join(self.finger_names)}")
            return self.finger_names.index(finger)
        if isinstance(finger, bool) or not isinstance(finger, numbers.Integral) or \
                not 0 <= finger < len(self.finger_names):
            raise ValueError(f"finger: must be a name or an index from 0 to {len(self.finger_names) - 1}, not "
                             f"{finger!r}")
        return int(finger)

    def objects(self):
        """Every scene object after the world's last step, in scene order (object_names): a dict of arrays
        "position_m", "velocity_mps", "angular_velocity_radps", "impulse_Ns" (the total the couplings applied),
        objects x 3, and "orientation_wxyz", objects x 4."""
        return self._open().objects()

    def close(self):
        """Ends the run (the logs are flushed and summary.json written to out_dir) and returns summary.json's
        document; later calls return the same."""
        if self.summary is not None or self._loop is None:
            return self.summary
        summary = json.loads(self._loop.finish())
        summary["config"].update({"scene": self._scene_name, "trajectory": "closed loop",
                                  "duration_s": self.ticks * self.tick_period_s})
        if self.out_dir is not None:
            (self.out_dir / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        self.summary = summary
        self._loop = None
        return summary

    def __repr__(self):
        state = "closed" if self._loop is None else f"{self.ticks} ticks"
        return f"Simulation({self._scene_name}, fingers {', '.join(self.finger_names)}, {state})"


class ToolStep(_Ticks):
    """What the tool servo and the grip device did in the ticks of one ToolSimulation.step call, one row per tick:

    time_s                ticks      the tick's time t·T (s)
    target_m, target_wxyz ticks x 3, ticks x 4   the hand's target pose at the tick's end
    grip_m, grip_wxyz     the grip's pose as the driver measured it from the eight string counts
    hand_m, hand_wxyz     where the simulated hand truly holds the grip at the tick's end
    proxy_m, proxy_wxyz   the tool's proxy (the pose the tool would have if it could not go in)
    force_N, torque_Nm    ticks x 3  the wrench on the grip (torque about its centre), as the servo commanded it
    strings_force_N, strings_torque_Nm   what the eight string tensions put on the grip
    active                ticks      contacts pushing the tool
    Orientations are unit quaternions w, x, y, z, grip -> world.
    """

    __slots__ = ("time_s", "target_m", "target_wxyz", "grip_m", "grip_wxyz", "hand_m", "hand_wxyz", "proxy_m",
                 "proxy_wxyz", "force_N", "torque_Nm", "strings_force_N", "strings_torque_Nm", "active")

    def __repr__(self):
        if not len(self):
            return "ToolStep(0 ticks)"
        force, torque = self.force_N[-1], self.torque_Nm[-1]
        return (f"ToolStep({len(self)} ticks to t = {self.time_s[-1]:.3f} s; grip at {self.grip_m[-1]} m, force "
                f"[{force[0]:+.3f} {force[1]:+.3f} {force[2]:+.3f}] N, torque "
                f"[{torque[0]:+.4f} {torque[1]:+.4f} {torque[2]:+.4f}] N·m)")


class ToolSimulation(_Closable):
    """A tool in the hand, in a closed loop: the scene's tool ("tool" block, docs/scene-format.md) held by a
    simulated hand on the simulated 8-string grip SPIDAR, rendered by the 6-DoF tool servo against the world, in
    lockstep (bitwise reproducible). The caller moves the hand's target pose; the hand follows it with its own
    impedance, so the tool stops at surfaces and the hand feels the force and torque.

        with impetus.ToolSimulation(impetus.shipped_scene("peg_in_hole"), start_m=[0, 0, 0.1]) as sim:
            step = sim.step(targets=np.linspace([0, 0, 0.1], [0, 0, 0.045], 1000))   # down the hole
            step.force_N[-1]                            # the hole's floor pushing back
            summary = sim.close()                       # counters, and per object the impulse rendered and applied

    scene        a scene file or a dict in its schema, with a "tool" block
    start_m      where the grip starts, at rest (x, y, z, metres); start_wxyz its orientation (default level)
    coupling     "local" (default) or "impulse"; position coupling samples one point and is refused
    rate_hz      the world's rate (default: the scene's); a 1 ms tick must divide its period
    out_dir      a directory for world.csv, haptic.csv (the grip's centre as the finger, the proxy's as the proxy)
                 and haptic.tool.csv (the grip's and the proxy's poses, force and torque), and at close summary.json:
                 `viewer --replay OUT_DIR` plays the run back, the tool drawn; None: no logs
    device       the 8-string grip SPIDAR: "grip" (the built-in frame) or "grip:FILE.json" (a device file in the
                 form of common/spidar/desktop_grip.json, docs/devices.md)

    The world steps every n ticks (n = 1000 / world rate), at ticks 0, n, 2n, ...
    """

    def __init__(self, scene, start_m, coupling="local", *, start_wxyz=(1.0, 0.0, 0.0, 0.0), rate_hz=None,
                 out_dir=None, device="grip"):
        import numpy as np
        self._np = np
        self._loop = None
        self.summary = None
        scene_path, scene_text = _scene_argument(scene)
        if coupling not in COUPLINGS:
            raise ValueError(f"coupling: must be one of {', '.join(COUPLINGS)}, not {coupling!r}")
        start = self._pose("start", Simulation._point("start_m", start_m), start_wxyz)
        if out_dir is not None and not isinstance(out_dir, (str, os.PathLike)):
            raise TypeError(f"out_dir: must be a path or None, not {type(out_dir).__name__}")
        self.out_dir = pathlib.Path(out_dir) if out_dir is not None else None
        if self.out_dir is not None:
            self.out_dir.mkdir(parents=True, exist_ok=True)
        if not isinstance(device, str):
            raise TypeError(f"device: must be 'grip' or 'grip:FILE.json', not {type(device).__name__}")
        self._scene_name = scene_path if not scene_text else "(dict)"
        self._loop = _impetus.ToolClosedLoop(scene_path, scene_text, coupling, _real("rate_hz", rate_hz, True), start,
                                             str(self.out_dir) if self.out_dir is not None else "", device)
        self.object_names = tuple(self._loop.object_names)
        self.tick_period_s = self._loop.tick_period_s

    def _pose(self, name, position, wxyz):
        np = self._np
        try:
            q = np.asarray(wxyz, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name}_wxyz: must be four numbers (w, x, y, z), not {wxyz!r}") from None
        if q.shape != (4,) or not np.all(np.isfinite(q)) or abs(np.linalg.norm(q) - 1.0) > 1e-6:
            raise ValueError(f"{name}_wxyz: must be a unit quaternion (w, x, y, z; norm 1 within 1e-6), not {wxyz!r}")
        return tuple(position) + tuple(float(v) for v in q)

    def _open(self):
        if self._loop is None or self._loop.finished:
            raise RuntimeError("impetus.ToolSimulation: closed; make a new one")
        return self._loop

    @property
    def ticks(self):
        """Ticks taken so far."""
        return self._loop.ticks if self._loop is not None else 0

    def step(self, ticks=None, targets=None):
        """Takes `ticks` ticks (default 1, or as many as `targets` has rows) and returns their ToolStep.

        targets   None (the target holds), or the target at the end of each tick: ticks x 3 positions (the
                  orientation held level) or ticks x 7 poses (x, y, z in metres, then a unit quaternion w, x, y, z)"""
        np = self._np
        loop = self._open()
        table = None
        if targets is not None:
            try:
                table = np.asarray(targets, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"targets: must be an array of poses, not {type(targets).__name__}") from None
            if table.ndim != 2 or table.shape[1] not in (3, 7):
                raise ValueError(f"targets: must be ticks x 3 or ticks x 7, not shape {table.shape}")
            if table.shape[1] == 3:
                table = np.hstack([table, np.tile([1.0, 0.0, 0.0, 0.0], (table.shape[0], 1))])
            if not np.all(np.isfinite(table)):
                raise ValueError("targets: must be finite")
            norms = np.linalg.norm(table[:, 3:], axis=1)
            if np.any(np.abs(norms - 1.0) > 1e-6):
                raise ValueError(f"targets: row {int(np.argmax(np.abs(norms - 1.0)))}'s quaternion is not unit")
            if ticks is not None and int(ticks) != table.shape[0]:
                raise ValueError(f"ticks: {ticks} but targets has {table.shape[0]} rows")
            ticks = table.shape[0]
            table = np.ascontiguousarray(table)
        else:
            ticks = 1 if ticks is None else ticks
        if isinstance(ticks, bool) or not isinstance(ticks, numbers.Integral) or not 0 <= ticks < 2**32:
            raise ValueError(f"ticks: must be a whole number from 0 to 2**32 - 1, not {ticks!r}")
        return ToolStep(loop.step(int(ticks), table))

    def set_target(self, target_m, target_wxyz=(1.0, 0.0, 0.0, 0.0)):
        """Moves the hand's target to the pose over the next tick; it holds there."""
        self._open().set_target(self._pose("target", Simulation._point("target_m", target_m), target_wxyz))

    def objects(self):
        """Every scene object after the world's last step, in scene order (object_names): a dict of arrays
        "position_m", "velocity_mps", "angular_velocity_radps", "impulse_Ns", "angular_impulse_Nms" (what the
        couplings applied), objects x 3, and "orientation_wxyz", objects x 4."""
        return self._open().objects()

    def close(self):
        """Ends the run (two more world steps apply the last ticks' impulse) and returns the summary: ticks, the
        tool's and the device's counters, per object touched the impulse rendered and applied ("ledger"), and the
        world's and haptic node's halves of a trial's summary.json; written to out_dir as summary.json if given."""
        if self.summary is not None or self._loop is None:
            return self.summary
        self.summary = json.loads(self._loop.finish())
        self.summary["scene"] = self._scene_name
        if self.out_dir is not None:
            (self.out_dir / "summary.json").write_text(json.dumps(self.summary, indent=2) + "\n")
        self._loop = None
        return self.summary

    def __repr__(self):
        state = "closed" if self._loop is None else f"{self.ticks} ticks"
        return f"ToolSimulation({self._scene_name}, {state})"
