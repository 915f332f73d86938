#!/usr/bin/env bash
# Quick start: install dependencies, build the command-line tool (the library and the
# `posefilter` CLI only: no test, benchmark or Python target), then estimate a pose on a
# built-in synthetic scene. Arguments go to `posefilter demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release --target posefilter_bin
build/release/posefilter demo --out build/demo "$@"
