#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs what is missing and builds Impetus.
#   scripts/build.sh [--daemons] [BUILD_DIR [extra cmake -D options...]]     default BUILD_DIR: build (Release)
#   --daemons   build only world_manager, haptic_controller, spidar_sim and viewer (what the demo needs), not the tests
set -euo pipefail
case "${1:-}" in
  -h|--help) sed -n '3,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  --daemons|-D*|"") ;;
  -*) echo "build.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
targets=()
if [ "${1:-}" = "--daemons" ]; then
  targets=(--target world_manager haptic_controller spidar_sim viewer)
  shift
fi
build_dir="${1:-build}"
shift || true
bash scripts/deps.sh
cmake -S . -B "$build_dir" "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)" "${targets[@]}"
