#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Phase sensitivity of the tap trial (paper Fig. 5): stop position of the cube against the world clock's phase.

Runs the tap scene through the real processes in lockstep at the world rate (default 20 Hz) for PHASES phases spread
over one world period, once per coupling, plus the single-rate reference (world at the haptic rate, 1 kHz). Writes
OUT/phase.csv, OUT/phase.md and OUT/phase_xt.png (x(t) of the cube per phase, side by side like Fig. 5), and prints
the table. With --check it exits 1 unless the paper's claim holds: impulse spread <= --max-ratio x position spread.
(The reference has one phase: its world period is one haptic tick.)
"""
import argparse
import csv
import json
import os
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402


def x_track_m(trial_dir, name):
    """Times (s) and x (m) of object `name` after each world step of the trial in trial_dir."""
    world = logs.read_log(trial_dir / logs.WORLD)
    return world["time_s"], world[f"{name}.x_m"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/phase")
    parser.add_argument("--scene", type=pathlib.Path, default=ROOT / "scenes/tap.json")
    parser.add_argument("--object", default="cube", help="the dynamic object whose stop position is measured")
    parser.add_argument("--trajectory", default="tap")
    parser.add_argument("--rate", type=float, default=20.0, help="world rate under test, Hz")
    parser.add_argument("--haptic-rate", type=float, default=float(HAPTIC_RATE_HZ))
    parser.add_argument("--phases", type=int, default=10, help="phases spread evenly over one world period")
    parser.add_argument("--couplings", default="position,impulse")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--plot", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--check", action="store_true", help="exit 1 unless the paper's claim holds")
    parser.add_argument("--max-ratio", type=float, default=0.5,
                        help="--check: largest allowed impulse spread / position spread (the paper's claim: 0.5)")
    parser.add_argument("--local-max-spread-ratio", type=float, default=0.05,
                        help="--check, when local coupling ran: largest allowed local spread / position spread "
                             "(the goal local coupling was built to: 5 %%)")
    parser.add_argument("--local-max-bias", type=float, default=0.05,
                        help="--check, when local coupling ran: largest allowed |bias| as a fraction of the reference "
                             "travel (the goal local coupling was built to: 5 %%)")
    parser.add_argument("--expect-overshoot", action="store_true",
                        help="--check: also require impulse coupling to stop beyond the reference (the haptic side "
                             "pushes on a plane that cannot move until the next world step, so the object receives "
                             "more momentum than at 1 kHz)")
    args = parser.parse_args()

    ticks_per_step = round(args.haptic_rate / args.rate)
    phases = sorted({round(k * ticks_per_step / args.phases) for k in range(args.phases)})
    couplings = args.couplings.split(",")
    jobs = []
    for coupling in couplings:
        for phase in phases:
            jobs.append((coupling, args.rate, phase))
    # The reference: world at the haptic rate. Its period is one tick, so it has one phase; lockstep makes it
    # bitwise repeatable, so one trial is the whole reference.
    jobs.append(("reference", args.haptic_rate, 0))

    results = {}
    tasks = []
    for label, rate, phase in jobs:
        coupling = "impulse" if label == "reference" else label
        trial_dir = args.out / f"{label}-phase{phase:03d}"
        tasks.append(((label, phase, trial_dir), run_trial,
                      (trial_dir, args.scene, args.trajectory, coupling, rate, phase)))
    # The trials cost about the same (one tap each), so the bar counts them.
    for (label, phase, trial_dir), summary in track(run_parallel(tasks, args.jobs), [key for key, _, _ in tasks],
                                                    "phase sweep", args.quiet):
        results[(label, phase)] = (summary.final_position_m(args.object)[0], trial_dir)

    reference = [results[("reference", 0)][0]]
    reference_mean = sum(reference) / len(reference)
    start_x = Scene(args.scene).start_position_m(args.object)[0]
    rows, stats = [], {}
    for label in couplings + ["reference"]:
        label_phases = phases if label != "reference" else [0]
        stops = [results[(label, p)][0] for p in label_phases]
        for p, x in zip(label_phases, stops):
            rows.append({"coupling": label, "phase_ticks": p, "stop_x_m": x, "bias_m": x - reference_mean})
        mean = sum(stops) / len(stops)
        stats[label] = {"spread_m": max(stops) - min(stops), "mean_m": mean, "bias_m": mean - reference_mean,
                        "bias_pct_of_travel": 100.0 * (mean - reference_mean) / (reference_mean - start_x)}

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "phase.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["coupling", "phase_ticks", "stop_x_m", "bias_m"])
        writer.writeheader()
        writer.writerows(rows)
    lines = [f"Tap trial, world {args.rate:g} Hz vs the {args.haptic_rate:g} Hz reference "
             f"(reference stop x = {reference_mean:.4f} m, travel {reference_mean - start_x:.4f} m)", "",
             "| coupling | phases | stop x mean (m) | phase spread (mm) | bias vs reference (mm) | "
             "bias (% of travel) |",
             "|---|---|---|---|---|---|"]
    for label, s in stats.items():
        count = len(phases) if label != "reference" else 1
        lines.append(f"| {label} | {count} | {s['mean_m']:.4f} | {1e3 * s['spread_m']:.2f} | "
                     f"{1e3 * s['bias_m']:+.2f} | {s['bias_pct_of_travel']:+.1f} |")
    if "position" in stats and "impulse" in stats and stats["position"]["spread_m"] > 0:
        ratio = stats["impulse"]["spread_m"] / stats["position"]["spread_m"]
        lines += ["", f"impulse spread / position spread = {ratio:.3f}"]
    table = "\n".join(lines)
    (args.out / "phase.md").write_text(table + "\n")
    (args.out / "phase.json").write_text(json.dumps(stats, indent=2) + "\n")
    print(table)

    if args.plot:
        os.environ.setdefault("MPLBACKEND", "Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(couplings), figsize=(5 * len(couplings), 3.6), sharey=True)
        if len(couplings) == 1:
            axes = [axes]
        ref_t, ref_x = x_track_m(results[("reference", 0)][1], args.object)
        for ax, label in zip(axes, couplings):
            for p in phases:
                t, x = x_track_m(results[(label, p)][1], args.object)
                ax.plot(t, x, lw=1, alpha=0.8)
            ax.plot(ref_t, ref_x, "k--", lw=1.5, label=f"{args.haptic_rate:g} Hz reference")
            ax.set_title(f"{label} coupling, world {args.rate:g} Hz, {len(phases)} phases")
            ax.set_xlabel("time (s)")
            ax.grid(alpha=0.3)
            ax.legend(loc="lower right", fontsize=8)
        axes[0].set_ylabel(f"{args.object} x (m)")
        fig.tight_layout()
        fig.savefig(args.out / "phase_xt.png", dpi=90)
        print(f"plot: {args.out / 'phase_xt.png'}")

    if args.check:
        failures = []
        ratio = stats["impulse"]["spread_m"] / stats["position"]["spread_m"]
        if ratio > args.max_ratio:
            failures.append(f"impulse spread / position spread = {ratio:.3f} > {args.max_ratio}")
        if "local" in stats:
            local_ratio = stats["local"]["spread_m"] / stats["position"]["spread_m"]
            if local_ratio > args.local_max_spread_ratio:
                failures.append(f"local spread / position spread = {local_ratio:.3f} > {args.local_max_spread_ratio}")
            if abs(stats["local"]["bias_pct_of_travel"]) > 100 * args.local_max_bias:
                failures.append(f"local bias {stats['local']['bias_pct_of_travel']:+.1f} % of travel exceeds "
                                f"{100 * args.local_max_bias:.0f} %")
        if args.expect_overshoot and stats["impulse"]["bias_m"] <= 0:
            failures.append("impulse coupling did not overshoot the reference "
                            f"(bias {stats['impulse']['bias_m']:+.4f} m)")
        if failures:
            print("CHECK FAILED: " + "; ".join(failures))
            sys.exit(1)
        print("check passed")


if __name__ == "__main__":
    main()
