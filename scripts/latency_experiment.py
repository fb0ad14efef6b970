#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Latency and loss tolerance of the couplings: tap, catch, stack and grasp over a delayed, lossy world link.

Every trial runs in this process through the impetus package (in-process link with its delay line: frames and reports
each arrive DELAY later, rounded to whole haptic ticks; common/link/inproc/inproc_world_link.h). The three daemons
have no delay line, so the package must be built (scripts/build.sh).

  tap    scenes/tap.json, trajectory tap with a rest at the start (--rest-s: the first frames reach the haptic side
         a round trip after the start, and a finger that strikes before would meet a cube nobody told it about),
         world 20 Hz, PHASES world-clock phases per (coupling, delay) for position, impulse and local coupling, and
         position and impulse coupling with the world's passivity layer (COUPLING+layer, world_manager --passivity
         on; the energy it withheld from pushes, as predicted, plus what it damped out of bodies and off the fingers
         is the "layer withheld + damped" column): the
         cube's stop position (mean, phase spread, bias against the zero-delay single-rate 1 kHz reference as
         scripts/phase_experiment.py computes it), and stability: the largest energy
         gain beyond the hand's work (impetus_py/energy.py), the largest finger force, and how many separate contacts
         the single stroke made (1 for a clean push; more when the cube is bounced back and forth).
  loss   the tap again with the link losing packets (--losses, at --loss-delays-ms): frames and reports, each
         direction its own seeded Gilbert-Elliott stream (common/link/link_loss.h).
  stack  hard case 8 (five boxes of 1000:1 mass ratios pressed from above): held (every box within 1 mm of its rest
         pose), energy gain.
  catch  hard case 12a (a cube sliding into a still finger), every coupling with and without the layer: caught (never
         through the finger), settled (under 0.1 mm of motion in the last 0.5 s), arrival and leaving speed, energy
         gain.
  grasp  scenes/grasp.json, thumb and index (scenes/grasp_*.csv) lifting the cube, impulse and local coupling: lift at
         the start of the hold, slip during the hold, peak-to-peak of each finger's force during the hold, energy
         gain.

