#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# What a user of the library does: install Impetus into a prefix, build the example project against the installed
# package (find_package(Impetus 0.2)), run it; import the Python package from the prefix and run a trial with a
# shipped scene; check the pkg-config file; make the Debian packages (impetus, the runtime; impetus-dev, headers and
# libraries), check that the runtime depends on no -dev package, unpack both into a scratch root (dpkg -x) and run a
# daemon, the viewer, the Python package and pkg-config from it.
# usage: install_test.sh SOURCE_DIR BUILD_DIR SCRATCH_DIR [PYTHON]   (PYTHON 0: the build has no Python package)
set -euo pipefail
src=$1 build=$2 scratch=$3 python=${4:-1}
rm -rf "$scratch" && mkdir -p "$scratch"
prefix="$scratch/prefix"

cmake --install "$build" --prefix "$prefix" > "$scratch/install.log"
for file in bin/impetus-world-manager bin/impetus-haptic-controller bin/impetus-spidar-sim lib/cmake/Impetus/ImpetusConfig.cmake lib/cmake/Impetus/ImpetusConfigVersion.cmake \
            lib/pkgconfig/impetus.pc include/impetus/loop/in_process_trial.h share/impetus/scenes/tap.json \
            share/impetus/desktop_spidar.json share/impetus/desktop_grip.json bin/impetus-viewer \
            share/impetus/viewer/web/index.html \
            share/impetus/viewer/web/node_modules/three/build/three.module.js; do
  [ -e "$prefix/$file" ] || { echo "install_test: $prefix/$file was not installed" >&2; exit 1; }
done

cmake -S "$src/examples/in_process_trial" -B "$scratch/example" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release > "$scratch/example-configure.log"
cmake --build "$scratch/example" -j2 > "$scratch/example-build.log"
"$scratch/example/in_process_trial" "$scratch"

# A version the package does not provide is refused.
mkdir -p "$scratch/too_new"
printf 'cmake_minimum_required(VERSION 3.20)\nproject(t LANGUAGES CXX)\nfind_package(Impetus 9.0 REQUIRED)\n' \
  > "$scratch/too_new/CMakeLists.txt"
if cmake -S "$scratch/too_new" -B "$scratch/too_new/build" -DCMAKE_PREFIX_PATH="$prefix" > /dev/null 2>&1; then
  echo "install_test: find_package(Impetus 9.0) was accepted" >&2; exit 1
fi

