#!/usr/bin/env bash
# Configures and builds the release preset (library, CLI, tests, benchmarks).
# POSEFILTER_BUILD_BENCH=OFF leaves the Google Benchmark programs out (scripts/test.sh: no test
# runs them); every other run builds them again. POSEFILTER_UNITY=ON compiles the CLI and the
# test binaries as unity builds (scripts/test.sh: half their compile time; OFF again on the next
# run without it). POSEFILTER_SYSTEMC_TESTS=OFF leaves out the SystemC differential test of the HLS
# types (label `long`; scripts/test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release -DPOSEFILTER_BUILD_BENCH="${POSEFILTER_BUILD_BENCH:-ON}" \
  -DPOSEFILTER_UNITY="${POSEFILTER_UNITY:-OFF}" -DPOSEFILTER_SYSTEMC_TESTS="${POSEFILTER_SYSTEMC_TESTS:-ON}" >/dev/null
cmake --build --preset release

# `import posefilter` without pip: a posefilter.pth in the user site-packages of each Python 3
# on this machine (Debian's /usr/bin/python3 and the first python3 on PATH) points at the module
# the build made in build/release/python. Rewritten on every build; delete it to undo.
if [ -d build/release/python/posefilter ]; then
  for py in /usr/bin/python3 "$(command -v python3 || true)"; do
    [ -x "$py" ] || continue
    site=$("$py" -c 'import site; print(site.getusersitepackages())' 2>/dev/null) || continue
    mkdir -p "$site" && echo "$PWD/build/release/python" > "$site/posefilter.pth"
  done
fi
