#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian packages Impetus builds and runs with, skipping those already present.
# Sourced by scripts/test.sh and scripts/demo.sh; safe to run alone.
set -euo pipefail
IMPETUS_PACKAGES=(cmake g++ make pkg-config libeigen3-dev libode-dev libboost-dev catch2 nlohmann-json3-dev
                  libcli11-dev python3-matplotlib python3-numpy python3-tqdm
                  pybind11-dev python3-dev  # the impetus Python module (python/)
                  time)  # /usr/bin/time: each process's peak RSS in scripts/bench.sh
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
