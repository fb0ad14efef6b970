#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs what is missing, configures, builds and runs the whole test suite (CTest).
#   scripts/test.sh                      Release build in build/
#   scripts/test.sh --sanitize address   ASan+UBSan build in build-address/
#   scripts/test.sh --sanitize thread    TSan build in build-thread/
# Extra arguments after -- go to ctest (e.g. -- -R seqlock).
set -euo pipefail
cd "$(dirname "$0")/.."

sanitize=""
ctest_args=()
while (($#)); do
  case "$1" in
    --sanitize) sanitize="${2:?--sanitize needs address or thread}"; shift 2 ;;
    --sanitize=*) sanitize="${1#*=}"; shift ;;
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --) shift; ctest_args=("$@"); break ;;
    *) echo "test.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$sanitize" in
  ""|address|thread) ;;
  *) echo "test.sh: --sanitize must be address or thread, not '$sanitize'" >&2; exit 2 ;;
esac

build_dir=build${sanitize:+-$sanitize}
build_type=Release
[ -n "$sanitize" ] && build_type=RelWithDebInfo
bash scripts/deps.sh --browser
bash scripts/build.sh "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" -DIMPETUS_SANITIZE="$sanitize"
cd "$build_dir"
ctest --output-on-failure --timeout 600 -j"$(nproc)" "${ctest_args[@]}"
