#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job: on a fresh Debian machine, installs what is missing, builds, and runs the paper's tap trial in real
# time (world manager at 20 Hz with impulse coupling, 1 kHz haptic controller, simulated SPIDAR and finger), prints
# the outcome and writes a plot of the cube and the finger over time to out/demo/trial.png. A viewer serves the trial
# live at http://127.0.0.1:8080/ (the finger waits 5 s for you to open it); afterwards the demo says how to replay it.
#   scripts/demo.sh [extra scripts/run.sh arguments, e.g. --coupling position or --view-listen 127.0.0.1:9000]
#   scripts/demo.sh --interactive [extra run.sh arguments]
# --interactive: you are the finger. A playground scene (scenes/playground.json) with local coupling, steered from
# the page at the address it prints (drag to move the finger, wheel for depth); Ctrl-C ends it, then the outcome and
# out/demo-interactive/trial.png.
set -euo pipefail
interactive=0
args=()
for arg in "$@"; do
  case "$arg" in
    -h|--help) sed -n '3,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --interactive) interactive=1 ;;
    *) args+=("$arg") ;;
  esac
done
cd "$(dirname "$0")/.."
bash scripts/build.sh --daemons build
if ((interactive)); then
  out=out/demo-interactive
  rm -rf "$out"
  bash scripts/run.sh --scene scenes/playground.json --device web --coupling local --out "$out" "${args[@]}"
else
  out=out/demo
  rm -rf "$out"
  bash scripts/run.sh --scene scenes/tap.json --trajectory tap --clock realtime --coupling impulse --out "$out" \
    --view --view-wait 5 "${args[@]}"
fi
MPLBACKEND=Agg /usr/bin/python3 scripts/plot_trial.py "$out" --out "$out/trial.png"
