#!/usr/bin/env bash
# Installs the build tree BUILD into a scratch prefix with `cmake --install`, then configures,
# builds and runs tests/install/consumer against it with find_package(posefilter CONFIG
# REQUIRED): the check that an installed posefilter is usable as a library.
# usage: tests/install/run_consumer.sh BUILD_DIR SCRATCH_DIR
set -euo pipefail
build=$1
scratch=$2
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" > "$scratch.install.log" 2>&1 || { cat "$scratch.install.log"; exit 1; }
test -f "$scratch/prefix/include/posefilter/filter.h"
test -x "$scratch/prefix/bin/posefilter"
cmake -S "$here/consumer" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$scratch/build" -j 2 > /dev/null
"$scratch/build/consumer"
"$scratch/prefix/bin/posefilter" options > /dev/null
rm -rf "$scratch" "$scratch.install.log"
