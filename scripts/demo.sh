#!/usr/bin/env bash
# Quick start: install dependencies, build, then estimate a pose on a built-in synthetic scene.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
build/release/posefilter demo --out build/demo "$@"
