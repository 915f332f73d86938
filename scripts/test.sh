#!/usr/bin/env bash
# Install dependencies, build, and run the whole test suite: the tests of the release build
# (ctest, Python included), then the unit and CLI tests under AddressSanitizer + UBSan
# (scripts/sanitize.sh) and a bounded fuzz run of every file reader (scripts/fuzz.sh,
# POSEFILTER_FUZZ_SECONDS per target, default 5). Arguments go to the release ctest.
# POSEFILTER_QUICK=1 stops after the release tests. docs/RELIABILITY.md.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# The benchmark programs are not built here: no test runs them (scripts/build.sh builds them).
POSEFILTER_BUILD_BENCH=OFF scripts/build.sh
ctest --preset release "$@"
if [ "${POSEFILTER_QUICK:-0}" = 1 ]; then
  exit 0
fi
scripts/sanitize.sh
scripts/fuzz.sh "${POSEFILTER_FUZZ_SECONDS:-5}" 2
