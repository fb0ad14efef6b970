#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Deformation from integrated force (paper §6.4): the experiment the paper left to be carried out.

A finger presses, taps and strokes a clay slab (scenes/clay.json) in lockstep, at PHASES phases of the world clock
spread over one world period, at each world rate under test (default 20 and 10 Hz), under the two rules of
docs/deformation.md: `impulse` (the surface yields from the push the haptic side integrated, where it was given) and
`penetration` (the previous method: the surface follows the finger's penetration sampled at each world step). Each
rule also runs once with the world at the haptic rate (1 kHz), its reference. Reports per case, rule and rate the dent
depth and volume (and for the stroke the groove's depth along its middle): mean, spread over the phases (max − min)
and bias against the reference, and checks the law itself (dent volume × flow resistance = push above yield).

With an elastic slab (--scene scenes/gel.json: "law": "elastic") the surface springs back, so the measures are the
deepest it went and the work the pushes did on it, and the law's check is its energy books (work + the integrator's
share = dissipated + held, world_manager/deform/elastic_membrane.h).

Writes OUT/deformation.md, OUT/deformation.json and OUT/deformation.png (dent against time for every phase, the two
rules side by side), and prints the table. With --check it exits 1 unless the law holds to 1e-9 in every trial and,
for every case of --check-cases at every rate, the impulse rule's spread is at most --max-spread of its dent and at
most --max-ratio of the penetration rule's, and its bias at most --max-bias (docs/deformation.md).
"""
import argparse
import json
import os
import pathlib
import statistics
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

RULES = ("impulse", "penetration")


def trajectories(surface_z, x0, y0):
    """The three finger paths as waypoint lists (t, x, y, z): straight lines between them (docs/trajectory-format.md).
    Each ends with the finger lifted and still, so every push has reached the world before the trial ends."""
    above = surface_z + 0.02  # 2 cm above the clay: out of reach of nothing, clear of the dent
    press_z = surface_z - 0.006  # the target 6 mm into the undented surface: ~2.5 N against the hand's spring at first

    def path(points):
        t, out = 0.0, []
        for duration, x, y, z in points:
            t += duration
            out.append((t, x, y, z))
        return out

    down_s = 0.02 / 0.1 + 0.006 / 0.1  # at 0.1 m/s, a deliberate press
    press = path([(0.0, x0, y0, above), (0.2, x0, y0, above), (down_s, x0, y0, press_z), (0.6, x0, y0, press_z),
                  (down_s, x0, y0, above), (0.4, x0, y0, above)])
    # A tap: down at 0.3 m/s to 4 mm into the surface and straight back.
    tap_z = surface_z - 0.004
    tap_s = (above - tap_z) / 0.3
    tap = path([(0.0, x0, y0, above), (0.2, x0, y0, above), (tap_s, x0, y0, tap_z), (tap_s, x0, y0, above),
                (0.4, x0, y0, above)])
    # A stroke: in at x0 − 3 cm, along +x for 6 cm at 5 cm/s, out.
    start_x, end_x = x0 - 0.03, x0 + 0.03
    stroke_z = surface_z - 0.005
    stroke = path([(0.0, start_x, y0, above), (0.2, start_x, y0, above), ((above - stroke_z) / 0.1, start_x, y0,
                                                                             stroke_z),
                   (0.1, start_x, y0, stroke_z), ((end_x - start_x) / 0.05, end_x, y0, stroke_z),
                   (0.1, end_x, y0, stroke_z), ((above - stroke_z) / 0.1, end_x, y0, above), (0.4, end_x, y0, above)])
    # The groove is measured along the stroke's middle, a pad's width in from where it went in and came out. An elastic
    # slab's depth while held is averaged over the middle of the press's hold and of the stroke's cruise.
    press_held = (0.2 + down_s + 0.2, 0.2 + down_s + 0.5)
    cruise_start = 0.2 + (above - stroke_z) / 0.1 + 0.1
    stroke_held = (cruise_start + 0.3, cruise_start + (end_x - start_x) / 0.05 - 0.3)
    return {"press": (press, None, press_held), "tap": (tap, None, None),
            "stroke": (stroke, (start_x + 0.015, end_x - 0.015), stroke_held)}


def write_csv(path, waypoints):
    path.write_text("t,x,y,z\n" + "".join(f"{t:.6f},{x:.6f},{y:.6f},{z:.6f}\n" for t, x, y, z in waypoints))
    return path


def measure(trial_dir, scene_path, rule, case, groove_span, held):
    """What one trial left in the clay, from its summary (and, for an elastic slab held down, world.csv)."""
    summary = json.loads((trial_dir / "summary.json").read_text())
    clay = next(iter(summary["world"]["deformable"].values()))
    result = {"dent_m": clay["max_dent_m"], "volume_m3": clay["dent_volume_m3"], "absorbed_Ns": clay["absorbed_Ns"],
              "yielding_Ns": clay["yielding_Ns"], "clamped_m3": clay["clamped_m3"], "rule": clay["rule"]}
    if clay.get("law") == "elastic":
        result.update({key: clay[key] for key in ("work_J", "scheme_J", "dissipated_J", "stored_J")})
        if held is not None:
            world = logs.read_log(trial_dir / logs.WORLD, keep_time_s=lambda t: held[0] <= t <= held[1])
            name = next(k for k in world.columns if k.endswith(".dent_m"))
            result["held_m"] = statistics.mean(world[name])
        return result
    if groove_span is not None:
        row = clay["deepest_row"]
        centre_x = json.loads(scene_path.read_text())["objects"][0]["position_m"][0]
        xs = [centre_x + row["x0_m"] + k * row["dx_m"] for k in range(len(row["depth_m"]))]
        middle = [d for x, d in zip(xs, row["depth_m"]) if groove_span[0] <= x <= groove_span[1]]
        result["groove_m"] = statistics.mean(middle)
        result["groove_ripple_m"] = max(middle) - min(middle)
        result["profile"] = [d for x, d in zip(xs, row["depth_m"])]
    return result


def one_trial(trial_dir, scene_path, trajectory, rate_hz, phase, rule, case, groove_span, held):
    run_trial(trial_dir, scene_path, trajectory, "impulse", rate_hz, phase)
    return measure(trial_dir, scene_path, rule, case, groove_span, held)


def stats_of(values, reference):
    mean = statistics.mean(values)
    return {"mean": mean, "spread": max(values) - min(values),
            "spread_pct": 100.0 * (max(values) - min(values)) / mean if mean > 0 else float("nan"),
            "bias_pct": 100.0 * (mean - reference) / reference if reference > 0 else float("nan")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/deformation")
    parser.add_argument("--scene", type=pathlib.Path, default=ROOT / "scenes/clay.json",
                        help="a scene whose first object is a deformable box; the fingers work over its centre")
    parser.add_argument("--rates", default="20,10", help="world rates under test, Hz")
    parser.add_argument("--haptic-rate", type=float, default=float(HAPTIC_RATE_HZ))
    parser.add_argument("--phases", type=int, default=25, help="phases spread evenly over one world period")
    parser.add_argument("--cases", default="press,tap,stroke")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--plot", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--check", action="store_true", help="exit 1 unless the goals below hold")
    parser.add_argument("--check-cases", default="press,tap,stroke",
                        help="--check: the cases held to the goals below (the others are reported)")
    parser.add_argument("--check-measures", default=None,
                        help="--check: the measures held to the goals (default: all for a plastic slab; for an "
                             "elastic one held_m, the depth while held: its deepest and the energy it took depend on "
                             "when within a period the push was given, which the world is not told)")
    parser.add_argument("--max-spread", type=float, default=1.0,
                        help="--check: largest impulse-rule spread over phases, %% of the dent (the goal: 1 %%)")
    parser.add_argument("--max-ratio", type=float, default=0.2,
                        help="--check: largest impulse-rule spread / penetration-rule spread (the goal: 1/5)")
    parser.add_argument("--max-bias", type=float, default=2.0,
                        help="--check: largest |bias| of the impulse rule against its 1 kHz reference, %% (goal 2 %%)")
    args = parser.parse_args()

    scene = json.loads(args.scene.read_text())
    clay = scene["objects"][0]
    if "deformable" not in clay or clay["shape"] != "box":
        sys.exit(f"{args.scene}: the first object must be a deformable box")
    elastic = clay["deformable"].get("law", "plastic") == "elastic"
    check_measures = (args.check_measures.split(",") if args.check_measures else
                      ["held_m"] if elastic else ["dent_m", "volume_m3", "groove_m"])
    centre = clay["position_m"]
    surface_z = centre[2] + 0.5 * clay["size_m"][2]
    args.out.mkdir(parents=True, exist_ok=True)
    scenes = {}
    for rule in RULES:
        variant = json.loads(json.dumps(scene))
        variant["objects"][0]["deformable"]["rule"] = rule
        scenes[rule] = args.out / f"scene_{rule}.json"
        scenes[rule].write_text(json.dumps(variant, indent=1))
    paths = trajectories(surface_z, centre[0], centre[1])
    cases = args.cases.split(",")
    files, spans, helds = {}, {}, {}
    for case in cases:
        if case not in paths:
            sys.exit(f"--cases: unknown case {case!r}, expected press, tap, stroke")
        waypoints, spans[case], helds[case] = paths[case]
        files[case] = write_csv(args.out / f"{case}.csv", waypoints)

    rates = [float(r) for r in args.rates.split(",")]
    tasks = []
    for case in cases:
        for rule in RULES:
            key = (case, rule, "reference", 0)
            tasks.append((key, one_trial, (args.out / f"{case}-{rule}-reference", scenes[rule], files[case],
                                           args.haptic_rate, 0, rule, case, spans[case], helds[case])))
            for rate in rates:
                ticks = round(args.haptic_rate / rate)
                for phase in sorted({round(k * ticks / args.phases) for k in range(args.phases)}):
                    key = (case, rule, rate, phase)
                    tasks.append((key, one_trial, (args.out / f"{case}-{rule}-{rate:g}hz-phase{phase:03d}",
                                                   scenes[rule], files[case], rate, phase, rule, case,
                                                   spans[case], helds[case])))
    results = dict(track(run_parallel(tasks, args.jobs), [key for key, _, _ in tasks], "deformation", args.quiet))

    table, report, failures = [], {}, []
    if elastic:
        law_error = max(abs(r["work_J"] + r["scheme_J"] - r["dissipated_J"] - r["stored_J"]) / r["work_J"]
                        for r in results.values() if r["work_J"] > 0)
        law_text = "energy books: |work + scheme − dissipated − held| / work"
    else:
        flow = clay["deformable"].get("flow_resistance_Paspm", 1e6)
        law_error = max(abs(r["volume_m3"] * flow - r["yielding_Ns"]) / r["yielding_Ns"] for r in results.values()
                        if r["rule"] == "impulse" and r["clamped_m3"] == 0.0 and r["yielding_Ns"] > 0)
        law_text = "|volume × η − push above yield| / push above yield"
    if law_error > 1e-9:
        failures.append(f"the law's check ({law_text}) is off by {law_error:.2e} (relative)")
    header = ("| case | rule | world | measure | reference (1 kHz) | mean | spread over phases | spread (% of mean) | "
              "bias vs reference |")
    table += [header, "|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        measures = [("dent depth", "dent_m", 1e3, "mm"), ("dent volume", "volume_m3", 1e9, "mm³")]
        if elastic:
            measures = ([("depth held", "held_m", 1e3, "mm")] if helds[case] is not None else []) + \
                [("deepest", "dent_m", 1e3, "mm"), ("energy it took", "work_J", 1e3, "mJ")]
        elif case == "stroke":
            measures.append(("groove depth", "groove_m", 1e3, "mm"))
        for rule in RULES:
            reference = results[(case, rule, "reference", 0)]
            for rate in rates:
                phase_results = [r for (c, ru, ra, _), r in results.items() if (c, ru, ra) == (case, rule, rate)]
                for label, field, scale, unit in measures:
                    s = stats_of([r[field] for r in phase_results], reference[field])
                    report.setdefault(case, {}).setdefault(rule, {}).setdefault(f"{rate:g}", {})[field] = \
                        dict(s, reference=reference[field], phases=len(phase_results))
                    table.append(f"| {case} | {rule} | {rate:g} Hz | {label} | {scale * reference[field]:.4f} {unit} | "
                                 f"{scale * s['mean']:.4f} {unit} | {scale * s['spread']:.4f} {unit} | "
                                 f"{s['spread_pct']:.2f} % | {s['bias_pct']:+.2f} % |")
    ratio_lines = ["", "| case | world | measure | impulse spread / penetration spread |", "|---|---|---|---|"]
    for case in cases:
        for rate in rates:
            for field in report[case]["impulse"][f"{rate:g}"]:
                imp = report[case]["impulse"][f"{rate:g}"][field]
                pen = report[case]["penetration"][f"{rate:g}"][field]
                ratio = imp["spread"] / pen["spread"] if pen["spread"] > 0 else float("inf")
                report[case]["impulse"][f"{rate:g}"][field]["spread_ratio_to_penetration"] = ratio
                ratio_lines.append(f"| {case} | {rate:g} Hz | {field} | {ratio:.3f} |")
                if case not in args.check_cases.split(",") or field not in check_measures:
                    continue
                if imp["spread_pct"] > args.max_spread:
                    failures.append(f"{case} at {rate:g} Hz: impulse-rule {field} spread {imp['spread_pct']:.2f} % "
                                    f"> {args.max_spread} %")
                if ratio > args.max_ratio:
                    failures.append(f"{case} at {rate:g} Hz: impulse/penetration {field} spread ratio {ratio:.3f} "
                                    f"> {args.max_ratio}")
                if abs(imp["bias_pct"]) > args.max_bias:
                    failures.append(f"{case} at {rate:g} Hz: impulse-rule {field} bias {imp['bias_pct']:+.2f} % "
                                    f"beyond ±{args.max_bias} %")
    title = ["# Deformation experiment: the full table", "",
             "Generated by `scripts/deformation_experiment.py` (`scripts/make_figures.sh`); read "
             "[deformation.md](deformation.md) first.", ""]
    law = f"law check: {law_text} ≤ {law_error:.1e} over all {len(results)} trials"
    text = "\n".join(title + table + ratio_lines + ["", law])
    (args.out / "deformation.md").write_text(text + "\n")
    (args.out / "deformation.json").write_text(json.dumps({"cases": report, "law_relative_error": law_error,
                                                           "failures": failures}, indent=1) + "\n")
    print(text)

    if args.plot:
        plot(args, cases, rates, results)
    if args.check:
        for failure in failures:
            print(f"FAIL: {failure}", file=sys.stderr)
        sys.exit(1 if failures else 0)


def plot(args, cases, rates, results):
    """Dent against time, every phase of the first rate, the two rules side by side (one row per case)."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt
    rate = rates[0]
    fig, axes = plt.subplots(len(cases), 2, figsize=(10, 2.8 * len(cases)), sharex="row", squeeze=False)
    for row, case in enumerate(cases):
        for col, rule in enumerate(RULES):
            ax = axes[row][col]
            for (c, ru, ra, phase), _ in sorted(results.items(), key=lambda item: str(item[0])):
                if (c, ru, ra) != (case, rule, rate):
                    continue
                world = logs.read_log(args.out / f"{case}-{rule}-{rate:g}hz-phase{phase:03d}" / logs.WORLD)
                name = next(k for k in world.columns if k.endswith(".dent_m"))
                ax.plot(world["time_s"], 1e3 * world[name], lw=0.8, alpha=0.7)
            world = logs.read_log(args.out / f"{case}-{rule}-reference" / logs.WORLD)
            name = next(k for k in world.columns if k.endswith(".dent_m"))
            ax.plot(world["time_s"], 1e3 * world[name], "k--", lw=1.5, label=f"{args.haptic_rate:g} Hz reference")
            ax.set_title(f"{case}: {rule} rule, world {rate:g} Hz, {args.phases} phases", fontsize=10)
            ax.set_ylabel("deepest dent (mm)")
            ax.grid(alpha=0.3)
            ax.legend(loc="lower right", fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(args.out / "deformation.png", dpi=80)
    print(f"plot: {args.out / 'deformation.png'}")


if __name__ == "__main__":
    main()