Writes OUT/latency.csv (one row per scene, coupling and delay), OUT/latency_trials.csv (one row per trial),
OUT/latency.md (the tables) and OUT/latency.png. --check exits 1 unless every number is finite and, for every impulse
and local trial, the impulse the world applied to each object equals what the haptic side rendered (the ledger stays
exact under delay; the fingers leave the objects long before the end, so the totals are final).
"""
import argparse
import csv
import math
import os
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import logs  # noqa: E402
from impetus_py.daemon_defaults import HAPTIC_RATE_HZ  # noqa: E402
from impetus_py.energy import energy_balance  # noqa: E402
from impetus_py.parallel import run_parallel  # noqa: E402
from impetus_py.paths import ROOT  # noqa: E402
from impetus_py.progress import track  # noqa: E402
from impetus_py.scene import Scene  # noqa: E402
from impetus_py.trial import COUPLINGS, backend, run_trial  # noqa: E402

TAP_SCENE = ROOT / "scenes/tap.json"
GRASP_SCENE = ROOT / "scenes/grasp.json"
# The catch: a cube slides down a ramp into a finger held still (hard case 12a).
CATCH_SCENE = ROOT / "tests/hard_cases/c12a_slide_down_ramp.json"
CATCH_TRAJECTORY = ROOT / "tests/hard_cases/c12a_slide_down_ramp.csv"
# The stack: five boxes of 1000:1 mass ratios pressed from above (hard case 8), the finger starting 4.5 cm above (the
# device frame's top) so the first frames reach it before the press at every delay swept (a round trip of 0.3 s
# plus a period at 150 ms; it reaches the top box after about 0.7 s).
STACK_SCENE = ROOT / "tests/hard_cases/c08_stack_ratio.json"
STACK_TRAJECTORY = "press:x=0,y=0,surface_z=0.2,depth=0.01,speed=0.1,hold=2,standoff=0.045"
CATCH_SETTLE_S = 0.5      # the settling window: the cube's motion over the last half second...
CATCH_SETTLE_M = 1e-4     # ...below 0.1 mm
GRASP_FINGERS = {"thumb": str(ROOT / "scenes/grasp_thumb.csv"), "index": str(ROOT / "scenes/grasp_index.csv")}
# The fingers hold the cube up over this window (scripts/grasp_figure.py): lift, slip and force ripple are read here.
GRASP_HOLD_S = (2.5, 7.0)
# A finger is in contact while its force exceeds this (N): 1 % of the device's 10 N limit, far above the 1e-12 N of
# rounding, far below any push.
CONTACT_FORCE_N = 0.1
# The ledger holds to rounding: a running total of ~1e3 tick impulses, each exact to 1e-16 relative.
LEDGER_TOLERANCE = 1e-9

FULL_DELAYS_MS = (0, 1, 2, 5, 10, 20, 50, 100, 150)
FULL_GRASP_DELAYS_MS = (0, 5, 20, 50, 100, 150)


def contact_episodes(force_N):
    """How many separate runs of contact (|f| > CONTACT_FORCE_N) a force trace holds."""
    touching = force_N > CONTACT_FORCE_N
    return int(np.count_nonzero(touching[1:] & ~touching[:-1]) + (1 if len(touching) and touching[0] else 0))


def force_magnitude_N(haptic):
    return np.linalg.norm(haptic.vectors("force_", "_N"), axis=1)


def ledger_error_Ns(summary, out_dir):
    """How far the impulse the world applied is from what the haptic side rendered (relative, |a − r| / (1 + |r|),
    largest component over the endpoints), or None when the coupling applies no rendered impulse (position coupling
    applies a penalty from the sampled finger).

    Over a delayed link the world has read the reports only up to its last step's, which the delay and a world period
    put at most delay_ticks + one period of ticks before the end: a finger still touching at the end has rendered
    more since. So the applied total (summed over the objects) is compared with the rendered totals of that last
    stretch of the endpoint's haptic log, and the nearest counts; with nothing rendered at the end they are all the
    same, the final total."""
    if summary.config["coupling"] == "position":
        return None
    applied = summary.world["endpoints"]
    tail_ticks = summary.link["delay_ticks"] + round(summary.world_period_s / summary.haptic_period_s) + 2
    worst = 0.0
    for k in range(len(summary.haptic["endpoints"])):
        applied_Ns = np.sum([v for v in applied[k]["impulse_by_object_Ns"].values()] or [[0.0, 0.0, 0.0]], axis=0)
        log = logs.read_log(out_dir / (logs.HAPTIC if k == 0 else f"haptic.endpoint{k}.csv"))
        rendered_Ns = log.vectors("object_impulse_", "_Ns")[-tail_ticks:]
        errors = np.max(np.abs(rendered_Ns - applied_Ns) / (1.0 + np.abs(rendered_Ns)), axis=1)
        worst = max(worst, float(errors.min()))
    return worst


def energy_gain(out_dir, summary, scene, devices, phase_ticks):
    """energy_balance of the trial: (largest energy gain beyond the hand's work, its tolerance), J.

    energy_balance pairs each world step with the haptic tick it was taken at on a phase-0 clock without delay, when
    the step holds every impulse rendered up to that tick. Over a link of delay d (and with phase p) a step holds the
    impulses up to the report it applied, d (and p) earlier; what the hand did after that tick is still on the link,
    in both directions: a hand that has already taken the push of a cube the world has not yet stopped would show the
    cube's energy twice (0.12 J in the catch at 50 ms). So each step is paired with the tick of the report it applied
    (world.csv's haptic_time_s: logs.world_clock_offset_s, the phase alone without delay). Nothing is hidden: every
    push lands in a later step, which is compared with the hand's work up to its own report."""
    world = logs.read_log(out_dir / logs.WORLD)
    haptic_period_s = summary.haptic_period_s
    offset_s = logs.world_clock_offset_s(world) if summary.link["delay_ticks"] > 0 else -phase_ticks * haptic_period_s
    world.columns["time_s"] = world["time_s"] - offset_s
    balance = energy_balance(scene, summary.objects, devices, world, summary.device, summary.world_period_s,
                             haptic_period_s)
    return balance["excess_J"], balance["tolerance_J"]


def layer_cost_J(summary):
    """What the passivity layer held back in a trial, J: the energy the world withheld from pushes (as predicted) and
    damped out of bodies (world_manager/couplings/passivity_layer.h), and what the hands' dampers took from the
    force on the fingers (haptic_controller/hand_port.h)."""
    port = summary.world["port"]
    hands = summary.haptic.get("endpoints", [summary.haptic])
    return port["withheld_J"] + port["damped_J"] + sum(h.get("hand_port", {}).get("damped_J", 0.0) for h in hands)


def hard_case_trial(out_dir, scene, trajectory, label, phase_ticks, delay_ms):
    """One trial of a hard case's scene: (its hard_cases.Trial, the measurements every cell shares)."""
    import hard_cases  # scripts/: the cases' own checks
    coupling, layer = coupling_and_layer(label)
    summary = run_trial(out_dir, scene, trajectory, coupling, None, phase_ticks, link_delay_s=delay_ms * 1e-3,
                        passivity=layer)
    trial = hard_cases.Trial(out_dir)
    gain_J, tolerance_J = energy_gain(out_dir, summary, Scene(scene), [trial.device], phase_ticks)
    return trial, {"energy_gain_J": gain_J, "energy_tolerance_J": tolerance_J,
                   "max_force_N": float(force_magnitude_N(trial.haptic).max()),
                   "layer_withheld_J": layer_cost_J(summary),
                   "ledger_error": ledger_error_Ns(summary, out_dir), "delay_ticks": summary.link["delay_ticks"],
                   "link_dropped": summary.link["dropped"]}


def catch_trial(out_dir, label, phase_ticks, delay_ms):
    """One catch trial; returns its row of measurements: caught (hard_cases.check_arrival: never passed through, ends
    on its own side), the speed it arrived at and left with along the approach, its motion in the last CATCH_SETTLE_S,
    and the energy gain."""
    import hard_cases
    trial, row = hard_case_trial(out_dir, CATCH_SCENE, str(CATCH_TRAJECTORY), label, phase_ticks, delay_ms)
    # check_arrival compares the proxy with the world's cube a world period later, the lag of a link without delay.
    # Over a delay d the world's step holds the pushes of the report it applied, d earlier: the world log is put
    # on the haptic clock d back, so the cube is compared with the proxy that pushed it, as without delay.
    world_times = trial.world["time_s"].copy()
    trial.world.columns["time_s"] = world_times - row["delay_ticks"] * trial.summary.haptic_period_s
    caught, _, _ = hard_cases.check_arrival(trial)
    trial.world.columns["time_s"] = world_times
    centre = trial.world.vectors("cube.", "_m")
    u = trial.device.vectors("target_", "_m")[0] - np.asarray(trial.objects["cube"]["position_m"])
    u /= np.linalg.norm(u)
    speed = trial.world.vectors("cube.v", "_mps") @ u
    t = trial.world["time_s"]
    last = centre[t >= t[-1] - CATCH_SETTLE_S]
    return {**row, "caught": bool(caught), "arrival_mps": float(np.max(speed)),
            "leaving_mps": float(max(0.0, -np.min(speed))),
            "settle_m": float(np.max(np.linalg.norm(last - last[-1], axis=1)))}


def stack_trial(out_dir, label, phase_ticks, delay_ms):
    """One stack trial; returns its row of measurements: the largest displacement of any box from its rest pose
    (hard_cases.check_stack: held within 1 mm) and the energy gain."""
    import hard_cases
    trial, row = hard_case_trial(out_dir, STACK_SCENE, STACK_TRAJECTORY, label, phase_ticks, delay_ms)
    held, _, _ = hard_cases.check_stack(trial)
    worst = max(float(np.max(np.linalg.norm(trial.world.vectors(f"{name}.", "_m") - np.asarray(obj["position_m"]),
                                            axis=1)))
                for name, obj in trial.objects.items())
    return {**row, "held": bool(held), "displacement_m": worst}


def coupling_and_layer(label):
    """A coupling label, COUPLING or COUPLING+layer: (coupling, whether the world's passivity layer is on)."""
    coupling, _, variant = label.partition("+")
    return coupling, variant == "layer"


def tap_trial(out_dir, trajectory, label, rate_hz, phase_ticks, delay_ms, loss=(0.0, 1.0)):
    """One tap trial; returns its row of measurements. loss: (fraction lost, mean burst in packets)."""
    coupling, layer = coupling_and_layer(label)
    summary = run_trial(out_dir, TAP_SCENE, trajectory, coupling, rate_hz, phase_ticks, link_delay_s=delay_ms * 1e-3,
                        passivity=layer, link_loss=loss[0], link_loss_burst=loss[1])
    haptic = logs.read_log(out_dir / logs.HAPTIC)
    device = logs.read_log(out_dir / logs.DEVICE)
    force = force_magnitude_N(haptic)
    gain_J, tolerance_J = energy_gain(out_dir, summary, Scene(TAP_SCENE), [device], phase_ticks)
    return {"stop_x_m": summary.final_position_m("cube")[0], "energy_gain_J": gain_J,
            "energy_tolerance_J": tolerance_J, "max_force_N": float(force.max()),
            "layer_withheld_J": layer_cost_J(summary),
            "contacts": contact_episodes(force), "ledger_error": ledger_error_Ns(summary, out_dir),
            "lost_frames": summary.link["lost_frames"], "lost_reports": summary.link["lost_reports"],
            "delay_ticks": summary.link["delay_ticks"],
            "link_dropped": summary.link["dropped"]}


def grasp_trial(out_dir, label, phase_ticks, delay_ms, scene=GRASP_SCENE):
    """One grasp trial (of `scene`, the grasp's by default: another must hold the same cube where the fingers'
    paths expect it); returns its row of measurements, with the cube's height at the end (final_z_m)."""
    coupling, layer = coupling_and_layer(label)
    summary = run_trial(out_dir, scene, GRASP_FINGERS, coupling, None, phase_ticks,
                        link_delay_s=delay_ms * 1e-3, passivity=layer)
    world = logs.read_log(out_dir / logs.WORLD)
    t, z = world["time_s"], world["cube.z_m"]
    hold = z[(t >= GRASP_HOLD_S[0]) & (t <= GRASP_HOLD_S[1])]
    devices = [logs.read_log(out_dir / logs.DEVICE), logs.read_log(out_dir / "device.endpoint1.csv")]
    ripple, largest = [], 0.0
    for name in (logs.HAPTIC, "haptic.endpoint1.csv"):
        haptic = logs.read_log(out_dir / name)
        force = force_magnitude_N(haptic)
        held = force[(haptic["time_s"] >= GRASP_HOLD_S[0]) & (haptic["time_s"] <= GRASP_HOLD_S[1])]
        ripple.append(float(held.max() - held.min()))
        largest = max(largest, float(force.max()))
    gain_J, tolerance_J = energy_gain(out_dir, summary, Scene(scene), devices, phase_ticks)
    return {"lift_mm": 1e3 * (hold[0] - z[0]), "lift_end_mm": 1e3 * (hold[-1] - z[0]), "final_z_m": float(z[-1]),
            "slip_mm": 1e3 * (hold.max() - hold.min()),
            "hold_force_p2p_N": max(ripple), "max_force_N": largest, "energy_gain_J": gain_J,
            "layer_withheld_J": layer_cost_J(summary),
            "energy_tolerance_J": tolerance_J, "ledger_error": ledger_error_Ns(summary, out_dir),
            "delay_ticks": summary.link["delay_ticks"],
            "link_dropped": summary.link["dropped"]}


def parse_ms(text, name):
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        sys.exit(f"latency_experiment: {name} must be comma-separated numbers of milliseconds, not '{text}'")
    if not values or any(not 0 <= v <= 1000 for v in values):
        sys.exit(f"latency_experiment: {name} must be delays from 0 to 1000 ms, not '{text}'")
    return values


# --check holds local coupling, and every coupling with the passivity layer, to no energy gain at every delay, except
# the grasp under local coupling beyond this one-way delay (ms), where docs/latency.md reports a gain still open.
GRASP_PASSIVE_UP_TO_MS = 20.0


def ms_label(delay_ms):
    return f"{delay_ms:g}"


def parse_losses(text):
    """--losses: comma-separated PCT or PCTbB (PCT % of packets lost in runs of B on average): [(fraction, burst)]."""
    losses = []
    for item in (x.strip() for x in text.split(",") if x.strip()):
        percent, _, burst = item.partition("b")
        try:
            loss = (float(percent) / 100.0, float(burst) if burst else 1.0)
        except ValueError:
            sys.exit(f"latency_experiment: --losses takes PCT or PCTbBURST items (5, 20b5), not '{item}'")
        if not (0.0 < loss[0] <= 0.5 and 1.0 <= loss[1] <= 1000.0):
            sys.exit(f"latency_experiment: a loss must be above 0 and at most 50 %, its burst 1 to 1000 packets, "
                     f"not '{item}'")
        losses.append(loss)
    return losses


def loss_label(loss):
    return f"{100 * loss[0]:g} %" + (f", bursts of {loss[1]:g}" if loss[1] > 1.0 else "")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     epilog="\n".join(__doc__.splitlines()[2:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/latency")
    parser.add_argument("--delays-ms", default=",".join(map(str, FULL_DELAYS_MS)),
                        help="one-way link delays of the tap sweep, ms (default %(default)s)")
    parser.add_argument("--couplings", default="position,impulse,local,position+layer,impulse+layer",
                        help="tap couplings, COUPLING or COUPLING+layer (the world's passivity layer on; default "
                             "%(default)s)")
    parser.add_argument("--phases", type=int, default=10, help="world-clock phases per tap cell (default 10)")
    parser.add_argument("--rate", type=float, default=20.0, help="world rate under test, Hz (default 20)")
    parser.add_argument("--rest-s", type=float, default=None,
                        help="time the tap's finger rests at its start before the stroke (tap:rest=...), s; default: "
                             "whole world periods covering two longest delays plus two periods, so the first frames "
                             "(a round trip late) are there before the finger moves at every delay swept; 0: the "
                             "plain tap of scripts/phase_experiment.py, whose finger moves at once")
    parser.add_argument("--losses", default="5,20,20b5",
                        help="tap cells with link loss: PCT or PCTbB (B: mean run of lost packets; default "
                             "%(default)s)")
    parser.add_argument("--loss-delays-ms", default="0,20,50",
                        help="delays the loss cells run at (default %(default)s)")
    parser.add_argument("--catch-delays-ms", default=",".join(map(str, FULL_GRASP_DELAYS_MS)),
                        help="catch cells (a cube sliding into a still finger, hard case 12a): delays (default "
                             "%(default)s; empty: none)")
    parser.add_argument("--catch-couplings", default="position,impulse,local,position+layer,impulse+layer",
                        help="catch couplings, as --couplings (default %(default)s)")
    parser.add_argument("--catch-phases", type=int, default=5, help="world-clock phases per catch cell (default 5)")
    parser.add_argument("--stack-delays-ms", default=",".join(map(str, FULL_GRASP_DELAYS_MS)),
                        help="stack cells (five boxes of 1000:1 mass ratios pressed from above, hard case 8): delays "
                             "(default %(default)s; empty: none)")
    parser.add_argument("--stack-couplings", default="position,impulse,local,position+layer,impulse+layer",
                        help="stack couplings, as --couplings (default %(default)s)")
    parser.add_argument("--stack-phases", type=int, default=3, help="world-clock phases per stack cell (default 3)")
    parser.add_argument("--grasp-delays-ms", default=",".join(map(str, FULL_GRASP_DELAYS_MS)),
                        help="delays of the grasp, ms (default %(default)s; empty: no grasp)")
    parser.add_argument("--grasp-couplings", default="impulse,local",
                        help="grasp couplings, as --couplings (default %(default)s)")
    parser.add_argument("--grasp-phases", type=int, default=5, help="world-clock phases per grasp cell (default 5)")
    parser.add_argument("--quick", action="store_true",
                        help="a small sweep for CTest: the tap at delays 0 and 20 ms, 2 phases, and the grasp at 20 ms "
                             "under local coupling, 1 phase")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quiet", action="store_true", help="no progress bar (it shows only on a terminal anyway)")
    parser.add_argument("--plot", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--check", action="store_true",
                        help="exit 1 unless every number is finite, the ledger is exact in every impulse and local "
                             "trial, and no local or +layer trial gains energy beyond its tolerance (the grasp under "
                             "local coupling up to 20 ms)")
    args = parser.parse_args()
    if args.quick:
        args.delays_ms, args.phases = "0,20", 2
        args.losses, args.loss_delays_ms = "20b5", "20"
        args.catch_delays_ms, args.catch_couplings, args.catch_phases = "20,50", "local,impulse+layer", 1
        args.stack_delays_ms, args.stack_couplings, args.stack_phases = "20", "local", 1
        args.grasp_delays_ms, args.grasp_couplings, args.grasp_phases = "20", "local", 1
    for flag, count in (("--phases", args.phases), ("--grasp-phases", args.grasp_phases),
                        ("--catch-phases", args.catch_phases), ("--stack-phases", args.stack_phases)):
        if count < 1:
            sys.exit(f"latency_experiment: {flag} must be 1 or more, not {count}")
    if backend() != "module":
        sys.exit("latency_experiment: the delay line lives in the in-process link; build the impetus package "
                 "(scripts/build.sh) and do not set IMPETUS_TRIALS=processes")
    delays = parse_ms(args.delays_ms, "--delays-ms")
    grasp_delays = parse_ms(args.grasp_delays_ms, "--grasp-delays-ms") if args.grasp_delays_ms.strip() else []
    losses = parse_losses(args.losses)
    loss_delays = parse_ms(args.loss_delays_ms, "--loss-delays-ms") if losses else []
    catch_delays = parse_ms(args.catch_delays_ms, "--catch-delays-ms") if args.catch_delays_ms.strip() else []
    catch_couplings = [c for c in args.catch_couplings.split(",") if c] if catch_delays else []
    stack_delays = parse_ms(args.stack_delays_ms, "--stack-delays-ms") if args.stack_delays_ms.strip() else []
    stack_couplings = [c for c in args.stack_couplings.split(",") if c] if stack_delays else []
    couplings = [c for c in args.couplings.split(",") if c]
    grasp_couplings = [c for c in args.grasp_couplings.split(",") if c] if grasp_delays else []
    for label in couplings + grasp_couplings + catch_couplings + stack_couplings:
        coupling, _ = coupling_and_layer(label)
        if coupling not in COUPLINGS or label not in (coupling, coupling + "+layer"):
            sys.exit(f"latency_experiment: a coupling must be one of {', '.join(COUPLINGS)}, optionally with "
                     f"'+layer', not '{label}'")

    ticks_per_step = round(HAPTIC_RATE_HZ / args.rate)
    phases = sorted({round(k * ticks_per_step / args.phases) for k in range(args.phases)})
    # A rest of whole world periods keeps the stroke where it was against the world clock: at zero delay the trials
    # are those of the plain tap, the cube resting meanwhile.
    world_period_s = 1.0 / args.rate
    if args.rest_s is None:
        args.rest_s = (math.ceil(2e-3 * max(delays + loss_delays) / world_period_s - 1e-9) + 2) * world_period_s
    if args.rest_s < 0:
        sys.exit(f"latency_experiment: --rest-s must be 0 or more, not {args.rest_s}")
    tap = f"tap:rest={args.rest_s:.6g}" if args.rest_s > 0 else "tap"
    tasks = []
    for coupling in couplings:
        for delay in delays:
            for phase in phases:
                out_dir = args.out / "tap" / f"{coupling}-delay{ms_label(delay)}ms-phase{phase:03d}"
                tasks.append((("tap", coupling, delay, phase), tap_trial,
                              (out_dir, tap, coupling, args.rate, phase, delay)))
    for coupling in couplings:
        for loss in losses:
            for delay in loss_delays:
                for phase in phases:
                    out_dir = (args.out / "tap-loss" /
                               f"{coupling}-loss{100 * loss[0]:g}b{loss[1]:g}-delay{ms_label(delay)}ms-phase{phase:03d}")
                    tasks.append((("tap-loss", coupling, delay, phase, loss), tap_trial,
                                  (out_dir, tap, coupling, args.rate, phase, delay, loss)))
    # The reference: impulse coupling with the world at the haptic rate and no delay (one phase: its period is a tick).
    tasks.append((("tap", "reference", 0.0, 0), tap_trial,
                  (args.out / "tap" / "reference", tap, "impulse", float(HAPTIC_RATE_HZ), 0, 0.0)))
    def scene_tasks(scene, trial, scene_couplings, scene_delays, phase_count):
        """Tasks for every (coupling, delay, phase) of a scene; returns its phases."""
        scene_phases = sorted({round(k * ticks_per_step / phase_count) for k in range(phase_count)})
        for coupling in scene_couplings:
            for delay in scene_delays:
                for phase in scene_phases:
                    out_dir = args.out / scene / f"{coupling}-delay{ms_label(delay)}ms-phase{phase:03d}"
                    tasks.append(((scene, coupling, delay, phase), trial, (out_dir, coupling, phase, delay)))
        return scene_phases

    grasp_phases = scene_tasks("grasp", grasp_trial, grasp_couplings, grasp_delays, args.grasp_phases)
    catch_phases = scene_tasks("catch", catch_trial, catch_couplings, catch_delays, args.catch_phases)
    stack_phases = scene_tasks("stack", stack_trial, stack_couplings, stack_delays, args.stack_phases)

    # A grasp runs 10 s of trajectory, a catch 4 s, a stack 3 s, a tap about 2 s; the reference steps its world 50
    # times as often.
    def weight(key):
        return {"grasp": 5.0, "catch": 2.0, "stack": 1.5}.get(key[0], 1.0) * (3.0 if key[1] == "reference" else 1.0)

    trials = {}
    try:
        for key, row in track(run_parallel(tasks, args.jobs), [key for key, _, _ in tasks], "latency sweep",
                              args.quiet, weight):
            trials[key] = row
    except RuntimeError as error:  # a trial that failed names itself
        sys.exit(f"latency_experiment: {error}")

    reference_x = trials[("tap", "reference", 0.0, 0)]["stop_x_m"]
    start_x = Scene(TAP_SCENE).start_position_m("cube")[0]
    travel = reference_x - start_x
    def shared(scene, coupling, delay, rows):
        """What every cell reports, over its phases' rows: the energy check, the force, the ledger, the link."""
        ledger = [r["ledger_error"] for r in rows if r["ledger_error"] is not None]
        return {"scene": scene, "coupling": coupling, "delay_ms": delay, "delay_ticks": rows[0]["delay_ticks"],
                "trials": len(rows), "energy_gain_max_J": max(r["energy_gain_J"] for r in rows),
                "energy_tolerance_J": max(r["energy_tolerance_J"] for r in rows),
                "energy_over_tolerance": sum(r["energy_gain_J"] > r["energy_tolerance_J"] for r in rows),
                "max_force_N": max(r["max_force_N"] for r in rows),
                "layer_withheld_max_J": max(r["layer_withheld_J"] for r in rows),
                "ledger_error_max": max(ledger) if ledger else math.nan,
                "link_dropped": sum(r["link_dropped"] for r in rows)}

    def stops(rows):
        """The tap's stop position over its phases: mean, spread and bias against the reference."""
        x = [r["stop_x_m"] for r in rows]
        mean = sum(x) / len(x)
        return {"stop_x_mean_m": mean, "phase_spread_m": max(x) - min(x), "bias_m": mean - reference_x,
                "bias_pct_of_travel": 100.0 * (mean - reference_x) / travel}

    cells = []
    for coupling in couplings:
        for delay in delays:
            rows = [trials[("tap", coupling, delay, p)] for p in phases]
            cells.append({**shared("tap", coupling, delay, rows), **stops(rows),
                          "contacts_max": max(r["contacts"] for r in rows),
                          "contacts_mean": sum(r["contacts"] for r in rows) / len(rows)})
    for coupling in couplings:
        for loss in losses:
            for delay in loss_delays:
                rows = [trials[("tap-loss", coupling, delay, p, loss)] for p in phases]
                cells.append({**shared("tap-loss", coupling, delay, rows), **stops(rows), "loss": loss[0],
                              "loss_burst": loss[1],
                              "lost_frames_mean": sum(r["lost_frames"] for r in rows) / len(rows),
                              "lost_reports_mean": sum(r["lost_reports"] for r in rows) / len(rows)})
    for coupling in catch_couplings:
        for delay in catch_delays:
            rows = [trials[("catch", coupling, delay, p)] for p in catch_phases]
            cells.append({**shared("catch", coupling, delay, rows),
                          "caught": sum(r["caught"] for r in rows),
                          "settled": sum(r["settle_m"] < CATCH_SETTLE_M for r in rows),
                          "arrival_mps": max(r["arrival_mps"] for r in rows),
                          "leaving_mps": max(r["leaving_mps"] for r in rows),
                          "settle_m": max(r["settle_m"] for r in rows)})
    for coupling in stack_couplings:
        for delay in stack_delays:
            rows = [trials[("stack", coupling, delay, p)] for p in stack_phases]
            cells.append({**shared("stack", coupling, delay, rows), "held": sum(r["held"] for r in rows),
                          "displacement_m": max(r["displacement_m"] for r in rows)})
    for coupling in grasp_couplings:
        for delay in grasp_delays:
            rows = [trials[("grasp", coupling, delay, p)] for p in grasp_phases]
            # Held: the cube is still at least half as high at the hold's end as at its start.
            held = sum(r["lift_end_mm"] >= 0.5 * r["lift_mm"] > 0 for r in rows)
            cells.append({**shared("grasp", coupling, delay, rows),
                          "lift_mm": min(r["lift_mm"] for r in rows),
                          "lift_end_mm": min(r["lift_end_mm"] for r in rows), "held": held,
                          "slip_mm": max(r["slip_mm"] for r in rows),
                          "hold_force_p2p_N": max(r["hold_force_p2p_N"] for r in rows)})

    args.out.mkdir(parents=True, exist_ok=True)
    fields = ["scene", "coupling", "delay_ms", "loss", "loss_burst", "lost_frames_mean", "lost_reports_mean",
              "caught", "settled", "arrival_mps", "leaving_mps", "settle_m", "displacement_m",
              "delay_ticks", "trials", "stop_x_mean_m", "phase_spread_m", "bias_m",
              "bias_pct_of_travel", "lift_mm", "lift_end_mm", "held", "slip_mm", "hold_force_p2p_N",
              "energy_gain_max_J",
              "energy_tolerance_J", "energy_over_tolerance", "max_force_N", "layer_withheld_max_J", "contacts_max",
              "contacts_mean",
              "ledger_error_max", "link_dropped"]
    with open(args.out / "latency.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(cells)
    with open(args.out / "latency_trials.csv", "w", newline="") as f:
        trial_fields = ["scene", "coupling", "delay_ms", "loss", "loss_burst", "phase_ticks", "delay_ticks", "caught",
                        "arrival_mps", "leaving_mps", "settle_m", "held", "displacement_m", "stop_x_m", "lift_mm",
                        "lift_end_mm", "final_z_m", "slip_mm", "hold_force_p2p_N", "energy_gain_J",
                        "energy_tolerance_J", "max_force_N", "layer_withheld_J",
                        "contacts", "ledger_error", "lost_frames", "lost_reports", "link_dropped"]
        writer = csv.DictWriter(f, fieldnames=trial_fields, restval="")
        writer.writeheader()
        for key, row in sorted(trials.items(), key=lambda item: item[0][:4]):
            scene, coupling, delay, phase = key[:4]
            extra = {"loss": key[4][0], "loss_burst": key[4][1]} if len(key) > 4 else {}
            writer.writerow({"scene": scene, "coupling": coupling, "delay_ms": delay, "phase_ticks": phase, **extra,
                             **row})

    lines = [f"Tap trial (`{tap}`), world {args.rate:g} Hz, {len(phases)} world-clock phases per cell, one-way link "
             f"delay each way; reference: impulse coupling, world at {HAPTIC_RATE_HZ} Hz, no delay (stop x = "
             f"{reference_x:.4f} m, travel {travel:.4f} m)", "",
             "| coupling | delay (ms) | stop x mean (m) | phase spread (mm) | bias vs reference (mm) | "
             "bias (% of travel) | energy gain, worst phase (mJ) | phases over tolerance | max force (N) | "
             "layer withheld + damped, worst phase (mJ) | contacts per stroke (mean, max) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    ref = trials[("tap", "reference", 0.0, 0)]
    lines.append(f"| reference (1 kHz world) | 0 | {reference_x:.4f} | – | – | – | {1e3 * ref['energy_gain_J']:+.2f} | "
                 f"{int(ref['energy_gain_J'] > ref['energy_tolerance_J'])}/1 | {ref['max_force_N']:.2f} | – | "
                 f"{ref['contacts']:.1f}, {ref['contacts']} |")
    for c in cells:
        if c["scene"] != "tap":
            continue
        lines.append(f"| {c['coupling']} | {ms_label(c['delay_ms'])} | {c['stop_x_mean_m']:.4f} | "
                     f"{1e3 * c['phase_spread_m']:.2f} | {1e3 * c['bias_m']:+.2f} | {c['bias_pct_of_travel']:+.1f} | "
                     f"{1e3 * c['energy_gain_max_J']:+.2f} | {c['energy_over_tolerance']}/{c['trials']} | "
                     f"{c['max_force_N']:.2f} | "
                     f"{1e3 * c['layer_withheld_max_J']:.1f} | {c['contacts_mean']:.1f}, {c['contacts_max']} |")
    if losses:
        lines += ["", f"Tap with link loss ({len(phases)} phases per cell; each direction loses its own packets, from "
                  f"a seeded Gilbert–Elliott model)", "",
                  "| coupling | delay (ms) | loss | lost frames, reports (mean) | stop x mean (m) | phase spread (mm) | "
                  "bias (% of travel) | energy gain, worst phase (mJ) | phases over tolerance | max force (N) |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for c in cells:
            if c["scene"] != "tap-loss":
                continue
            lines.append(f"| {c['coupling']} | {ms_label(c['delay_ms'])} | "
                         f"{loss_label((c['loss'], c['loss_burst']))} | "
                         f"{c['lost_frames_mean']:.1f}, {c['lost_reports_mean']:.0f} | {c['stop_x_mean_m']:.4f} | "
                         f"{1e3 * c['phase_spread_m']:.2f} | {c['bias_pct_of_travel']:+.1f} | "
                         f"{1e3 * c['energy_gain_max_J']:+.2f} | {c['energy_over_tolerance']}/{c['trials']} | "
                         f"{c['max_force_N']:.2f} |")
    if catch_couplings:
        lines += ["", f"Catch: a cube slides down a ramp into a finger held still (hard case 12a), {len(catch_phases)} "
                  f"world-clock phases per cell, worst phase shown; caught: never through the finger and on its own "
                  f"side at the end; settled: it moves less than {1e3 * CATCH_SETTLE_M:g} mm in the last "
                  f"{CATCH_SETTLE_S:g} s", "",
                  "| coupling | delay (ms) | caught | settled | arrived at (m/s) | left at (m/s) | motion in the last "
                  f"{CATCH_SETTLE_S:g} s (mm) | energy gain (mJ) | phases over tolerance | max force (N) | layer "
                  "withheld + damped (mJ) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for c in cells:
            if c["scene"] != "catch":
                continue
            lines.append(f"| {c['coupling']} | {ms_label(c['delay_ms'])} | {c['caught']}/{c['trials']} | "
                         f"{c['settled']}/{c['trials']} | {c['arrival_mps']:.2f} | {c['leaving_mps']:.2f} | "
                         f"{1e3 * c['settle_m']:.2f} | {1e3 * c['energy_gain_max_J']:+.1f} | "
                         f"{c['energy_over_tolerance']}/{c['trials']} | {c['max_force_N']:.2f} | "
                         f"{1e3 * c['layer_withheld_max_J']:.1f} |")
    if stack_couplings:
        lines += ["", f"Stack: five boxes of 1000:1 mass ratios pressed from above (hard case 8, `{STACK_TRAJECTORY}`), "
                  f"{len(stack_phases)} world-clock phases per cell, worst phase shown; held: every box within 1 mm "
                  f"of its rest pose", "",
                  "| coupling | delay (ms) | held | largest box displacement (mm) | energy gain (mJ) | phases over "
                  "tolerance | max force (N) | layer withheld + damped (mJ) |",
                  "|---|---|---|---|---|---|---|---|"]
        for c in cells:
            if c["scene"] != "stack":
                continue
            lines.append(f"| {c['coupling']} | {ms_label(c['delay_ms'])} | {c['held']}/{c['trials']} | "
                         f"{1e3 * c['displacement_m']:.3f} | {1e3 * c['energy_gain_max_J']:+.1f} | "
                         f"{c['energy_over_tolerance']}/{c['trials']} | {c['max_force_N']:.2f} | "
                         f"{1e3 * c['layer_withheld_max_J']:.1f} |")
    if grasp_couplings:
        lines += ["", f"Grasp and lift (thumb and index), {len(grasp_phases)} world-clock phases per cell, worst phase "
                  f"shown; hold window {GRASP_HOLD_S[0]:g}–{GRASP_HOLD_S[1]:g} s; held: the cube still at least half "
                  f"as high at the hold's end as at its start", "",
                  "| coupling | delay (ms) | held (phases) | lift at hold start (mm) | lift at hold end (mm) | slip in "
                  "hold (mm) | force peak-to-peak in hold (N) | max force (N) | energy gain (mJ) | phases over "
                  "tolerance |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for c in cells:
            if c["scene"] != "grasp":
                continue
            lines.append(f"| {c['coupling']} | {ms_label(c['delay_ms'])} | {c['held']}/{c['trials']} | "
                         f"{c['lift_mm']:.1f} | {c['lift_end_mm']:.1f} | {c['slip_mm']:.2f} | "
                         f"{c['hold_force_p2p_N']:.2f} | {c['max_force_N']:.2f} | "
                         f"{1e3 * c['energy_gain_max_J']:+.2f} | {c['energy_over_tolerance']}/{c['trials']} |")
    dropped = sum(c["link_dropped"] for c in cells)
    tolerance_mJ = 1e3 * max(c["energy_tolerance_J"] for c in cells)
    lines += ["", f"Energy tolerance (quadrature + contact slop): {tolerance_mJ:.2f} mJ at most. Delay-line entries "
              f"dropped over all trials: {dropped}."]
    table = "\n".join(lines)
    (args.out / "latency.md").write_text(table + "\n")
    print(table)

    if args.plot:
        os.environ.setdefault("MPLBACKEND", "Agg")
        import matplotlib.pyplot as plt
        # One categorical axis for every panel: the delays span 0 to 100 ms, too wide for a linear axis, and 0 has no
        # place on a logarithmic one.
        axis_delays = sorted(set(delays) | set(grasp_delays))
        fig, axes = plt.subplots(2, 3, figsize=(13, 6.6))
        # Bias and energy span four decades with signs: symmetric-log axes, linear within the energy tolerance
        # (10 mJ) and within 10 mm of the reference.
        panels = [(axes[0][0], "tap", "phase_spread_m", 1e3, "tap: phase spread of the stop (mm)", None),
                  (axes[0][1], "tap", "bias_m", 1e3, "tap: bias vs 1 kHz reference (mm)", 10.0),
                  (axes[0][2], "grasp", "lift_end_mm", 1.0, "grasp: lift at the hold's end, worst phase (mm)", None),
                  (axes[1][0], "both", "energy_gain_max_J", 1e3, "energy gain, worst phase (mJ)", 10.0),
                  (axes[1][1], "both", "max_force_N", 1.0, "largest finger force (N)", None),
                  (axes[1][2], "grasp", "hold_force_p2p_N", 1.0, "grasp: force peak-to-peak in the hold (N)", None)]
        colours = {"position": "tab:blue", "impulse": "tab:orange", "local": "tab:green"}
        for ax, scene, field, scale, label, linear_within in panels:
            for kind, kind_couplings, style in (("tap", couplings, "o-"), ("grasp", grasp_couplings, "s--")):
                if scene not in (kind, "both"):
                    continue
                for coupling in kind_couplings:
                    pairs = [(axis_delays.index(c["delay_ms"]), scale * c[field]) for c in cells
                             if c["scene"] == kind and c["coupling"] == coupling]
                    if pairs:
                        base, layer = coupling_and_layer(coupling)
                        ax.plot(*zip(*pairs), ("^:" if kind == "tap" else "v:") if layer else style, ms=4, lw=1.2,
                                color=colours.get(base), label=f"{kind}, {coupling}")
            if linear_within is not None:
                ax.set_yscale("symlog", linthresh=linear_within)
            ax.set_xticks(range(len(axis_delays)), [ms_label(d) for d in axis_delays])
            ax.set_xlabel("one-way link delay (ms)")
            ax.set_title(label, fontsize=10)
            ax.grid(alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=7)
        axes[0][1].axhline(0.0, color="k", lw=0.8)
        fig.suptitle(f"Link delay: tap (world {args.rate:g} Hz, {len(phases)} phases) and grasp "
                     f"({len(grasp_phases)} phases)")
        fig.tight_layout()
        fig.savefig(args.out / "latency.png", dpi=80)
        print(f"plot: {args.out / 'latency.png'}")

    if args.check:
        failures = []
        for c in cells:
            numbers = [v for k, v in c.items() if isinstance(v, float) and k != "ledger_error_max"]
            if not all(math.isfinite(v) for v in numbers):
                failures.append(f"{c['scene']} {c['coupling']} {ms_label(c['delay_ms'])} ms: a number is not finite")
        # Every trial whose coupling applies the rendered impulse (the reference included), one by one.
        for key, row in trials.items():
            scene, coupling, delay, phase = key[:4]
            error = row["ledger_error"]
            if error is not None and not error <= LEDGER_TOLERANCE:
                where = f"{scene} {coupling} {ms_label(delay)} ms" + (f" {loss_label(key[4])}" if len(key) > 4 else "")
                failures.append(f"{where} phase {phase}: the impulse applied differs from the impulse rendered by "
                                f"{error:.3g} (relative)")
        # Passivity: local coupling and the passivity layer gain no energy beyond a trial's tolerance at any delay, in
        # every scene (docs/latency.md; the grasp's gain beyond GRASP_PASSIVE_UP_TO_MS is open).
        for key, row in trials.items():
            scene, coupling, delay, phase = key[:4]
            passive = coupling == "local" or coupling.endswith("+layer")
            if not passive or (scene == "grasp" and delay > GRASP_PASSIVE_UP_TO_MS) or "energy_gain_J" not in row:
                continue
            if not row["energy_gain_J"] <= row["energy_tolerance_J"]:
                failures.append(f"{scene} {coupling} {ms_label(delay)} ms phase {phase}: energy gain "
                                f"{1e3 * row['energy_gain_J']:.2f} mJ over the tolerance "
                                f"{1e3 * row['energy_tolerance_J']:.2f} mJ")
        if failures:
            print("CHECK FAILED: " + "; ".join(failures))
            sys.exit(1)
        print("check passed")


if __name__ == "__main__":
    main()
