#!/usr/bin/env bash
# The concurrency tests (ctest LABEL `tsan`: tests/concurrency/) under ThreadSanitizer:
# configures the `tsan` preset (-fsanitize=thread -O1 -g, build/tsan), builds the library and
# concurrency_test only, and runs them. Exits non-zero when a test fails or TSan reports
# anything (a data race, a lock-order inversion, ...; reports go to build/tsan/sanitizer-logs/
# and are printed). libgomp is not instrumented: the tests run every estimate with
# threads = 1 under TSan (no OpenMP team), so no suppressions are needed (docs/RELIABILITY.md).
# Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=${POSEFILTER_JOBS:-2}

cmake --preset tsan >/dev/null
nice cmake --build --preset tsan --parallel "$jobs" --target concurrency_test

logs=$root/build/tsan/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:history_size=4:log_path=$logs/tsan"

status=0
ctest --preset tsan --timeout 900 "$@" || status=$?

shopt -s nullglob
reports=("$logs"/*)
if [ ${#reports[@]} -gt 0 ]; then
  echo "tsan.sh: ${#reports[@]} ThreadSanitizer report(s):" >&2
  for f in "${reports[@]}"; do
    echo "==== $f" >&2
    cat "$f" >&2
  done
  exit 1
fi
exit "$status"
