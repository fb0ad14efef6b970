#!/usr/bin/env bash
# Installs what is missing and builds Impetus.
#   scripts/build.sh [BUILD_DIR [extra cmake -D options...]]     default BUILD_DIR: build (Release)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"
shift || true
bash scripts/deps.sh
cmake -S . -B "$build_dir" "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
