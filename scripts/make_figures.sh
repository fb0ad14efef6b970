#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Regenerates the figures and tables docs/results.md shows (docs/*.png, docs/*.md) from real lockstep runs.
#   scripts/make_figures.sh
set -euo pipefail
case "${1:-}" in
  -h|--help) sed -n '3,4p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  "") ;;
  *) echo "make_figures.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
bash scripts/build.sh build >/dev/null
mkdir -p docs
# Fig. 5 of the paper: cube stop position against the world clock's phase, position vs impulse coupling.
/usr/bin/python3 scripts/phase_experiment.py --phases 25 --couplings position,impulse,local --out out/figures/phase
cp out/figures/phase/phase_xt.png docs/phase_xt.png
cp out/figures/phase/phase.md docs/phase.md
# One tap trial, lockstep, impulse coupling: the cube face, the finger and the proxy.
bash scripts/run.sh --scene scenes/tap.json --trajectory tap --out out/figures/tap --quiet
/usr/bin/python3 scripts/plot_trial.py out/figures/tap --out docs/tap_trial.png
# Figs. 7/8 of the paper: a simulated subject learning the tap task with each coupling.
/usr/bin/python3 scripts/tap_task.py --methods position,impulse,local --out out/figures/tap_task
cp out/figures/tap_task/tap_task.png docs/tap_task.png
cp out/figures/tap_task/tap_task.md docs/tap_task.md
# Grasp and lift with two fingers under each coupling (hard case 14): height and forces, lift over 5 world phases.
/usr/bin/python3 scripts/grasp_figure.py --out out/figures/grasp
cp out/figures/grasp/grasp.png docs/grasp.png
cp out/figures/grasp/grasp.md docs/grasp.md
# A finger sliding off a box's edge between world frames: planes as sent against planes taken again every tick.
/usr/bin/python3 scripts/edge_figure.py --out out/figures/edge
cp out/figures/edge/edge_release.png docs/edge_release.png
# One-way delay on the world link: the tap under each coupling and the grasp, in-process (docs/latency.md).
/usr/bin/python3 scripts/latency_experiment.py --out out/figures/latency
cp out/figures/latency/latency.png docs/latency.png
cp out/figures/latency/latency.md docs/latency_table.md
# Deformation from integrated force against the previous method (paper §6.4, docs/deformation.md).
/usr/bin/python3 scripts/deformation_experiment.py --out out/figures/deformation
cp out/figures/deformation/deformation.png docs/deformation.png
cp out/figures/deformation/deformation.md docs/deformation_table.md
/usr/bin/python3 scripts/deformation_experiment.py --scene scenes/gel.json --out out/figures/deformation-gel
cp out/figures/deformation-gel/deformation.png docs/deformation_gel.png
cp out/figures/deformation-gel/deformation.md docs/deformation_gel_table.md
# The phase experiment and the hard cases on every engine (docs/engines.md).
/usr/bin/python3 scripts/engines.py --quiet --out out/figures/engines --doc docs/engines.md
# The viewer replaying a lockstep tap trial at its hardest push, in headless Chromium (the browser test's replay case
# takes the picture).
bash scripts/deps.sh --browser
node tests/viewer/viewer_test.mjs --build build --case replay --picture docs/viewer_tap.png
# The page as an input device: a pointer pushing the cube through the web hand (the touch test's drag case).
node tests/viewer/touch_test.mjs --build build --case drag --picture docs/touch_page.png
echo "figures written to docs/ (speed vs error: scripts/speed_vs_error.py --docs; hard cases: scripts/hard_cases.py)"
