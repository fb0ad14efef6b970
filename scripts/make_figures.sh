#!/usr/bin/env bash
# Regenerates the figures and tables the README shows (docs/*.png, docs/*.md) from real lockstep runs.
#   scripts/make_figures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh build >/dev/null
mkdir -p docs
# Fig. 5 of the paper: cube stop position against the world clock's phase, position vs impulse coupling.
/usr/bin/python3 scripts/phase_experiment.py --phases 25 --out out/figures/phase
cp out/figures/phase/phase_xt.png docs/phase_xt.png
cp out/figures/phase/phase.md docs/phase.md
# One tap trial, lockstep, impulse coupling: the cube face, the finger and the proxy.
bash scripts/run.sh --scene scenes/tap.json --trajectory tap --out out/figures/tap --quiet
/usr/bin/python3 scripts/plot_trial.py out/figures/tap --out docs/tap_trial.png
echo "figures written to docs/"
