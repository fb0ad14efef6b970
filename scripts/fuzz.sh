#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds the libFuzzer targets with clang (ASan+UBSan) in build-fuzz/ and fuzzes each for SECONDS (default 60).
#   scripts/fuzz.sh [SECONDS] [TARGET...]     targets: scene trajectory_csv trajectory_spec frames view (default: all)
# Each run starts from fuzz/corpus/<target> and fuzz/regressions/<target> (read only) and grows a working corpus in
# build-fuzz/corpus/<target>. A crash or failed invariant stops that target, leaves the input in
# build-fuzz/artifacts/<target>/ and makes the script exit non-zero after the remaining targets ran; to keep it as a
# regression test, fix the bug and copy the input to fuzz/regressions/<target>/.
# Needs clang and libclang-rt-<version>-dev (not in scripts/deps.sh: the default test suite replays the corpus with
# g++ and does not need them).
set -euo pipefail
case "${1:-}" in -h|--help) sed -n '3,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
cd "$(dirname "$0")/.."

seconds=60
if (($#)) && [[ "$1" =~ ^[0-9]+$ ]]; then
  seconds=$1
  shift
fi
all_targets=(scene trajectory_csv trajectory_spec frames view)
targets=("$@")
((${#targets[@]})) || targets=("${all_targets[@]}")
for target in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $target "* ]] || { echo "fuzz.sh: unknown target '$target' (known: ${all_targets[*]})" >&2; exit 2; }
done
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-dev)" >&2; exit 2; }

build_dir=build-fuzz
# RelWithDebInfo: optimised like the shipped code (so the fuzzer is fast) with line numbers in the stack traces.
CC=clang CXX=clang++ cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIMPETUS_FUZZ=ON \
  -DIMPETUS_BENCHMARKS=OFF >/dev/null
# -j2: the fuzz build shares the machine; only the fuzzers are built, not the daemons.
cmake --build "$build_dir" -j2 --target "${targets[@]/#/fuzz_}"

# PlaneFrame is ~23 kB: let the frame fuzzer grow inputs that fill all 64 planes (plus the selector byte).
declare -A max_len=([scene]=8192 [trajectory_csv]=4096 [trajectory_spec]=512 [frames]=32768 [view]=16384)
failed=()
for target in "${targets[@]}"; do
  work="$build_dir/corpus/$target"
  artifacts="$build_dir/artifacts/$target"
  mkdir -p "$work" "$artifacts"
  dict=()
  [ -f "fuzz/dicts/$target.dict" ] && dict=(-dict="fuzz/dicts/$target.dict")
  echo "=== fuzz_$target for ${seconds}s"
  # The first corpus directory receives new inputs; the seed and regression directories after it are only read.
  if ! "$build_dir/fuzz/fuzz_$target" -max_total_time="$seconds" -max_len="${max_len[$target]}" -timeout=10 \
      -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" \
      "$work" "fuzz/corpus/$target" "fuzz/regressions/$target" 2>"$build_dir/fuzz_$target.log"; then
    failed+=("$target")
    tail -n 40 "$build_dir/fuzz_$target.log" >&2
    echo "fuzz.sh: fuzz_$target FAILED; input saved in $artifacts/ (log: $build_dir/fuzz_$target.log)" >&2
  else
    grep -E '^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)' \
      "$build_dir/fuzz_$target.log" || true
  fi
done
if ((${#failed[@]})); then
  echo "fuzz.sh: failures in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz.sh: no crashes in ${targets[*]} (${seconds}s each)"
