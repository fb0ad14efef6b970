#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# CTest lists are ';'-separated: a Catch test whose name holds a ';' becomes two CTest tests that each match no test
# case and pass without running anything. A name that starts with '-' is taken by the test program for a flag, and its
# CTest test fails without running. This fails if any test program has such a name.
#   check_test_names.sh PROGRAM...
set -euo pipefail
status=0
for program in "$@"; do
  while IFS= read -r name; do
    echo "check_test_names: ${program##*/}: '$name' holds a ';' (CTest would run nothing for it)" >&2
    status=1
  done < <("$program" --list-test-names-only | grep ';' || true)
  while IFS= read -r name; do
    echo "check_test_names: ${program##*/}: '$name' starts with '-' (the program would take it for a flag)" >&2
    status=1
  done < <("$program" --list-test-names-only | grep '^-' || true)
done
((status == 0)) && echo "check_test_names: $# programs, no test name holds a ';' or starts with '-'"
exit "$status"
