#!/usr/bin/env bash
# Builds the libFuzzer targets of the file readers (fuzz/; the `asan` preset: clang with
# AddressSanitizer + UBSan, build/asan) and runs each one for N seconds (default 60) on a copy
# of its seed corpus fuzz/corpus/<target>/ (the committed corpus never grows), P targets at a
# time (default 2). Prints the executions per target and exits non-zero on any finding: a
# crash, a sanitizer report, an exception other than posefilter::Error, a contract check, a
# leak, a hang (> 10 s per input) or an allocation over 2 GB.
#
#   scripts/fuzz.sh [seconds_per_target [targets_at_a_time]]
#
# Environment: POSEFILTER_FUZZ_TARGETS="a b" runs only those targets; POSEFILTER_FUZZ_FLAGS adds
# libFuzzer flags (e.g. "-runs=1000000"); POSEFILTER_JOBS build jobs (default 2).
# Findings stay in build/asan/fuzz-run/<target>/ (log, and the input as crash-*/timeout-*/oom-*/
# leak-*); reproduce one with: build/asan/fuzz/<target> <file>. Past findings, kept in
# fuzz/regressions/<target>/, are replayed as seeds on every run (and by the ctest
# FuzzRegressions tests).
set -euo pipefail
cd "$(dirname "$0")/.."

secs=${1:-60}
parallel=${2:-2}
if ! [[ "$secs" =~ ^[0-9]+$ ]] || [ "$secs" -lt 1 ] || ! [[ "$parallel" =~ ^[0-9]+$ ]] || [ "$parallel" -lt 1 ]; then
  echo "usage: scripts/fuzz.sh [seconds_per_target [targets_at_a_time]]   (positive integers; default 60 2)" >&2
  exit 2
fi
if ! command -v clang++ >/dev/null; then
  echo "scripts/fuzz.sh: needs clang++ with libFuzzer (scripts/setup.sh installs clang)" >&2
  exit 2
fi

all_targets="depth_png_fuzz label_png_fuzz mesh_ply_fuzz mesh_obj_fuzz camera_json_fuzz detections_json_fuzz pyramid_raw_fuzz bop_csv_fuzz"
targets=${POSEFILTER_FUZZ_TARGETS:-$all_targets}

cmake --preset asan >/dev/null
# shellcheck disable=SC2086
cmake --build --preset asan --parallel "${POSEFILTER_JOBS:-2}" --target $targets

dict_of() {
  case "$1" in
    depth_png_fuzz | label_png_fuzz) echo fuzz/png.dict ;;
    mesh_ply_fuzz) echo fuzz/ply.dict ;;
    mesh_obj_fuzz) echo fuzz/obj.dict ;;
    camera_json_fuzz | detections_json_fuzz) echo fuzz/json.dict ;;
    bop_csv_fuzz) echo fuzz/bop_csv.dict ;;
    *) echo "" ;;
  esac
}

# Leaks inside Debian's assimp (its OBJ importer's error path) are known and not ours.
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

run=build/asan/fuzz-run
rm -rf "$run"
mkdir -p "$run"

# One target's run; its result line goes to $run/<target>/result.
fuzz_one() {
  local t=$1 dir=$run/$1
  mkdir -p "$dir/corpus"
  cp fuzz/corpus/"$t"/* "$dir/corpus/"
  local dict
  dict=$(dict_of "$t")
  local args=(-max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$dir/")
  [ -n "$dict" ] && args+=(-dict="$dict")
  # New inputs go to the first folder (the copy); fuzz/regressions/<target>/ holds past
  # findings, replayed as seeds.
  local corpora=("$dir/corpus")
  [ -d fuzz/regressions/"$t" ] && corpora+=(fuzz/regressions/"$t")
  local start rc=0
  start=$(date +%s)
  # shellcheck disable=SC2086
  timeout --signal=KILL $((secs + 600)) build/asan/fuzz/"$t" "${args[@]}" ${POSEFILTER_FUZZ_FLAGS:-} "${corpora[@]}" \
    >"$dir/log" 2>&1 || rc=$?
  local took execs rate artifacts result
  took=$(($(date +%s) - start))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$dir/log" | tail -1)
  artifacts=$(find "$dir" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' \
    -o -name 'oom-*' -o -name 'slow-unit-*' \) | sort)
  if [ "$rc" -ne 0 ] || [ -n "$artifacts" ]; then
    result="FINDING (exit $rc) ${artifacts:-no input saved}; log: $dir/log"
  else
    result=ok
  fi
  printf '%-22s %12s %10s %8s  %s\n' "$t" "${execs:--}" "${rate:--}" "$took" "$result" >"$dir/result"
}

for t in $targets; do
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
  fuzz_one "$t" &
done
wait

printf '%-22s %12s %10s %8s  %s\n' target executions exec/s seconds result
failed=()
for t in $targets; do
  cat "$run/$t/result"
  grep -q ' ok$' "$run/$t/result" || failed+=("$t")
done

if [ ${#failed[@]} -ne 0 ]; then
  for t in "${failed[@]}"; do
    echo
    echo "---- $t: the report in $run/$t/log"
    first=$(grep -n -m1 -E '^==[0-9]+==|runtime error|^posefilter fuzz:|terminate called|ERROR: libFuzzer' "$run/$t/log" | cut -d: -f1)
    sed -n "${first:-1},\$p" "$run/$t/log" | head -60
  done
  echo
  echo "scripts/fuzz.sh: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "scripts/fuzz.sh: no findings (${secs} s per target, ${parallel} at a time)"
