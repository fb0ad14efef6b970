#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian packages Impetus builds and runs with, skipping those already present, and the viewer's page
# (three.js, pinned by viewer/web/package-lock.json) from the npm registry.
#   scripts/deps.sh             what the build, the demo and the viewer need
#   scripts/deps.sh --browser   also Chromium and Playwright, for the viewer's browser tests (scripts/test.sh)
# Run by scripts/build.sh and scripts/test.sh; safe to run alone.
set -euo pipefail
cd "$(dirname "$0")/.."
browser=0
case "${1:-}" in
  -h|--help) sed -n '3,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  --browser) browser=1 ;;
  "") ;;
  *) echo "deps.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
esac
IMPETUS_PACKAGES=(cmake g++ make pkg-config libeigen3-dev libode-dev libbullet-dev libboost-dev catch2 nlohmann-json3-dev
                  libcli11-dev python3-matplotlib python3-numpy python3-tqdm
                  pybind11-dev python3-dev  # the impetus Python module (python/)
                  libassimp-dev  # users' mesh files: OBJ, STL and more (common/mesh)
                  cyclonedds-dev cyclonedds-tools  # the world link over DDS (common/link/dds; idlc)
                  iproute2  # network namespaces: the DDS tests' and benchmark's two hosts
                  openssl  # the secured DDS link's certificates and signed documents (scripts/dds_security.sh)
                  curl  # the install test fetches the installed viewer's page
                  time  # /usr/bin/time: each process's peak RSS in scripts/bench.sh
                  valgrind)  # callgrind: the haptic tick's instruction counts in scripts/bench.sh
# The viewer's page comes from the npm registry; a machine without Node.js gets Debian's.
command -v npm >/dev/null || IMPETUS_PACKAGES+=(nodejs npm)
((browser)) && IMPETUS_PACKAGES+=(chromium fonts-liberation)  # headless, driven by Playwright in tests/viewer; a font for the page's text
missing=()
for pkg in "${IMPETUS_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
done
if ((${#missing[@]})); then
  echo "deps: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# npm ci installs exactly what the lock file pins, and only when it is not there yet.
npm_install() {
  local dir="$1" marker="$2"
  [ -e "$dir/node_modules/$marker" ] && return 0
  echo "deps: npm ci in $dir"
  npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error >/dev/null
}
npm_install viewer/web three/build/three.module.js
((browser)) && npm_install tests/viewer playwright-core/package.json
exit 0
