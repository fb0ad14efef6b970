#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The tap task (paper §4.2, Fig. 7/8): a simulated subject taps the cube to move it 30 cm, trial after trial,
learning from each outcome, once with position coupling and once with impulse coupling.

Each trial is one lockstep run through the real processes with a random world-clock phase (seeded), so the subject
cannot rely on the timing of the world steps — as a real subject cannot. Between trials the subject adjusts the stroke
speed in proportion to the last error. Writes OUT/tap_task.csv, OUT/tap_task.md and OUT/tap_task.png (stop position
per trial like Fig. 7, and the mean absolute deviation of the last 20 trials per method like Fig. 8).
"""
import argparse
import csv
import os
import pathlib
import random
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402

# The subject corrects half of the last error per trial (a cautious learner that does not chase noise), converting
# the error in travel into a change of stroke speed through the sensitivity d travel / d speed it has learned so far:
# the least-squares slope of travel against speed over its own trials. Before it has two different speeds it assumes
# 1 m per m/s (travel ≈ v²/(2 μ g) gives about that near 0.3 m for a pure impulse; a push is less sensitive).
CORRECTED_FRACTION = 0.5
PRIOR_SLOPE_M_PER_MPS = 1.0
SLOPE_LIMITS_M_PER_MPS = (0.05, 5.0)  # keeps a noisy early estimate from making wild strokes
FIRST_SPEED_MPS = 0.4        # a first, tentative tap
SPEED_LIMITS_MPS = (0.1, 1.5)  # a subject neither pushes imperceptibly slowly nor slaps


def learned_slope(outcomes):
    """Least-squares slope of travel against speed over the trials so far."""
    speeds = [speed for _, speed, _, _ in outcomes]
    travels = [travel for _, _, _, travel in outcomes]
    if len(outcomes) < 2 or max(speeds) - min(speeds) < 1e-3:
        return PRIOR_SLOPE_M_PER_MPS
    mean_v = sum(speeds) / len(speeds)
    mean_d = sum(travels) / len(travels)
    slope = sum((v - mean_v) * (d - mean_d) for v, d in zip(speeds, travels)) / sum((v - mean_v) ** 2 for v in speeds)
    return min(max(slope, SLOPE_LIMITS_M_PER_MPS[0]), SLOPE_LIMITS_M_PER_MPS[1])


def subject(method, args, phases):
    """Runs one subject's trials with one method; returns [(trial, speed, phase, travel)]."""
    speed = FIRST_SPEED_MPS
    outcomes = []
    start_x = Scene(args.scene).start_position_m("cube")[0]
    for trial, phase in enumerate(phases):
        out = args.out / f"{method}-trial{trial:02d}"
        summary = run_trial(out, args.scene, f"tap:speed={speed:.6f}", method, args.rate, phase)
        travel = summary.final_position_m("cube")[0] - start_x
        outcomes.append((trial, speed, phase, travel))
        error = args.target - travel
        step = CORRECTED_FRACTION * error / learned_slope(outcomes)
        speed = min(max(speed + step, SPEED_LIMITS_MPS[0]), SPEED_LIMITS_MPS[1])
    return outcomes


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/tap_task")
    parser.add_argument("--scene", default=str(ROOT / "scenes/tap.json"))
    parser.add_argument("--rate", type=float, default=20.0)
    parser.add_argument("--trials", type=int, default=30)
    # The paper's subjects aimed for 30 cm. On our tap scene a stroke's travel saturates because the device force
    # clamps at 10 N: near 18 cm with local coupling (as in the 1 kHz reference) and 25 cm with impulse coupling, which
    # overshoots; 15 cm is inside the range every method reaches, so the task measures accuracy, not reach.
    parser.add_argument("--target", type=float, default=0.15, help="travel the subject aims for, m (paper: 0.30)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--methods", default="position,impulse")
    parser.add_argument("--plot", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--check", action="store_true",
                        help="exit 1 unless every tap moved the cube forward and every number is finite")
    args = parser.parse_args()

    methods = args.methods.split(",")
    ticks_per_step = round(HAPTIC_RATE_HZ / args.rate)
    rng = random.Random(args.seed)
    # The same phase sequence for every method, so the methods differ only in how they couple.
    phases = [rng.randrange(ticks_per_step) for _ in range(args.trials)]
    # One subject per method, each a sequence of trials that adapts to the last; the bar counts finished subjects.
    results = dict(track(run_parallel([(m, subject, (m, args, phases)) for m in methods], jobs=len(methods)), methods,
                         "subjects", args.quiet))

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "tap_task.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["method", "trial", "speed_mps", "phase_ticks", "travel_m", "error_m"])
        for method in methods:
            for trial, speed, phase, travel in results[method]:
                writer.writerow([method, trial, f"{speed:.6f}", phase, f"{travel:.6f}", f"{travel - args.target:.6f}"])
    last = min(20, args.trials)
    lines = [f"Tap task: {args.trials} trials per method, target travel {args.target:.2f} m, world {args.rate:g} Hz, "
             f"random phase per trial (seed {args.seed})", "",
             f"| method | mean abs deviation, last {last} trials (mm) | mean travel, last {last} (m) |",
             "|---|---|---|"]
    deviations = {}
    for method in methods:
        tail = [travel for _, _, _, travel in results[method][-last:]]
        deviations[method] = sum(abs(t - args.target) for t in tail) / len(tail)
        lines.append(f"| {method} | {1e3 * deviations[method]:.1f} | {sum(tail) / len(tail):.3f} |")
    table = "\n".join(lines)
    (args.out / "tap_task.md").write_text(table + "\n")
    print(table)

    if args.plot:
        os.environ.setdefault("MPLBACKEND", "Agg")
        import matplotlib.pyplot as plt
        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [3, 1]})
        for method in methods:
            trials = [t for t, _, _, _ in results[method]]
            travel = [100 * d for _, _, _, d in results[method]]
            left.plot(trials, travel, "o-", ms=4, lw=1, label=method)
        left.axhline(100 * args.target, color="k", ls="--", lw=1, label="target")
        left.set_xlabel("trial")
        left.set_ylabel("stop position (cm)")
        left.set_title("stop position per trial (paper Fig. 7)")
        left.legend(fontsize=8)
        left.grid(alpha=0.3)
        right.bar(methods, [1e3 * deviations[m] for m in methods],
                  color=["tab:blue", "tab:orange", "tab:green"][:len(methods)])
        right.set_ylabel(f"mean |error|, last {last} (mm)")
        right.set_title("accuracy (Fig. 8)")
        fig.tight_layout()
        fig.savefig(args.out / "tap_task.png", dpi=90)
        print(f"plot: {args.out / 'tap_task.png'}")

    if args.check:
        bad = [(m, t) for m in methods for t, _, _, travel in results[m] if not (travel > 0 and travel < 10)]
        if bad:
            print(f"CHECK FAILED: trials without forward travel: {bad}")
            sys.exit(1)
        print("check passed")


if __name__ == "__main__":
    main()
