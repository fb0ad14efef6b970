#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job: on a fresh Debian machine, installs what is missing, builds, and runs the paper's tap trial in real
# time (world manager at 20 Hz with impulse coupling, 1 kHz haptic controller, simulated SPIDAR and finger), prints
# the outcome and writes a plot of the cube and the finger over time to out/demo/trial.png. A viewer serves the trial
# live at http://127.0.0.1:8080/ (the finger waits 5 s for you to open it); afterwards the demo says how to replay it.
#   scripts/demo.sh [extra scripts/run.sh arguments, e.g. --coupling position or --view-listen 127.0.0.1:9000]
set -euo pipefail
for arg in "$@"; do
  case "$arg" in -h|--help) sed -n '3,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
done
cd "$(dirname "$0")/.."
bash scripts/build.sh --daemons build
out=out/demo
rm -rf "$out"
bash scripts/run.sh --scene scenes/tap.json --trajectory tap --clock realtime --coupling impulse --out "$out" \
  --view --view-wait 5 "$@"
MPLBACKEND=Agg /usr/bin/python3 scripts/plot_trial.py "$out" --out "$out/trial.png"
