#!/usr/bin/env bash
# scripts/peers.py's bad options: each must exit non-zero with a message naming the option,
# before any scene is written or any peer runs. Skipped (exit 77) where the peers' Python
# packages are not installed (`scripts/setup.sh peers` installs them).
#
# usage: tests/scripts/peers_args_test.sh PYTHON
set -uo pipefail

PY="${1:?usage: peers_args_test.sh PYTHON}"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
if ! "$PY" -c "import numpy, open3d, scipy" >/dev/null 2>&1; then
  echo "peers_args_test: SKIP: no numpy/open3d/scipy for $PY (scripts/setup.sh peers)"
  exit 77
fi
T="$(mktemp -d "${TMPDIR:-/tmp}/peers_args_test.XXXXXX")"
trap 'rm -rf "$T"' EXIT
# The checks after the meshes folder's get an existing (empty) one, so that the test does not
# depend on ../shared/data being beside the clone.
mkdir -p "$T/models"

failures=0
# expect_error WHAT ARGS...: peers.py ARGS must fail and print WHAT on stderr, writing nothing.
expect_error() {
  local what="$1"
  shift
  local err rc
  err="$("$PY" "$ROOT/scripts/peers.py" --out "$T/out" "$@" 2>&1 >/dev/null)"
  rc=$?
  if [[ $rc -eq 0 ]]; then
    echo "peers_args_test: FAIL: '$*' exited 0" >&2
    failures=$((failures + 1))
  elif [[ "$err" != *"$what"* ]]; then
    echo "peers_args_test: FAIL: '$*' did not name '$what'; stderr: $err" >&2
    failures=$((failures + 1))
  fi
  if [[ -e "$T/out" ]]; then
    echo "peers_args_test: FAIL: '$*' wrote $T/out" >&2
    failures=$((failures + 1))
  fi
}

expect_error "--peers: unknown peer 'opencv'" --peers opencv
expect_error "--peers: name at least one peer" --peers ,
expect_error "--opencv-scene-sampling" --opencv-scene-sampling fine
expect_error "--count must be >= 1" --count 0
expect_error "--opencv-model-points must be >= 10" --opencv-model-points 5
expect_error "--world" --world kitchen
expect_error "--max-depth and --large-plane apply to --world room" --max-depth 2
expect_error "--max-depth must be above 0.35" --world room --max-depth 0.2
expect_error "--large-plane must be > 0" --world room --large-plane 0
expect_error "--reuse-posefilter: no posefilter.json" --reuse-posefilter --models "$T/models"
expect_error "no such folder" --models "$T/no_models"
expect_error "no posefilter binary" --posefilter "$T/no_posefilter" --models "$T/models"

if [[ $failures -ne 0 ]]; then
  exit 1
fi
echo "peers_args_test: OK"
