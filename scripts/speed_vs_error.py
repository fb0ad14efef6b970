#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Speed against error: how far a multi-rate trial lands from the 1 kHz single-rate reference, and what it costs.

Grid (through the real processes in lockstep, see docs/architecture.md §3):
  scene {tap, spheres} x coupling (--couplings) x world rate (--rates, Hz) x --phases phases per rate,
  plus the world's ODE substeps per period as a second speed knob (--substeps at each of --substeps-rates Hz,
  --substeps-coupling coupling, on --substeps-scenes).
The reference of each scene is the cell "world at 1000 Hz, impulse coupling, the scene's default substeps": at the
haptic rate the world sees every tick, so there is nothing for a coupling to integrate or to miss.

Per cell (one row of OUT/speed_vs_error.csv and of the Markdown table OUT/speed_vs_error.md):
  error, from the position of every dynamic object at a common world time T (late in the trial, when the tap cube has
  stopped; the spheres never quite stop rolling, so they are compared at the same T rather than at their last step):
    rms_mm    sqrt(mean over phases and objects of |p - p_ref|^2)
    bias_mm   the part that every phase shares: RMS over objects of |mean over phases of (p - p_ref)|
    bias_along_travel_mm  signed: that mean error projected on each object's reference travel (start -> p_ref),
              averaged over objects; > 0 means the objects went further than in the reference
    spread_mm phase spread: per object the norm of the per-axis range (max - min) over phases, RMS over objects
              (for the one-cube tap scene this is the paper's Fig. 5 spread of the stop position)
    worst_mm  the worst single phase's RMS-over-objects error
  floor_penetration_mm  the deepest any object went into the floor at the end of a world step, worst phase
            (summary world.floor_penetration_max_m): ODE's penetration, which grows with the substep length
  cost, averaged over the cell's phases (from each trial's summary.json):
    world CPU per step (mean and p99, us) and per simulated second (ms), haptic CPU per tick (mean and p99, ns),
    wall time of the lockstep trial (s) and simulated seconds per wall second.
Plots (unless --no-plot): OUT/error_vs_cost.png (RMS error vs world CPU per simulated second, one line per coupling,
with the Pareto front) and OUT/spread_vs_rate.png (phase spread vs world rate, one line per coupling).
--docs copies the table and plots into docs/ (speed_vs_error_table.md, speed_vs_error_*.png).
--check asserts the physics-backed invariants listed in check().
--quick is a reduced grid (tap only, 4 rates, 4 phases) for the test suite.

  /usr/bin/python3 scripts/speed_vs_error.py                 # full sweep, out/speed_vs_error
  /usr/bin/python3 scripts/speed_vs_error.py --quick --check # the CTest variant
