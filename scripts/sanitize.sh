#!/usr/bin/env bash
# Tests under AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer included): configures
# the `asan` preset (clang, -O1, asserts on; build/asan, which also holds the fuzz targets of
# scripts/fuzz.sh), builds what the tests need and runs them with ctest, without the tests
# labelled `slow` (too slow under ASan) or `tsan` (scripts/tsan.sh).
#
#   scripts/sanitize.sh [--all] [--build-only | --test-only] [ctest arguments...]
#
# Default (CI): the library without the hw engine (the preset's POSEFILTER_HW=OFF; the release
# tests cover it), the CLI and the tests of the file readers and the CLI: the ctest labels core,
# prior, eval and cli (every test that parses input or runs the `posefilter` binary). --all:
# the hw engine too (configured with POSEFILTER_HW=ON; the next default run configures it off
# again) and every test binary (render, filter, synth, view and hw too; about twice the time).
# Exits non-zero when a test fails or when any process, including a `posefilter` run started by
# a CLI test, wrote a sanitizer report (reports go to build/asan/sanitizer-logs/ and are
# printed). --build-only stops after the build, --test-only runs the tests of an earlier build
# (scripts/test.sh times the two apart). Extra arguments go to ctest (e.g. -R Mesh). See
# docs/RELIABILITY.md.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=${POSEFILTER_JOBS:-2}

if ! command -v clang++ >/dev/null; then
  echo "scripts/sanitize.sh: needs clang++ (scripts/setup.sh installs it)" >&2
  exit 2
fi
labels='core|prior|eval|cli'
targets=(posefilter_bin core_test prior_test eval_test cli_test)
configure=()
if [ "${1:-}" = --all ]; then
  shift
  labels=''
  targets=(all)
  configure=(-DPOSEFILTER_HW=ON)
fi
build=1
tests=1
case "${1:-}" in
  --build-only) tests=0; shift ;;
  --test-only) build=0; shift ;;
esac
if [ "$build" = 1 ]; then
  cmake --preset asan "${configure[@]}" >/dev/null
  cmake --build --preset asan --parallel "$jobs" --target "${targets[@]}"
fi
[ "$tests" = 1 ] || exit 0

logs=$root/build/asan/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
# halt_on_error: the first report ends the process (UB included: -fno-sanitize-recover=undefined).
# log_path: reports go to files, <prefix>.<pid>, so that one in a child process whose exit status
# a test expects to be non-zero is still seen. Leaks inside Debian's assimp (its OBJ importer's
# error path) are known and not ours: fuzz/lsan.supp.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:check_initialization_order=1:strict_init_order=1:detect_odr_violation=2:log_path=$logs/asan"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$logs/ubsan"
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0"

status=0
if [ -n "$labels" ]; then
  ctest --preset asan --timeout 900 -L "$labels" "$@" || status=$?
else
  ctest --preset asan --timeout 900 "$@" || status=$?
fi

shopt -s nullglob
reports=("$logs"/*)
if [ ${#reports[@]} -gt 0 ]; then
  echo "sanitize.sh: ${#reports[@]} sanitizer report(s):" >&2
  for f in "${reports[@]}"; do
    echo "==== $f" >&2
    cat "$f" >&2
  done
  exit 1
fi
[ "$status" -eq 0 ] && echo "scripts/sanitize.sh: every test passed with no sanitizer report"
exit "$status"
