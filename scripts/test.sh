#!/usr/bin/env bash
# Install dependencies, build, and run the whole test suite: clang-tidy on the C++ files of the
# last commit (scripts/tidy.sh), the tests of the release build (ctest, Python included), then
# the unit and CLI tests under AddressSanitizer + UBSan (scripts/sanitize.sh) and a bounded
# fuzz run of every file reader (scripts/fuzz.sh, POSEFILTER_FUZZ_SECONDS per target, default 5).
# Arguments go to the release ctest.
# POSEFILTER_QUICK=1 stops after the release tests. Ends with the wall time of each phase.
# docs/RELIABILITY.md.
set -euo pipefail
cd "$(dirname "$0")/.."

phases=()
started=$SECONDS
# run NAME COMMAND...: one phase, timed; its time is printed at the end (also on failure).
run() {
  local name=$1 t0=$SECONDS rc=0
  shift
  "$@" || rc=$?
  phases+=("$(printf '%-34s %5d s%s' "$name" $((SECONDS - t0)) "$([ "$rc" -ne 0 ] && echo "  (failed: exit $rc)")")")
  return "$rc"
}
summary() {
  local rc=$?
  echo
  echo "scripts/test.sh: time per phase"
  for p in "${phases[@]}"; do echo "  $p"; done
  printf '  %-34s %5d s\n' total $((SECONDS - started))
  exit "$rc"
}
trap summary EXIT

run "setup (apt packages)" scripts/setup.sh
# The benchmark programs are not built here: no test runs them (scripts/build.sh builds them).
# The CLI and the test binaries as unity builds (CMake option POSEFILTER_UNITY): half their compile time.
# The SystemC differential test of the HLS types is labelled `long` and not built here.
run "release build" env POSEFILTER_BUILD_BENCH=OFF POSEFILTER_UNITY=ON POSEFILTER_SYSTEMC_TESTS=OFF scripts/build.sh
# clang-tidy (.clang-tidy) on the C++ sources the last commit changed, with the release build's
# compile commands (scripts/tidy.sh; a clone without history has no last commit to compare with).
run "clang-tidy (changed files)" scripts/tidy.sh
# Tests labelled `long` (a few full-scale runs whose lighter versions are in the suite) run
# outside CI's budget: ctest --preset release -L long. docs/RELIABILITY.md lists the labels.
run "release tests (ctest)" ctest --preset release -LE long "$@"
if [ "${POSEFILTER_QUICK:-0}" = 1 ]; then
  exit 0
fi
run "asan build" scripts/sanitize.sh --build-only
run "asan tests" scripts/sanitize.sh --test-only
run "fuzzing (fuzz.sh)" scripts/fuzz.sh "${POSEFILTER_FUZZ_SECONDS:-5}" 2
