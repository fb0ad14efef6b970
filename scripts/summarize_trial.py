#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Merges one trial's per-process summaries into DIR/summary.json (docs/architecture.md §4) and prints the outcome.

usage: summarize_trial.py DIR [--set key=value ...] [--quiet]
"""
import argparse
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py import summary  # noqa: E402


def load(path):
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError) as error:
        sys.exit(f"summarize_trial: cannot read {path}: {error}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", type=pathlib.Path)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a config entry of the trial")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args()

    entries = {key: value for key, _, value in (item.partition("=") for item in args.set)}
    haptic = load(args.dir / summary.HAPTIC_FILE_NAME)
    # A device simulated inside the haptic controller (the web hand) has no process and no file of its own: its
    # figures are the haptic controller's "device".
    device_file = args.dir / summary.DEVICE_FILE_NAME
    device = load(device_file) if device_file.exists() else {"device": haptic["haptic"].get("device", {})}
    merged = summary.merge(load(args.dir / summary.WORLD_FILE_NAME), haptic, device, entries)
    # Other users on the same world (run.sh --user): userU.haptic.json and userU.device.json, U = 1, 2, ...
    followers = []
    while (args.dir / f"user{len(followers) + 1}.haptic.json").exists():
        u = len(followers) + 1
        followers.append({**load(args.dir / f"user{u}.haptic.json"), **load(args.dir / f"user{u}.device.json")})
    if followers:
        merged["followers"] = followers
    (args.dir / summary.FILE_NAME).write_text(summary.to_json(merged))

    if args.quiet:
        return
    config = merged["config"]
    print(f"trial: {config.get('scene')} / {config.get('trajectory')} / {config.get('coupling')} coupling, "
          f"{config.get('clock')} clock, world {config.get('world_rate_hz')} Hz, phase {config.get('phase_ticks')}")
    for name, obj in merged["objects"].items():
        x, y, z = obj["position"]
        jx, jy, jz = obj["impulse_Ns"]
        print(f"  {name:12s} final position [{x:+.4f} {y:+.4f} {z:+.4f}] m   "
              f"impulse delivered [{jx:+.4f} {jy:+.4f} {jz:+.4f}] N·s")
    h, w = merged["haptic"], merged["world"]
    print(f"  haptic: {h['ticks']} ticks, max force {h['max_force_N']:.2f} N, faults {h['faults']}, "
          f"force clamps {h['force_clamps']}, saturations {h['saturations']}, skipped periods {h['skipped_periods']}, "
          f"lateness p50/p99/max {h['lateness_p50_ns'] / 1e3:.0f}/{h['lateness_p99_ns'] / 1e3:.0f}/"
          f"{h['lateness_max_ns'] / 1e3:.0f} µs")
    if merged["device"].get("kind") == "web":
        d = merged["device"]
        print(f"  web hand: taken {d['holds']} time(s), let go {d['releases']} time(s) when told and "
              f"{d['timeouts']} on silence; force off within {d['max_release_delay_s'] * 1e3:.1f} ms of a page's end")
    print(f"  world:  {w['steps']} steps, {w['time_s']:.3f} s simulated, skipped periods {w['skipped_periods']}, "
          f"rejected reports {w['rejected_reports']}")
    written = "logs and summary.json" if any(pathlib.Path(args.dir).glob("*.csv")) else "summary.json (no logs)"
    print(f"  wall time {config.get('wall_time_s', 0):.2f} s; {written} in {args.dir}")


if __name__ == "__main__":
    main()
