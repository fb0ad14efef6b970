#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Every engine side by side (docs/engines.md): the paper's claim (§5) that force integration applies to any model of
dynamics, measured on each rigid-body engine Impetus has, with the same scenes.

  phase      the paper's tap (scenes/tap.json) at --phases world-clock phases under each coupling: the cube's stop
             position, its spread over the phases (Fig. 5's sampling coherency problem) and its bias against that
             engine's own single-rate reference (the world at the haptic rate, 1 kHz, where the phase cannot matter),
             as docs/phase.md measures it on ODE
  tap task   the paper's tap task (Figs. 7/8, scripts/tap_task.py): a simulated subject learns to tap the cube to a
             mark over 30 trials at random phases; the mean absolute deviation of its last 20 taps per coupling
  speed      speed against error (scripts/speed_vs_error.py's rate experiment: the tap and the spheres at 10 to
             1000 Hz worlds, each engine against its own 1 kHz reference): RMS error, phase spread and world CPU per
             simulated second per scene, coupling and rate (--quick: its quick grid)
  hard       the stability suite (scripts/hard_cases.py, tests/hard_cases/) under impulse and local coupling: each
             case's verdict and key metric per engine

Writes OUT/engines.json and the tables to --doc (default docs/engines.md), and prints them.

usage: engines.py [--phases N] [--jobs N] [--out DIR] [--doc FILE] [--quick] [--quiet]
"""
import argparse
import csv
import json
import random
import subprocess
import types
import os
import pathlib
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import hard_cases  # noqa: E402
import tap_task  # noqa: E402
from impetus_py import daemon_defaults  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

TAP_SCENE = ROOT / "scenes/tap.json"
COUPLINGS = ("impulse", "position", "local")
HARD_CASE_COUPLINGS = ("impulse", "local")
START_X_M = 0.03  # the cube's centre at rest in scenes/tap.json
TAP_TASK_TRIALS = 30       # scripts/tap_task.py's defaults: 30 trials, aiming at 15 cm, the last 20 scored
TAP_TASK_TARGET_M = 0.15
TAP_TASK_SCORED = 20


def on_engine(engine, function, *args):
    """Runs function(*args) with the scripts' trials on `engine` (a worker process's own environment)."""
    os.environ["IMPETUS_ENGINE"] = engine
    started = time.monotonic()
    return function(*args), time.monotonic() - started


def tap(out_dir, coupling, phase_ticks, rate_hz):
    summary = run_trial(out_dir, TAP_SCENE, "tap", coupling, rate_hz=rate_hz, phase_ticks=phase_ticks)
    return summary.objects["cube"]["position"][0]


def tap_subject(out_dir, coupling, phases):
    """One simulated subject of the tap task (tap_task.subject) with its defaults: [(trial, speed, phase, travel)]."""
    args = types.SimpleNamespace(scene=str(TAP_SCENE), out=out_dir, rate=20.0, target=TAP_TASK_TARGET_M)
    return tap_task.subject(coupling, args, phases)


def speed_sweep(out_dir, quick):
    """speed_vs_error.py's rate experiment on this process's engine (IMPETUS_ENGINE): its full grid (both scenes, every
    rate, 10 phases), or with `quick` its quick one; its CSV rows of the rate experiment."""
    grid = ["--quick"] if quick else ["--substeps", ""]
    subprocess.run([sys.executable, str(ROOT / "scripts/speed_vs_error.py"), *grid, "--no-plot", "--quiet",
                    "--jobs", "1", "--out", str(out_dir)], check=True, capture_output=True, text=True)
    with open(out_dir / "speed_vs_error.csv", newline="") as f:
        return [row for row in csv.DictReader(f) if row["experiment"] == "rate"]


def hard_case(case, out_dir, coupling):
    cid, _, scene, trajectory, rate, _ = case
    error = hard_cases.run_case_trial(out_dir, hard_cases.CASES_DIR / scene, hard_cases.resolve_trajectory(trajectory),
                                      coupling, rate)
    if error is not None:
        return {"ok": False, "metric": "trial did not run", "problems": [str(error)]}
    row = hard_cases.evaluate(case, out_dir, coupling)
    return {"ok": row["ok"], "metric": row["metric"], "problems": row["problems"]}


# What the tables show that is the engines' and not the method's, each traced (kept with the script so the page and
# its tables are regenerated together).
NOTES = [
    "## Where the engines differ, and why", "",
    "- **Bullet's own contact and friction were changed where they broke physics the scenes rely on** "
    "(`world_manager/engine/bullet_engine.cpp`): the floor is a box, not Bullet's plane (the plane meets a box at one "
    "point per substep, so a sliding box rocked corner to corner and its contacts carried about a fifth of its "
    "weight); friction acts in two fixed tangential directions per contact point (Bullet's default, one along the "
    "sliding velocity, let a cube pushed across it creep, and directions turning with the velocity flipped where a "
    "slide reversed, which made the cube of hard case 12a spin on its ramp, tip and slide under the finger); forces "
    "and torques enter as the velocity change of the substep (Bullet 3.24's friction rows leave out "
    "an external torque's spin, so a 5 cm cube on the floor given a 6 mN·m torque slid at 0.8 mm/s for ever, which "
    "the haptic side's sticking proxy then amplified into hard case 7 sliding 42 mm). Each is tested on every "
    "engine in `tests/world_manager/test_engines.cpp` (a sliding cube stops at v²/2μg within 2 %; a resting cube's "
    "contacts carry its weight).",
    "- **Case 8 (a 1000:1 stack) holds on each engine's direct solver.** The scene asks every engine for one "
    "(`\"ode\": {\"solver\": \"direct\"}, \"bullet\": {\"solver\": \"direct\"}`); each engine reads its own "
    "block. On their iterative solvers (QuickStep, sequential impulses) both drop it: a light box under a heavy one "
    "is a system an iterative solver converges on too slowly (ODE QuickStep 894 mm, Bullet's sequential impulses "
    "373 mm). Bullet's direct solver is its MLCP solver with Dantzig pivoting; as shipped it leaves out each contact's "
    "own softness, so its rows were rigid, a face resting on four points a singular system, and it fell back to "
    "sequential impulses in 547 substeps of the trial (2638 mm). Given ODE's world CFM, 1/(k·h + c), on every row, it "
    "falls back once (the first substep of contact) and holds the stack (the table above). "
    "`tests/world_manager/test_engines.cpp` checks both solvers on both engines.",
    "- Impulse coupling fails cases 10 and 14 on both engines, as docs/hard_cases.md reports for ODE.",
    "- **Speed against error.** The tap (one cube sliding on the floor) agrees between the engines to a few hundredths "
    "of a millimetre at every rate and coupling. The spheres (balls driven into each other) agree only in size: "
    "collisions between round bodies amplify the first difference in rounding or contact order, so each engine's "
    "run at a rate ends in a different arrangement and the columns differ by up to a factor of two (both far above "
    "what local coupling leaves on the tap). Bullet's world costs 2 to 3 times ODE's on the spheres (its collision "
    "pipeline per substep, sleeping aside) and about the same on the tap.",
    "- **Ghost force** (`build/tests/bench_ghost_force`, streams of objects past the finger, each coupling at 20 and "
    "10 Hz): the same on both engines to the tick, ghost at most 0.45 % of the contact ticks, except one row on "
    "Bullet, 16 objects, local coupling, 10 Hz: 6 ticks of pop-through (0.50–0.59 mm), traced: the finger, held at the "
    "servo's 10 N clamp for seconds, pushed one 100 kg stream box into another inside a world period (ticks "
    "6600–6699), which the haptic side's local model cannot know of until the next frame; the box's predicted pose "
    "drifted 1.6 mm from the world's by the period's end. Not an engine difference: the two engines' runs part "
    "chaotically earlier (each integrates a free rotation its own way: a box spun at 2.7 rad/s off its principal axes differs by 8·10⁻³ rad/s between them after one 10 Hz period), and on ODE "
    "that collision does not happen. Of 40 stream seeds at this row, that is the only pop-through but one (seed 15, "
    "on both engines: the finger starts inside an object, which the stream's placement does not avoid).",
    "- **Cost.** `build/tests/bench_world` prints the world step per body on both (2 cores, measured 2026-11-27): "
    "ODE 13–15 µs per sphere per 20 Hz step (20 to 2000 spheres on the floor), Bullet 30–69 µs, growing with the "
    "count. With sleeping (N resting spheres, 10 rolling, one pressed; `bench_world --sleeping`), ODE's step stays "
    "at 0.15–0.20 ms from 10³ to 10⁵ resting spheres; Bullet's grows with them, 2.3 ms, 44 ms and 1.3 s: its island "
    "pass walks every body and every broadphase pair at every substep, asleep or not (62 % of the step in a profile "
    "of 5000 sleeping spheres: building the islands and joining them), and its 2 cm broadphase margin gives each "
    "sphere of this grid (1 cm apart) about five pairs. Bullet's own island manager also joined bodies whose "
    "bounding boxes overlap, so one pressed sphere kept the whole field awake (1010 moving); islands here are joined "
    "by contact points, as ODE's are by contact joints (11 moving on both engines).",
    "", "Regenerate: `/usr/bin/python3 scripts/engines.py` (the world step cost per body on both engines: "
    "`bash scripts/bench.sh`, section 2).", ""]


def phase_rows(results, engines, phases):
    lines = ["| engine | coupling | stop x mean (m) | phase spread (mm) | bias vs the engine's 1 kHz reference "
             "(% of travel) | trials' wall time (s) |", "|---|---|---|---|---|---|"]
    for engine in engines:
        reference = results[("reference", engine)][0]
        for coupling in COUPLINGS:
            stops = [results[("tap", engine, coupling, p)][0] for p in phases]
            wall = sum(results[("tap", engine, coupling, p)][1] for p in phases)
            mean = sum(stops) / len(stops)
            bias = 100.0 * (mean - reference) / (reference - START_X_M)
            lines.append(f"| {engine} | {coupling} | {mean:.4f} | {1000 * (max(stops) - min(stops)):.2f} | "
                         f"{bias:+.2f} | {wall:.2f} |")
        lines.append(f"| {engine} | reference (1 kHz world) | {reference:.4f} | - | - | "
                     f"{results[('reference', engine)][1]:.2f} |")
    return lines


def tap_task_rows(results, engines):
    lines = [f"| engine | coupling | mean abs deviation, last {TAP_TASK_SCORED} taps (mm) | mean travel (m) |",
             "|---|---|---|---|"]
    for engine in engines:
        for coupling in COUPLINGS:
            tail = [travel for _, _, _, travel in results[("task", engine, coupling)][0][-TAP_TASK_SCORED:]]
            deviation_mm = 1000 * sum(abs(t - TAP_TASK_TARGET_M) for t in tail) / len(tail)
            lines.append(f"| {engine} | {coupling} | {deviation_mm:.1f} | {sum(tail) / len(tail):.3f} |")
    return lines


def speed_rows(results, engines):
    rows = {engine: {(r["scene"], r["coupling"], float(r["rate_hz"])): r for r in results[("speed", engine)][0]}
            for engine in engines}
    keys = sorted(rows[engines[0]], key=lambda k: (k[0], COUPLINGS.index(k[1]), k[2]))
    lines = ["| scene | coupling | world Hz | " + " | ".join(f"{e}: RMS error (mm)" for e in engines) + " | " +
             " | ".join(f"{e}: phase spread (mm)" for e in engines) + " | " +
             " | ".join(f"{e}: world CPU per simulated s (ms)" for e in engines) + " |",
             "|---|---|---|" + "---|" * (3 * len(engines))]
    for key in keys:
        errors = " | ".join(f"{float(rows[e][key]['rms_mm']):.2f}" for e in engines)
        spreads = " | ".join(f"{float(rows[e][key]['spread_mm']):.2f}" for e in engines)
        costs = " | ".join(f"{float(rows[e][key]['world_cpu_ms_per_sim_s']):.2f}" for e in engines)
        lines.append(f"| {key[0]} | {key[1]} | {key[2]:g} | {errors} | {spreads} | {costs} |")
    return lines


def hard_rows(results, engines, cases):
    header = "| case | " + " | ".join(f"{engine}, {coupling}" for engine in engines for coupling in HARD_CASE_COUPLINGS)
    lines = [header + " |", "|---|" + "---|" * (len(engines) * len(HARD_CASE_COUPLINGS))]
    for case in cases:
        cells = []
        for engine in engines:
            for coupling in HARD_CASE_COUPLINGS:
                row = results[("hard", engine, coupling, case[0])][0]
                cells.append(("pass" if row["ok"] else "**FAIL**") + ": " + row["metric"].replace("|", "/"))
        lines.append(f"| {case[0]}. {case[1]} | " + " | ".join(cells) + " |")
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phases", type=int, default=10, help="world-clock phases per coupling, spread evenly "
                        "over the world period (default 10)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/engines")
    parser.add_argument("--doc", type=pathlib.Path, default=ROOT / "docs/engines.md")
    parser.add_argument("--quick", action="store_true", help="3 phases and the first 5 hard cases (a smoke run)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args()
    engines = daemon_defaults.ENGINES
    period_ticks = round(daemon_defaults.HAPTIC_RATE_HZ / 20.0)  # scenes/tap.json runs its world at 20 Hz
    count = 3 if args.quick else args.phases
    if not 1 <= count <= period_ticks:
        parser.error(f"--phases: 1 to {period_ticks}, not {count}")
    phases = sorted({round(k * period_ticks / count) for k in range(count)})
    cases = hard_cases.CASES[:5] if args.quick else hard_cases.CASES
    # The tap task's random phases, the same for every engine and coupling (tap_task.py's seed 1).
    rng = random.Random(1)
    task_phases = [rng.randrange(period_ticks) for _ in range(5 if args.quick else TAP_TASK_TRIALS)]

    tasks = []
    for engine in engines:
        tasks.append((("reference", engine), on_engine,
                      (engine, tap, args.out / engine / "reference", "impulse", 0, daemon_defaults.HAPTIC_RATE_HZ)))
        for coupling in COUPLINGS:
            for p in phases:
                tasks.append((("tap", engine, coupling, p), on_engine,
                              (engine, tap, args.out / engine / f"tap_{coupling}_{p}", coupling, p, None)))
        tasks.append((("speed", engine), on_engine,
                      (engine, speed_sweep, args.out / engine / "speed_vs_error", args.quick)))
        for coupling in COUPLINGS:
            tasks.append((("task", engine, coupling), on_engine,
                          (engine, tap_subject, args.out / engine / f"task_{coupling}", coupling, task_phases)))
        for coupling in HARD_CASE_COUPLINGS:
            for case in cases:
                tasks.append((("hard", engine, coupling, case[0]), on_engine,
                              (engine, hard_case, case, args.out / engine / f"case{case[0]}_{coupling}", coupling)))
    results = dict(track(run_parallel(tasks, args.jobs), [key for key, _, _ in tasks], "engines", args.quiet))

    command = "/usr/bin/python3 scripts/engines.py" + ("" if count == 10 else f" --phases {count}")
    text = [f"# Engines side by side: {', '.join(engines)}", "",
            f"Generated by `{command}` (about a minute and a half on 2 cores). "
            "Every trial is a lockstep run, bitwise repeatable on each engine. What differs between the engines and "
            "why: `world_manager/engine/bullet_engine.h`.", "",
            f"## The tap over {len(phases)} world-clock phases (paper Fig. 5, docs/phase.md)", "",
            *phase_rows(results, engines, phases), "",
            f"## The tap task (paper Figs. 7/8, docs/tap_task.md): a simulated subject aiming at "
            f"{100 * TAP_TASK_TARGET_M:.0f} cm", "",
            *tap_task_rows(results, engines), "",
            "## Speed against error (docs/speed_vs_error.md's rate experiment, " +
            ("its quick grid: the tap, 4 phases per rate" if args.quick else
             "its full grid: the tap and the spheres, 10 phases per rate (fewer where a period has fewer ticks)") +
            "), each engine against its own 1 kHz reference", "",
            *speed_rows(results, engines), "",
            "## The stability suite (docs/hard_cases.md), each case's verdict and key metric", "",
            *hard_rows(results, engines, cases), "", *NOTES]
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "engines.json").write_text(json.dumps({" ".join(map(str, k)): v for k, v in results.items()},
                                                      indent=1) + "\n")
    args.doc.write_text("\n".join(text))
    print("\n".join(text))
    print(f"engines: written to {args.doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
