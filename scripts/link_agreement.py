#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Does the real link agree with the lockstep model? The tap trial in real time over shared memory on one host and
over DDS between two network hosts (namespaces joined by a veth pair, scripts/netns_hosts.sh), against the same tap
in lockstep with no link delay over every phase of the world clock (a real-time run starts at a random phase).

Prints, per coupling, the model's band of stop positions (min, max over the phases) at each one-way link delay of
--delays-ms (the in-process delay line, docs/latency.md), every real-time run's stop position, and how many runs fall
within each band widened by --margin-mm: the delays whose band holds the runs are those the real link behaves like.
Writes OUT/link_agreement.md. Needs root (network namespaces).
"""
import argparse
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from impetus_py.paths import ROOT, build_dir  # noqa: E402
from impetus_py.trial import run_trial  # noqa: E402


def hosts(action, tag):
    script = f'source "{ROOT}/scripts/netns_hosts.sh"; ' + (f"make_hosts {tag}" if action == "up" else
                                                          f"world_ns={tag}w hands_ns={tag}h; remove_hosts")
    return subprocess.run(["bash", "-c", script]).returncode == 0


def stop(process, name):
    process.send_signal(signal.SIGTERM)
    if process.wait(timeout=20) != 0:
        raise RuntimeError(f"{name} exited with status {process.returncode}")


def realtime_trial(out, scene, coupling, link, tag):
    """One real-time tap: 'shm' all on this host, 'dds' world on one namespace host, hands on the other."""
    out.mkdir(parents=True, exist_ok=True)
    build = build_dir()
    world_ns = ["ip", "netns", "exec", f"{tag}w"] if link == "dds" else []
    hands_ns = ["ip", "netns", "exec", f"{tag}h"] if link == "dds" else []
    shm = f"{tag}_{out.name}"
    flags = ["--clock", "realtime"] + (["--link", "dds", "--dds-partition", shm] if link == "dds" else [])
    with open(out / "world.out", "w") as world_log, open(out / "haptic.out", "w") as haptic_log, \
            open(out / "device.out", "w") as device_log:
        world = subprocess.Popen(world_ns + [str(build / "world_manager/world_manager"), "--scene", str(scene),
                                             "--coupling", coupling, "--shm", shm, "--summary",
                                             str(out / "world.json"), *flags], stdout=world_log, stderr=world_log)
        haptic = subprocess.Popen(hands_ns + [str(build / "haptic_controller/haptic_controller"), "--shm", shm,
                                              "--summary", str(out / "haptic.json"), *flags],
                                  stdout=haptic_log, stderr=haptic_log)
        device = subprocess.Popen(hands_ns + [str(build / "spidar_sim/spidar_sim"), "--clock", "realtime", "--shm",
                                              shm, "--trajectory", "tap", "--attach-timeout", "30"],
                                  stdout=device_log, stderr=device_log)
        if device.wait(timeout=120) != 0:
            raise RuntimeError(f"spidar_sim failed: see {out}/device.out")
        time.sleep(0.5)  # the cube slides on after the finger has left; let it come to rest as the world sees it
        stop(haptic, "haptic_controller")
        stop(world, "world_manager")
    world_summary = json.loads((out / "world.json").read_text())
    return world_summary["objects"]["cube"]["position"][0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="real-time runs per coupling and link")
    parser.add_argument("--couplings", default="position,impulse,local")
    parser.add_argument("--phases", type=int, default=10, help="model phases over one world period")
    parser.add_argument("--delays-ms", default="0,1,2", help="model link delays (one way), ms")
    parser.add_argument("--margin-mm", type=float, default=2.0,
                        help="a run agrees if within this of the model's band (real time adds host jitter)")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "out/link_agreement")
    args = parser.parse_args()
    if os.geteuid() != 0:
        sys.exit("link_agreement: network namespaces need root")
    scene = ROOT / "scenes/tap.json"
    delays_ms = [float(d) for d in args.delays_ms.split(",")]
    margin_m = args.margin_mm / 1e3
    tag = f"ila{os.getpid() % 100000}"
    if not hosts("up", tag):
        hosts("down", tag)
        sys.exit("link_agreement: cannot make network namespaces here")
    rows = []
    try:
        for coupling in args.couplings.split(","):
            period_ticks = 50  # the tap scene's 20 Hz world at 1 kHz
            bands = []
            for delay_ms in delays_ms:
                model = [run_trial(args.out / f"model-{coupling}-{delay_ms:g}ms-{p}", scene, "tap", coupling,
                                   phase_ticks=p * period_ticks // args.phases,
                                   link_delay_s=delay_ms / 1e3).final_position_m("cube")[0]
                         for p in range(args.phases)]
                bands.append((min(model), max(model)))
            for link in ("shm", "dds"):
                stops = [realtime_trial(args.out / f"{link}-{coupling}-{k}", scene, coupling, link, tag)
                         for k in range(args.runs)]
                inside = [sum(low - margin_m <= x <= high + margin_m for x in stops) for low, high in bands]
                rows.append((coupling, link, bands, stops, inside))
                print(f"{coupling:8s} {link}: real time {', '.join(f'{x:.4f}' for x in stops)} m; within the model's "
                      f"band at " + ", ".join(f"{d:g} ms ({low:.4f}..{high:.4f}): {n}/{len(stops)}"
                                              for d, (low, high), n in zip(delays_ms, bands, inside)), flush=True)
    finally:
        hosts("down", tag)
    header = "| coupling | link | real-time stops (m) | " + " | ".join(
        f"model band at {d:g} ms (m): runs within ± {args.margin_mm:g} mm" for d in delays_ms) + " |"
    lines = [header, "|" + "---|" * (3 + len(delays_ms))]
    for coupling, link, bands, stops, inside in rows:
        where = "shared memory, one host" if link == "shm" else "DDS, two hosts (veth)"
        cells = [f"{low:.4f} – {high:.4f}: {n}/{len(stops)}" for (low, high), n in zip(bands, inside)]
        lines.append(f"| {coupling} | {where} | {', '.join(f'{x:.4f}' for x in stops)} | " + " | ".join(cells) + " |")
    (args.out / "link_agreement.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