"""
import argparse
import csv
import json
import math
import os
import pathlib
import shutil
import subprocess
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT, build_dir  # noqa: E402
from impetus_py.progress import ProgressBar  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.trial import COUPLINGS, run_trial  # noqa: E402

FULL_RATES = [10, 20, 50, 100, 200, 500, 1000]
QUICK_RATES = [10, 20, 100, 1000]
# Spheres: the 24 balls drop and roll toward the centre for ~0.3 s; the finger comes down at x = -0.12 m to the balls'
# centre height (2 cm, surface_z - depth) away from the drop, settles, then drags 20 cm along +x through the middle
# of the pile at 0.2 m/s, so it strikes and pushes a few balls that are already rolling (2 at the reference).
# The default `tap` would start the finger inside the drop zone, where balls land on it, a different task.
SPHERES_TRAJECTORY = "slide:x=-0.12,y=0,surface_z=0.04,depth=0.02,distance=0.2,speed=0.2,settle=0.3,hold=0.5"
SCENES = {"tap": ("scenes/tap.json", "tap"), "spheres": ("scenes/spheres.json", SPHERES_TRAJECTORY)}
TOUCH_THRESHOLD_NS = 1e-6  # an object counts as touched if the world applied more impulse than this to it
CSV_FIELDS = ["experiment", "scene", "coupling", "rate_hz", "substeps", "phases", "failed", "touched_objects",
              "rms_mm", "bias_mm", "bias_along_travel_mm", "spread_mm", "worst_mm",
              "world_cpu_step_mean_us", "world_cpu_step_p99_us", "world_cpu_ms_per_sim_s",
              "haptic_cpu_tick_mean_ns", "haptic_cpu_tick_p99_ns", "wall_s", "sim_s", "sim_per_wall"]


def parse_list(text, kind):
    return [kind(item) for item in text.split(",") if item.strip()]


def positions_on_grid(world_csv, grid_ticks):
    """({tick: {object: [x, y, z]}}, {tick: fastest object's speed}) for the world log's rows whose world time is a
    whole multiple of grid_ticks haptic ticks. Every world rate of the sweep steps on that grid, so all trials can be
    compared at one common time; only those rows are parsed (a 1 kHz spheres log has ~3000 rows of 24 objects).
    The speed tells whether "the stop position" at that time is really a stop."""
    def on_grid(time_s):
        ticks = HAPTIC_RATE_HZ * time_s
        return abs(ticks - round(ticks)) <= 1e-3 and round(ticks) % grid_ticks == 0

    world = logs.read_log(world_csv, keep_time_s=on_grid)
    names = world.object_names()
    positions = {name: world.vectors(f"{name}.", "_m").tolist() for name in names}
    velocities = {name: world.vectors(f"{name}.v", "_mps").tolist() for name in names}
    out, speeds = {}, {}
    for row, time_s in enumerate(world["time_s"]):
        tick = round(HAPTIC_RATE_HZ * time_s)
        out[tick] = {name: positions[name][row] for name in names}
        speeds[tick] = max(norm(velocities[name][row]) for name in names)
    return out, speeds


def one_trial(out_dir, scene, trajectory, coupling, rate, substeps, phase, grid_ticks, keep_logs):
    """A trial, reduced to what the sweep needs. Errors are returned, not raised, so one bad trial is reported in its
    cell instead of stopping the sweep."""
    try:
        summary = run_trial(out_dir, ROOT / scene, trajectory, coupling, rate, phase, substeps)
        positions, speeds = positions_on_grid(out_dir / logs.WORLD, grid_ticks)
        if not positions:
            raise RuntimeError(f"no world log row on the {grid_ticks}-tick grid in {out_dir / logs.WORLD}")
    except Exception as error:  # noqa: BLE001 — any failure of the trial belongs in the report
        return {"error": str(error)}
    finally:
        if not keep_logs:  # the logs of a 1 kHz spheres trial are ~20 MB; the summaries are kept
            for log in logs.NAMES:
                (out_dir / log).unlink(missing_ok=True)
    return {"summary": summary, "positions": positions, "speeds": speeds}


def mean(values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    return sum(values) / len(values) if values else float("nan")


def norm(v):
    return math.sqrt(sum(c * c for c in v))


def cell_stats(trials, reference, start, eval_tick):
    """Error and cost of one cell from its successful trials (list of one_trial results)."""
    names = sorted(reference)
    errors = []  # per phase: {object: error vector}
    for trial in trials:
        at = trial["positions"][eval_tick]
        errors.append({n: [a - b for a, b in zip(at[n], reference[n])] for n in names})
    per_phase_rms = [math.sqrt(mean([norm(e[n]) ** 2 for n in names])) for e in errors]
    rms = math.sqrt(mean([r * r for r in per_phase_rms]))
    bias = {n: [mean([e[n][axis] for e in errors]) for axis in range(3)] for n in names}
    bias_rms = math.sqrt(mean([norm(bias[n]) ** 2 for n in names]))
    along = []
    for n in names:
        travel = [r - s for r, s in zip(reference[n], start[n])]
        if norm(travel) > 1e-3:  # an object that barely moved in the reference has no direction of travel
            along.append(sum(b * t for b, t in zip(bias[n], travel)) / norm(travel))
    spreads = []
    for n in names:
        ranges = [max(t["positions"][eval_tick][n][axis] for t in trials) -
                  min(t["positions"][eval_tick][n][axis] for t in trials) for axis in range(3)]
        spreads.append(norm(ranges))
    spread = math.sqrt(mean([s * s for s in spreads]))

    def summary_mean(section, key, scale=1.0):
        return scale * mean([getattr(t["summary"], section).get(key) for t in trials])

    penetrations = [t["summary"].world.get("floor_penetration_max_m") for t in trials]
    penetrations = [p for p in penetrations if p is not None]
    walls = [t["summary"].wall_time_s for t in trials]
    sims = [t["summary"].world.get("time_s") for t in trials]
    touched = [sum(1 for name in t["summary"].objects if norm(t["summary"].impulse_Ns(name)) > TOUCH_THRESHOLD_NS)
               for t in trials]
    return {
        "touched_objects": mean(touched),
        "rms_mm": 1e3 * rms, "bias_mm": 1e3 * bias_rms, "bias_along_travel_mm": 1e3 * mean(along),
        "spread_mm": 1e3 * spread, "worst_mm": 1e3 * max(per_phase_rms),
        "floor_penetration_mm": 1e3 * max(penetrations) if penetrations else float("nan"),
        "world_cpu_step_mean_us": summary_mean("world", "cpu_per_step_mean_us"),
        "world_cpu_step_p99_us": summary_mean("world", "cpu_per_step_p99_us"),
        "world_cpu_ms_per_sim_s": summary_mean("world", "cpu_per_simulated_s", 1e3),
        "haptic_cpu_tick_mean_ns": summary_mean("haptic", "cpu_per_tick_mean_ns"),
        "haptic_cpu_tick_p99_ns": summary_mean("haptic", "cpu_per_tick_p99_ns"),
        "wall_s": mean(walls), "sim_s": mean(sims),
        "sim_per_wall": mean([s / w for s, w in zip(sims, walls) if s is not None and w > 0]),
    }


def fmt(value, digits):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return f"{value:.{digits}f}"


def markdown(rows, meta):
    lines = []
    for scene in meta["scenes"]:
        info = meta["scenes"][scene]
        lines += [f"### {scene}: `{info['scene']}`, trajectory `{info['trajectory']}`", "",
                  f"Error at world time {info['eval_time_s']:.1f} s vs the reference (world 1000 Hz, impulse, "
                  f"{info['default_substeps']} substeps; its own phase spread {fmt(info['reference_spread_mm'], 3)} "
                  f"mm); {info['objects']} dynamic object(s), reference travel RMS {fmt(info['travel_mm'], 1)} mm; "
                  f"fastest object at that time: {fmt(info.get('reference_max_speed_at_eval_mps'), 3)} m/s in the "
                  f"reference, {fmt(info['max_speed_at_eval_mps'], 3)} m/s over all trials.",
                  "",
                  "| experiment | coupling | world Hz | substeps | phases | touched | RMS err (mm) | bias (mm) | "
                  "bias along travel (mm) | phase spread (mm) | worst (mm) | floor penetration (mm) | "
                  "world CPU/step mean, p99 (µs) | "
                  "world CPU per sim s (ms) | haptic CPU/tick mean, p99 (ns) | wall (s) | sim s / wall s |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            if r["scene"] != scene:
                continue
            phases = f"{r['phases']}" + (f" ({r['failed']} failed)" if r["failed"] else "")
            lines.append(
                f"| {r['experiment']} | {r['coupling']} | {r['rate_hz']:g} | {r['substeps']} | {phases} | "
                f"{fmt(r.get('touched_objects'), 1)} | {fmt(r.get('rms_mm'), 2)} | {fmt(r.get('bias_mm'), 2)} | "
                f"{fmt(r.get('bias_along_travel_mm'), 2)} | {fmt(r.get('spread_mm'), 2)} | "
                f"{fmt(r.get('worst_mm'), 2)} | {fmt(r.get('floor_penetration_mm'), 2)} | "
                f"{fmt(r.get('world_cpu_step_mean_us'), 0)}, "
                f"{fmt(r.get('world_cpu_step_p99_us'), 0)} | {fmt(r.get('world_cpu_ms_per_sim_s'), 2)} | "
                f"{fmt(r.get('haptic_cpu_tick_mean_ns'), 0)}, {fmt(r.get('haptic_cpu_tick_p99_ns'), 0)} | "
                f"{fmt(r.get('wall_s'), 2)} | {fmt(r.get('sim_per_wall'), 1)} |")
        lines.append("")
    lines.append(f"{meta['trials']} trials, {meta['jobs']} in parallel on {os.cpu_count()} CPUs, "
                 f"{meta['wall_s']:.0f} s in all (git {meta['revision']}; "
                 f"1-min load average {meta['load_before']:.1f} before, "
                 f"{meta['load_after']:.1f} after). Wall times and CPU costs were measured with {meta['jobs']} trials "
                 f"sharing the machine.")
    return "\n".join(lines) + "\n"


def plot(rows, meta, out):
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib
    matplotlib.use(os.environ["MPLBACKEND"])
    import matplotlib.pyplot as plt

    scenes = list(meta["scenes"])
    floor_mm = 1e-3  # log axes cannot show 0: the reference cell (error ~0 by definition) is drawn at this floor
    colours = {"position": "tab:red", "impulse": "tab:blue", "local": "tab:green"}
    # local is drawn dashed with hollow markers so that it stays visible where it coincides with impulse.
    styles = {"position": "o-", "impulse": "o-", "local": "o--"}
    paths = []

    fig, axes = plt.subplots(1, len(scenes), figsize=(5.6 * len(scenes), 4.2), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        points = []
        for coupling in meta["couplings"]:
            cells = sorted((r for r in rows if r["scene"] == scene and r["experiment"] == "rate"
                            and r["coupling"] == coupling and not math.isnan(r.get("rms_mm", math.nan))),
                           key=lambda r: r["world_cpu_ms_per_sim_s"])
            if not cells:
                continue
            xs = [r["world_cpu_ms_per_sim_s"] for r in cells]
            ys = [max(r["rms_mm"], floor_mm) for r in cells]
            points += list(zip(xs, ys))
            ax.plot(xs, ys, styles.get(coupling, "o-"), color=colours.get(coupling), label=f"{coupling} coupling",
                    lw=1.3, ms=4, mfc="none" if coupling == "local" else None)
            for r, x, y in zip(cells, xs, ys):
                ax.annotate(f"{r['rate_hz']:g}", (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7,
                            color=colours.get(coupling))
        knob = [r for r in rows if r["scene"] == scene and r["experiment"] == "substeps"
                and not math.isnan(r.get("rms_mm", math.nan))]
        for rate, colour in zip(sorted({r["rate_hz"] for r in knob}), ("tab:purple", "tab:brown", "tab:olive")):
            cells = sorted((r for r in knob if r["rate_hz"] == rate), key=lambda r: r["world_cpu_ms_per_sim_s"])
            xs = [r["world_cpu_ms_per_sim_s"] for r in cells]
            ys = [max(r["rms_mm"], floor_mm) for r in cells]
            points += list(zip(xs, ys))
            ax.plot(xs, ys, "s:", color=colour, lw=1, ms=4, label=f"{cells[0]['coupling']} {rate:g} Hz, substeps ×N")
            for r, x, y in zip(cells, xs, ys):
                ax.annotate(f"×{r['substeps']}", (x, y), textcoords="offset points", xytext=(3, -9), fontsize=7,
                            color=colour)
        # Pareto front: the cells no other cell beats on both cost and error.
        front, best = [], math.inf
        for x, y in sorted(points):
            if y < best:
                front.append((x, y))
                best = y
        if front:
            ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="0.5", lw=3, alpha=0.35,
                    label="Pareto front", zorder=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("world-manager CPU per simulated second (ms)")
        ax.set_ylabel(f"RMS error vs 1 kHz reference (mm, floor {floor_mm:g})")
        ax.set_title(f"{scene}: error vs cost (labels: world Hz)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    paths.append(out / "error_vs_cost.png")
    fig.savefig(paths[-1], dpi=80)
    plt.close(fig)

    fig, axes = plt.subplots(1, len(scenes), figsize=(5.6 * len(scenes), 4.0), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        for coupling in meta["couplings"]:
            cells = sorted((r for r in rows if r["scene"] == scene and r["experiment"] == "rate"
                            and r["coupling"] == coupling and not math.isnan(r.get("spread_mm", math.nan))),
                           key=lambda r: r["rate_hz"])
            if cells:
                ax.plot([r["rate_hz"] for r in cells], [max(r["spread_mm"], floor_mm) for r in cells],
                        styles.get(coupling, "o-"), color=colours.get(coupling), label=f"{coupling} coupling", lw=1.3,
                        ms=4, mfc="none" if coupling == "local" else None)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("world rate (Hz)")
        ax.set_ylabel(f"phase spread of the stop position (mm, floor {floor_mm:g})")
        ax.set_title(f"{scene}: spread over {meta['phases']} phases vs world rate", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.tight_layout()
    paths.append(out / "spread_vs_rate.png")
    fig.savefig(paths[-1], dpi=80)
    plt.close(fig)
    return paths


def check(rows, meta, reference_tolerance_mm):
    """The invariants --check asserts. Only what physics guarantees, not tuned outcomes:
    1. Every trial succeeded (the processes start, run in lockstep and exit cleanly at every rate and coupling).
    2. The reference cell agrees with itself: at 1000 Hz the world steps on every haptic tick, so it has one phase,
       and its error vs the reference (that same trial, rerun) is ~0: lockstep trials are bitwise reproducible.
       Checked on the tap scene.
    3. For every coupling, the RMS error at the highest rate is below the error at the lowest: as the world period
       approaches the haptic period, both the sampled finger position (position coupling) and the integrated
       impulse (impulse/local) reduce to the single-rate reference, whereas at 10 Hz the world reacts to a contact
       only 100 ms late (it cannot move the struck face within the period). With the tap cube this gap is
       centimetres, far beyond trial-to-trial noise (which lockstep makes zero: runs are bitwise reproducible).
    Returns the list of failures."""
    failures = []
    failed = sum(r["failed"] for r in rows)
    if failed:
        failures.append(f"{failed} trial(s) failed")
    for scene, info in meta["scenes"].items():
        if scene != "tap":
            continue
        ref = next((r for r in rows if r["scene"] == scene and r["experiment"] == "rate" and r["coupling"] ==
                    "impulse" and r["rate_hz"] == HAPTIC_RATE_HZ and r["substeps"] == info["default_substeps"]), None)
        if ref is None or not ref.get("rms_mm", math.nan) <= reference_tolerance_mm:
            failures.append(f"{scene}: 1 kHz impulse cell RMS error {ref and ref.get('rms_mm')} mm is not <= "
                            f"{reference_tolerance_mm} mm")
        for coupling in meta["couplings"]:
            cells = sorted((r for r in rows if r["scene"] == scene and r["experiment"] == "rate"
                            and r["coupling"] == coupling), key=lambda r: r["rate_hz"])
            if len(cells) < 2:
                continue
            low, high = cells[0], cells[-1]
            high_rms, low_rms = high.get("rms_mm", math.nan), low.get("rms_mm", math.nan)
            if not high_rms < low_rms:
                failures.append(f"{scene}/{coupling}: RMS error at {high['rate_hz']:g} Hz ({high_rms:.3f} mm) "
                                f"is not below the error at {low['rate_hz']:g} Hz ({low_rms:.3f} mm)")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n".join(__doc__.splitlines()[1:]))
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/speed_vs_error")
    parser.add_argument("--quick", action="store_true",
                        help="reduced grid: tap only, rates 10,20,100,1000, 4 phases, substeps 1,10 at 20 Hz")
    parser.add_argument("--rates", help=f"world rates, Hz (default {','.join(map(str, FULL_RATES))})")
    parser.add_argument("--couplings", default="position,impulse,local",
                        help=f"couplings to sweep, a subset of {','.join(COUPLINGS)}")
    parser.add_argument("--phases", type=int, help="phases per rate (default 10, --quick 4)")
    parser.add_argument("--scenes", help="subset of tap,spheres (default both, --quick tap)")
    parser.add_argument("--spheres-trajectory", default=SPHERES_TRAJECTORY)
    parser.add_argument("--substeps", help="substeps knob values (default 1,2,5,10,20,40; --quick 1,10; '' to skip)")
    parser.add_argument("--substeps-rates", help="world rates of the substeps knob, Hz (default 20,100; --quick 20)")
    parser.add_argument("--substeps-scenes", help="scenes of the substeps knob (default tap,spheres; --quick tap)")
    parser.add_argument("--substeps-coupling", default="impulse")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="trials run in parallel (nproc)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--keep-logs", action="store_true", help="keep each trial's CSV logs (large at 1 kHz)")
    parser.add_argument("--plot", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--docs", action="store_true", help="also copy the table and plots into docs/")
    parser.add_argument("--check", action="store_true", help="exit 1 unless the invariants in check() hold")
    parser.add_argument("--reference-tolerance-mm", type=float, default=0.1,
                        help="--check: largest RMS error of the 1 kHz impulse tap cell vs the reference, mm")
    args = parser.parse_args()

    rates = parse_list(args.rates, int) if args.rates else (QUICK_RATES if args.quick else FULL_RATES)
    phases_per_rate = args.phases or (4 if args.quick else 10)
    scenes = parse_list(args.scenes, str) if args.scenes else (["tap"] if args.quick else ["tap", "spheres"])
    substeps_knob = parse_list(args.substeps if args.substeps is not None else ("1,10" if args.quick else "1,2,5,10,20,40"),
                               int)
    substeps_rates = parse_list(args.substeps_rates or ("20" if args.quick else "20,100"), int)
    substeps_scenes = parse_list(args.substeps_scenes or ("tap" if args.quick else "tap,spheres"), str)
    for rate in rates + substeps_rates + [HAPTIC_RATE_HZ]:
        # Lockstep: world step i happens at haptic tick i*n + phase, so n = 1000/rate must be a whole number.
        if rate <= 0 or HAPTIC_RATE_HZ % rate:
            parser.error(f"--rates: {rate} Hz is not a whole number of {HAPTIC_RATE_HZ} Hz haptic ticks per step")
    for scene in scenes:
        if scene not in SCENES:
            parser.error(f"--scenes: unknown scene '{scene}' (known: {', '.join(SCENES)})")
    couplings = parse_list(args.couplings, str)
    for coupling in couplings:
        if coupling not in COUPLINGS:
            parser.error(f"--couplings: unknown coupling '{coupling}' (known: {', '.join(COUPLINGS)})")
    build = build_dir()
    # Run every trial on a private copy of the three binaries and the Python package: a rebuild of build/ during the
    # sweep (other work on the same tree) would otherwise mix versions or make trials fail while the linker rewrites
    # a binary.
    snapshot = args.out / "bin"
    for name in ("world_manager", "haptic_controller", "spidar_sim"):
        source = build / name / name
        if not source.is_file():
            parser.error(f"{source} is missing: build first (scripts/build.sh)")
        (snapshot / name).mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, snapshot / name / name)
    if (build / "python").is_dir():  # the impetus package, which runs the trials when it is built (impetus_py/trial.py)
        shutil.copytree(build / "python", snapshot / "python", dirs_exist_ok=True)
    os.environ["IMPETUS_BUILD_DIR"] = str(snapshot)  # read by run.sh in every trial
    scene_info = {"tap": SCENES["tap"], "spheres": (SCENES["spheres"][0], args.spheres_trajectory)}

    # Every rate steps on multiples of its period; their least common multiple (in ticks) is a grid all trials share.
    grid_ticks = 1
    for rate in rates + substeps_rates + [HAPTIC_RATE_HZ]:
        grid_ticks = math.lcm(grid_ticks, HAPTIC_RATE_HZ // rate)

    def phases_for(rate):
        # Spread over one world period; a period of fewer ticks than phases wanted (500 and 1000 Hz) has only that
        # many phases (a phase is an offset within the period).
        n = HAPTIC_RATE_HZ // rate
        return sorted({min(n - 1, round(k * n / phases_per_rate)) for k in range(phases_per_rate)})

    cells = {}  # (experiment, scene, coupling, rate, substeps) -> list of trial keys
    revision = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"], capture_output=True,
                              text=True).stdout.strip() or "unknown"
    meta = {"scenes": {}, "couplings": couplings, "phases": phases_per_rate, "jobs": args.jobs,
            "revision": revision, "load_before": os.getloadavg()[0]}
    for scene in scenes:
        scene_path, trajectory = scene_info[scene]
        scene_file = Scene(ROOT / scene_path)
        default_substeps = scene_file.substeps
        start = {obj["name"]: obj["position_m"] for obj in scene_file.dynamic_objects}
        meta["scenes"][scene] = {"scene": scene_path, "trajectory": trajectory, "default_substeps": default_substeps,
                                 "start": start, "objects": len(start)}
        wanted = [("rate", c, r, default_substeps) for c in couplings for r in rates]
        # The reference is always run, even if the grid leaves out 1000 Hz or impulse coupling.
        wanted.append(("reference", "impulse", HAPTIC_RATE_HZ, default_substeps))
        if scene in substeps_scenes:
            wanted += [("substeps", args.substeps_coupling, r, s) for r in substeps_rates for s in substeps_knob]
        for experiment, coupling, rate, substeps in wanted:
            cells[(experiment, scene, coupling, rate, substeps)] = [
                (scene, coupling, rate, substeps, p) for p in phases_for(rate)]

    # One trial per distinct (scene, coupling, rate, substeps, phase): cells that coincide (the reference and the
    # 1 kHz impulse cell; substeps = default and the grid cell) share their trials.
    trial_keys = sorted({k for keys in cells.values() for k in keys},
                        key=lambda k: -k[2] * k[3])  # costliest first, so the slow ones do not trail at the end
    tasks = []
    for key in trial_keys:
        scene, coupling, rate, substeps, phase = key
        out_dir = args.out / "trials" / scene / f"{coupling}-{rate}hz-sub{substeps}-phase{phase:03d}"
        tasks.append((key, one_trial, (out_dir, scene_info[scene][0], scene_info[scene][1], coupling, rate, substeps,
                                       phase, grid_ticks, args.keep_logs)))

    def weight(key):
        return 1.0 + key[2] * key[3] / 2000.0  # rough cost: fixed start-up + world steps x substeps

    started = time.monotonic()
    print(f"speed_vs_error: {len(tasks)} trials ({', '.join(scenes)}; couplings {', '.join(couplings)}; "
          f"rates {', '.join(map(str, rates))} Hz; {phases_per_rate} phases), {args.jobs} in parallel", file=sys.stderr)
    progress = ProgressBar(sum(weight(k) for k in trial_keys), len(trial_keys), "speed vs error", args.quiet)
    results = {}
    for key, result in run_parallel(tasks, args.jobs):
        results[key] = result
        progress.advance(weight(key), "" if "error" not in result else f"(failed: {key})")
    progress.close()
    wall = time.monotonic() - started
    meta["trials"] = len(tasks)
    meta["wall_s"] = wall
    meta["load_after"] = os.getloadavg()[0]  # other work on the machine inflates wall times (CPU times less so)

    failures_text = [f"{key}: {r['error']}" for key, r in results.items() if "error" in r]
    for text in failures_text[:5]:
        print(f"speed_vs_error: FAILED {text.strip()[:2000]}", file=sys.stderr)

    rows = []
    for scene, info in meta["scenes"].items():
        reference_trials = [results[k] for k in cells[("reference", scene, "impulse", HAPTIC_RATE_HZ,
                                                       info["default_substeps"])] if "error" not in results[k]]
        scene_trials = [r for k, r in results.items() if k[0] == scene and "error" not in r]
        if not reference_trials:
            print(f"speed_vs_error: {scene}: every reference trial failed; no errors can be computed", file=sys.stderr)
            info.update(eval_time_s=math.nan, reference_spread_mm=math.nan, travel_mm=math.nan,
                        max_speed_at_eval_mps=math.nan)
            reference = None
        else:
            # The latest grid time every trial of the scene reached (phases delay the world's start, so the world of
            # a late phase ends a little earlier).
            eval_tick = min(max(r["positions"]) for r in scene_trials)
            reference = {n: [mean([t["positions"][eval_tick][n][a] for t in reference_trials]) for a in range(3)]
                         for n in reference_trials[0]["positions"][eval_tick]}
            ref_stats = cell_stats(reference_trials, reference, info["start"], eval_tick)
            info.update(eval_time_s=eval_tick / HAPTIC_RATE_HZ, reference_spread_mm=ref_stats["spread_mm"],
                        max_speed_at_eval_mps=max(r["speeds"][eval_tick] for r in scene_trials),
                        reference_max_speed_at_eval_mps=max(r["speeds"][eval_tick] for r in reference_trials),
                        travel_mm=1e3 * math.sqrt(mean([norm([a - b for a, b in zip(reference[n], info["start"][n])])
                                                        ** 2 for n in reference])))
        for (experiment, cell_scene, coupling, rate, substeps), keys in cells.items():
            if cell_scene != scene or experiment == "reference":
                continue
            ok = [results[k] for k in keys if "error" not in results[k]]
            row = {"experiment": experiment, "scene": scene, "coupling": coupling, "rate_hz": rate,
                   "substeps": substeps, "phases": len(keys), "failed": len(keys) - len(ok)}
            if ok and reference is not None:
                row.update(cell_stats(ok, reference, info["start"], eval_tick))
            rows.append(row)
    for info in meta["scenes"].values():
        info.pop("start")

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "speed_vs_error.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    table = markdown(rows, meta)
    (args.out / "speed_vs_error.md").write_text(table)
    (args.out / "speed_vs_error.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1) + "\n")
    print(table)
    outputs = [args.out / "speed_vs_error.md"]
    if args.plot:
        outputs += plot(rows, meta, args.out)
        for path in outputs[1:]:
            print(f"plot: {path}")
    if args.docs:
        docs = ROOT / "docs"
        docs.mkdir(exist_ok=True)
        # docs/speed_vs_error.md is the hand-written report around these; the generated table goes beside it.
        copies = [docs / ("speed_vs_error_table.md" if path.suffix == ".md" else f"speed_vs_error_{path.name}")
                  for path in outputs]
        for path, copy in zip(outputs, copies):
            shutil.copy(path, copy)
        print(f"copied into docs/: {', '.join(c.name for c in copies)}")
    print(f"total wall time: {wall:.1f} s for {len(tasks)} trials ({args.jobs} in parallel); "
          f"CSV {args.out / 'speed_vs_error.csv'}")

    if args.check:
        failures = check(rows, meta, args.reference_tolerance_mm)
        if failures:
            print("CHECK FAILED: " + "; ".join(failures))
            sys.exit(1)
        print("check passed")
    elif failures_text:
        sys.exit(1)


if __name__ == "__main__":
    main()