# The installed Python package, run from a directory that holds no other copy of it.
python_trial() {
  ((python)) || return 0
  [ -e "$1/lib/python3/dist-packages/impetus/__init__.py" ] || { echo "install_test: no Python package in $1" >&2; exit 1; }
  (cd "$scratch" && PYTHONPATH="$1/lib/python3/dist-packages" /usr/bin/python3 -c '
import impetus, sys
assert impetus.__file__.startswith(sys.argv[1]), impetus.__file__
trial = impetus.run_trial(impetus.shipped_scene("tap"), "tap", coupling="local", logs=False)
x = trial.summary["objects"]["cube"]["position"][0]
assert x > 0.05, trial  # the tap pushed the cube along +x
print(trial)' "$1")
}
python_trial "$prefix"

# The installed viewer finds its page and three.js in the prefix (no source tree, no network).
viewer_serves() {
  # Long enough to outlast a loaded machine's start-up and requests; stopped below once they are answered. The output
  # file exists before the viewer starts: the background shell may open it after the first look below, and a sed
  # that cannot read it would end this script (set -e).
  : > "$scratch/viewer.out"
  "$1/bin/impetus-viewer" --shm "impetus_install_test_$$" --listen 127.0.0.1:0 --duration 60 > "$scratch/viewer.out" 2>&1 &
  local pid=$! url=""
  for _ in $(seq 100); do
    url=$(sed -n 's/.*serving \(http[^ ]*\).*/\1/p' "$scratch/viewer.out")
    [ -n "$url" ] && break
    sleep 0.05
  done
  [ -n "$url" ] || { cat "$scratch/viewer.out" >&2; echo "install_test: the installed viewer did not start" >&2; exit 1; }
  for target in "" viewer.js touch.js tool.js touch_worker.js three/build/three.module.js three/build/three.core.js \
                three/examples/jsm/controls/OrbitControls.js; do
    # What this checks is that the installed files are served (the viewer's own tests time it): on a machine busy
    # with the rest of the suite, a connection refused or reset is retried twice before it counts, and a failure
    # says what curl saw and what the viewer printed.
    local code=0 status=0
    code=$(curl -s -o /dev/null -w '%{http_code}' --retry 2 --retry-connrefused --retry-delay 1 --max-time 20 \
           "$url$target") || status=$?
    if [ "$status" -ne 0 ] || [ "$code" != 200 ]; then
      cat "$scratch/viewer.out" >&2
      local alive="still running"
      if ! kill -0 "$pid" 2> /dev/null; then
        local exit_status=0
        wait "$pid" || exit_status=$?
        alive="exited with status $exit_status"
      fi
      echo "install_test: the installed viewer does not serve /$target (curl exit $status, HTTP $code; the viewer" \
           "$alive)" >&2
      exit 1
    fi
  done
  kill -TERM "$pid"
  local status=0
  wait "$pid" || status=$?
  # A stop request ends the viewer with 0 (143 if the signal arrived before its handler was installed).
  [ "$status" -eq 0 ] || [ "$status" -eq 143 ] || { cat "$scratch/viewer.out" >&2; echo "install_test: the viewer exited $status" >&2; exit 1; }
}
viewer_serves "$prefix"

# pkg-config names the prefix the files were installed into (not the configured /usr/local), in a prefix and in the
# unpacked DEB alike: its include and lib directories hold the headers and libraries.
pkg_config_finds() {  # pkg_config_finds PKGCONFIG_DIR
  local includedir libdir
  PKG_CONFIG_PATH="$1" pkg-config --cflags --libs impetus | grep -q -- "-limpetus_loop" ||
    { echo "install_test: pkg-config in $1 does not list -limpetus_loop" >&2; exit 1; }
  includedir="$(PKG_CONFIG_PATH="$1" pkg-config --variable=includedir impetus)"
  libdir="$(PKG_CONFIG_PATH="$1" pkg-config --variable=libdir impetus)"
  [ -f "$includedir/loop/in_process_trial.h" ] && [ -f "$libdir/libimpetus_loop.a" ] ||
    { echo "install_test: pkg-config in $1 points to $includedir and $libdir, which lack the files" >&2; exit 1; }
}
pkg_config_finds "$prefix/lib/pkgconfig"

(cd "$build" && cpack -G DEB -B "$scratch/deb" > "$scratch/cpack.log")
deb=$(ls "$scratch"/deb/impetus_*.deb)
dev_deb=$(ls "$scratch"/deb/impetus-dev_*.deb)
# The runtime package needs no development package; the -dev one needs the runtime and the headers' -dev packages.
if dpkg-deb -f "$deb" Depends | grep -q -- "-dev"; then
  echo "install_test: $(basename "$deb") depends on -dev packages: $(dpkg-deb -f "$deb" Depends)" >&2
  exit 1
fi
dpkg-deb -f "$dev_deb" Depends | grep -q "impetus (= " ||
  { echo "install_test: $(basename "$dev_deb") does not depend on impetus: $(dpkg-deb -f "$dev_deb" Depends)" >&2; exit 1; }
# apt resolves both from this machine's repositories as `apt-get install ./impetus_*.deb ./impetus-dev_*.deb` would:
# a dry run (nothing is installed), which fails on a dependency no configured repository has.
if command -v apt-get >/dev/null; then
  apt-get install --simulate --no-install-recommends "$deb" "$dev_deb" > "$scratch/apt.log" 2>&1 ||
    { echo "install_test: apt-get cannot install the packages:" >&2; cat "$scratch/apt.log" >&2; exit 1; }
  grep -q "^Inst impetus " "$scratch/apt.log" && grep -q "^Inst impetus-dev " "$scratch/apt.log" ||
    { echo "install_test: apt-get's dry run does not install both:" >&2; cat "$scratch/apt.log" >&2; exit 1; }
fi
# Maintainer: a name and an address, as Debian's policy requires (§5.6.2).
dpkg-deb -f "$deb" Maintainer | grep -Eq '^[^<]+ <[^@> ]+@[^> ]+>$' ||
  { echo "install_test: $(basename "$deb") has no 'Name <address>' maintainer: $(dpkg-deb -f "$deb" Maintainer)" >&2
    exit 1; }
dpkg -x "$deb" "$scratch/root"
"$scratch/root/usr/bin/impetus-world-manager" --help | grep -q -- "--scene"
python_trial "$scratch/root/usr"
viewer_serves "$scratch/root/usr"
[ ! -e "$scratch/root/usr/include" ] || { echo "install_test: the runtime package ships headers" >&2; exit 1; }
dpkg -x "$dev_deb" "$scratch/root"
pkg_config_finds "$(dirname "$(find "$scratch/root/usr" -name impetus.pc | head -1)")"
echo "install_test: installed, example built and ran, packages $(basename "$deb") $(du -k "$deb" | cut -f1) KiB" \
     "and $(basename "$dev_deb") $(du -k "$dev_deb" | cut -f1) KiB"
