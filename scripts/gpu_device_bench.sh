#!/usr/bin/env bash
# The gpu engine's benchmark on a machine that has a Vulkan GPU but none of Debian's libraries.
#
# scripts/gpu_bundle.sh copies this file into a bundle as run.sh, next to the posefilter binary,
# lib/ (every shared library the binary needs, glibc and its dynamic loader included) and ycb/
# (one YCB-Video frame, one object's mesh, a detections prior). Run it from anywhere:
#     bash .gpu_bundle/run.sh            # outputs in $OUT, default ./gpu_out
# Every posefilter call goes through the bundle's loader (lib/ld-linux-x86-64.so.2 --library-path
# ...), so the binary runs with the glibc, libstdc++ and Vulkan loader it was built against,
# whatever the host's glibc is; the host supplies only the Vulkan driver (ICD), which the
# carried Vulkan loader loads into the process.
#
# Steps (each under `timeout`, all under one overall deadline; a failed step is logged and the
# next one still runs; the exit status is 1 if any step failed):
#   0. environment: host, glibc, Vulkan ICD files, nvidia-smi        -> $OUT/device.txt
#   1. a tiny gpu-only probe; when it fails, the same with the Vulkan loader's diagnostics, then
#      the next Vulkan driver choice (see VK_DRIVER_FILES below); when all fail, steps 2 and 3
#      run the cpu engine only, and the script's status is 1
#   2. posefilter bench --engines cpu,gpu on the bench's default scene (2048-face torus,
#      640x480) with GPU_BENCH_PARTICLES and with GPU_BENCH_PARTICLES2 particles
#                                       -> $OUT/bench_torus.json, $OUT/bench_torus_p<N>.json
#   3. the YCB-Video object estimated end to end (posefilter estimate, default settings) with
#      --engine gpu and --engine cpu, interleaved, GPU_BENCH_E2E_REPEATS times each: wall ms of
#      the process and the ms the CLI reports, then ADD-S of the last pose of each engine
#                                       -> $OUT/ycb_e2e.txt, $OUT/ycb_e2e.json
# Everything printed also goes to $OUT/log.txt. At most 6 files are written to $OUT.
#
# Environment:
#   OUT                      output folder (default ./gpu_out)
#   GPU_BENCH_QUICK=1        tiny sizes for a smoke test (128 particles, 1 iteration, 1 repeat,
#                            1 end-to-end repeat with 128 particles, 2 iterations, 1 restart)
#   GPU_BENCH_PARTICLES      bench particles (default 2048), GPU_BENCH_PARTICLES2 (default 510;
#                            0 = skip the second bench), GPU_BENCH_ITERATIONS (10),
#                            GPU_BENCH_REPEATS (3), GPU_BENCH_E2E_REPEATS (5),
#                            GPU_BENCH_E2E_ARGS (extra estimate options, default none)
#   GPU_BENCH_STEP_TIMEOUT   seconds per step (default 240), GPU_BENCH_DEADLINE seconds for the
#                            whole script (default 540)
#   VK_DRIVER_FILES          Vulkan ICD JSON(s), used as given. When it and VK_ICD_FILENAMES are
#                            unset, the choices tried are NVIDIA's container ICD
#                            /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json (if it exists),
#                            then the Vulkan loader's own search, then other nvidia_icd*.json files
#                            under /usr/local/nvidia, /usr/lib/nvidia, /usr/lib64/nvidia, /opt
#   POSEFILTER_GPU_DEVICE    index or name part of the Vulkan device to use (the engine's own choice
#                            otherwise: a discrete GPU first)
set -euo pipefail

B="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
OUT="${OUT:-./gpu_out}"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
LOG="$OUT/log.txt"
: >"$LOG"

QUICK="${GPU_BENCH_QUICK:-0}"
if [[ "$QUICK" == 1 ]]; then
  P="${GPU_BENCH_PARTICLES:-128}" ITER="${GPU_BENCH_ITERATIONS:-1}" REP="${GPU_BENCH_REPEATS:-1}"
  E2E_REP="${GPU_BENCH_E2E_REPEATS:-1}"
  E2E_ARGS="${GPU_BENCH_E2E_ARGS:---particles 128 --iterations 2 --restarts 1}"
else
  P="${GPU_BENCH_PARTICLES:-2048}" ITER="${GPU_BENCH_ITERATIONS:-10}" REP="${GPU_BENCH_REPEATS:-3}"
  E2E_REP="${GPU_BENCH_E2E_REPEATS:-5}"
  E2E_ARGS="${GPU_BENCH_E2E_ARGS:-}"
fi
P2="${GPU_BENCH_PARTICLES2:-510}"
STEP_TIMEOUT="${GPU_BENCH_STEP_TIMEOUT:-240}"
DEADLINE="${GPU_BENCH_DEADLINE:-540}"
for v in P P2 ITER REP E2E_REP STEP_TIMEOUT DEADLINE; do
  if [[ ! "${!v}" =~ ^[0-9]+$ ]]; then
    echo "run.sh: error: $v must be a non-negative integer, got '${!v}'" | tee -a "$LOG" >&2
    exit 2
  fi
done

NVIDIA_ICD=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
LOADER="$B/lib/ld-linux-x86-64.so.2"
BIN="$B/posefilter"
TMP="$(mktemp -d "${TMPDIR:-/tmp}/gpu_bench.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT
START_S=$SECONDS
FAILED=()

# A line to the terminal (fd 3: the script's stdout, whatever a step's output is redirected to)
# and the log.
exec 3>&1
log() { printf '%s\n' "$*" | tee -a "$LOG" >&3; }

# Milliseconds since the epoch (GNU date's %N; bash's EPOCHREALTIME where date lacks it).
now_ms() {
  local ns
  ns="$(date +%s%N 2>/dev/null || true)"
  if [[ "$ns" =~ ^[0-9]{13,}$ ]]; then
    echo $((ns / 1000000))
  else
    local r="${EPOCHREALTIME:-$(date +%s).000000}"
    echo $((${r%.*} * 1000 + 10#${r#*.} / 1000))
  fi
}

# step_limit [CAP]: seconds a step may still run: the step limit (or CAP, if smaller), cut to what
# the overall deadline leaves (0 when under 5 s are left).
step_limit() {
  local left=$((DEADLINE - (SECONDS - START_S))) cap="${1:-$STEP_TIMEOUT}"
  ((left < 5)) && left=0
  ((cap > STEP_TIMEOUT)) && cap=$STEP_TIMEOUT
  ((left > cap)) && left=$cap
  echo "$left"
}

# run_limited SECONDS CMD...: CMD under a time limit (timeout(1), or a watchdog where it is missing).
# Status 124 when the limit ended it.
run_limited() {
  local limit="$1"
  shift
  if command -v timeout >/dev/null 2>&1; then
    timeout -k 10 "$limit" "$@"
    return
  fi
  "$@" &
  local pid=$! rc=0
  (sleep "$limit" && kill -TERM "$pid" 2>/dev/null && sleep 10 && kill -KILL "$pid" 2>/dev/null) &
  local dog=$!
  wait "$pid" || rc=$?
  kill "$dog" 2>/dev/null || true
  wait "$dog" 2>/dev/null || true
  if ((rc == 143 || rc == 137)); then return 124; fi
  return "$rc"
}

# pf NAME LIMIT ARGS...: posefilter ARGS through the bundle's loader and libraries. Its stdout goes
# to stdout, its stderr to stderr, both also to the log. Status of posefilter (124: out of time,
# 125: skipped for the deadline).
pf() {
  local name="$1" limit="$2"
  shift 2
  if ((limit < 1)); then
    log "== $name: skipped, the overall deadline (${DEADLINE} s) is reached"
    return 125
  fi
  log "+ $LOADER --library-path $LIBPATH $BIN $*   (limit ${limit} s)"
  local rc=0
  run_limited "$limit" "$LOADER" --library-path "$LIBPATH" "$BIN" "$@" >"$TMP/step.out" 2>"$TMP/step.err" || rc=$?
  cat "$TMP/step.out" "$TMP/step.err" >>"$LOG"
  cat "$TMP/step.out"
  cat "$TMP/step.err" >&2
  ((rc == 124)) && log "== $name: out of time after ${limit} s"
  return "$rc"
}

fail() {
  FAILED+=("$1")
  log "== FAILED: $1"
}

# The directory that holds a Vulkan ICD's library: the JSON's library_path when it is a path,
# else (a bare name such as libGLX_nvidia.so.0) the first of LD_LIBRARY_PATH's folders, NVIDIA's
# container folders, the usual library folders and the host's loader cache that has it.
icd_lib_dir() {
  local json="$1" lib dir
  lib="$(sed -n 's/.*"library_path"[[:space:]]*:[[:space:]]*"\([^"]*\)".*/\1/p' "$json" 2>/dev/null | head -n 1)"
  [[ -n "$lib" ]] || return 0
  case "$lib" in
    /*) dirname "$lib" && return 0 ;;
    */*) (cd "$(dirname "$json")" && cd "$(dirname "$lib")" 2>/dev/null && pwd) || true
      return 0 ;;
  esac
  local -a dirs=()
  IFS=: read -r -a dirs <<<"${LD_LIBRARY_PATH:-}"
  for dir in "${dirs[@]}" /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /lib64; do
    if [[ -n "$dir" && -e "$dir/$lib" ]]; then
      echo "$dir"
      return 0
    fi
  done
  if command -v ldconfig >/dev/null 2>&1; then
    dir="$(ldconfig -p 2>/dev/null | awk -v l="$lib" '$1 == l && /x86-64/ {print $NF; exit}')"
    [[ -n "$dir" ]] && dirname "$dir"
  fi
  return 0
}

# use_driver CHOICE: set the Vulkan loader's driver variables for CHOICE (caller: as they are;
# search: unset, the loader's own search; else the ICD JSON file CHOICE), and ICDS (the ICD
# files in play) and LIBPATH: the bundle's lib first (glibc, libstdc++, the Vulkan loader...),
# then the folders of the ICDs' libraries and the caller's LD_LIBRARY_PATH, for the driver and
# the libraries it loads.
use_driver() {
  local j d
  case "$1" in
    caller) ;;
    search) unset VK_DRIVER_FILES VK_ICD_FILENAMES ;;
    *) export VK_DRIVER_FILES="$1"
      unset VK_ICD_FILENAMES ;;
  esac
  ICDS=()
  if [[ -n "${VK_DRIVER_FILES:-${VK_ICD_FILENAMES:-}}" ]]; then
    IFS=: read -r -a ICDS <<<"${VK_DRIVER_FILES:-${VK_ICD_FILENAMES:-}}"
  else
    for j in /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json /usr/share/vulkan/icd.d/*.json; do
      [[ -f "$j" ]] && ICDS+=("$j")
    done
  fi
  LIBPATH="$B/lib"
  for j in "${ICDS[@]}"; do
    d="$(icd_lib_dir "$j")"
    [[ -n "$d" && ":$LIBPATH:" != *":$d:"* ]] && LIBPATH="$LIBPATH:$d"
  done
  if [[ -n "${LD_LIBRARY_PATH:-}" ]]; then LIBPATH="$LIBPATH:$LD_LIBRARY_PATH"; fi
  return 0
}

main() {
  log "== posefilter gpu bundle: $B"
  log "== outputs: $OUT   quick: $QUICK   bench: $P (and $P2) particles, $ITER iterations, $REP repeats;" \
    "e2e: $E2E_REP repeats, extra options '${E2E_ARGS}'"
  if [[ ! -f "$BIN" || ! -f "$LOADER" ]]; then
    log "run.sh: error: the bundle has no posefilter or lib/ld-linux-x86-64.so.2 (rebuild it with scripts/gpu_bundle.sh)"
    return 2
  fi
  # The loader must be executable (a copy may lose the mode bits, or sit on a noexec mount; then
  # a copy of it in TMP). posefilter itself is mapped by the loader and needs no exec bit.
  if ! "$LOADER" --version >/dev/null 2>&1; then
    chmod u+x "$LOADER" 2>/dev/null || true
    if ! "$LOADER" --version >/dev/null 2>&1; then
      cp "$LOADER" "$TMP/ld-linux-x86-64.so.2" && chmod u+x "$TMP/ld-linux-x86-64.so.2"
      LOADER="$TMP/ld-linux-x86-64.so.2"
      if ! "$LOADER" --version >/dev/null 2>&1; then
        log "run.sh: error: the bundle's lib/ld-linux-x86-64.so.2 does not run here (a copy in $TMP neither)"
        return 2
      fi
    fi
  fi

  # Vulkan driver choices, tried in order until the gpu engine finds a device: the caller's
  # VK_DRIVER_FILES / VK_ICD_FILENAMES alone if set; else NVIDIA's container ICD (if present),
  # the Vulkan loader's own search, and any other nvidia_icd*.json found in the usual places.
  local -a choices=()
  local c j
  if [[ -n "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]]; then
    choices=(caller)
  else
    [[ -f "$NVIDIA_ICD" ]] && choices+=("$NVIDIA_ICD")
    choices+=(search)
    while IFS= read -r j; do
      [[ -n "$j" && "$j" != "$NVIDIA_ICD" && "$j" != */vulkan/icd.d/* ]] && choices+=("$j")
    done < <(find /usr/local/nvidia /usr/lib/nvidia /usr/lib64/nvidia /opt -maxdepth 5 -name 'nvidia_icd*.json' \
      2>/dev/null | head -n 3)
  fi

  # 0. Environment (for the first choice) and nvidia-smi.
  use_driver "${choices[0]}"
  {
    echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ 2>/dev/null || true)"
    echo "host: $(uname -a 2>/dev/null || true)"
    echo "host glibc: $(getconf GNU_LIBC_VERSION 2>/dev/null || echo unknown); bundle's: $(sed -n 's/^glibc: //p' "$B/MANIFEST.txt" 2>/dev/null || echo unknown)"
    echo "cpu: $(grep -m 1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2- | sed 's/^ *//'), $(nproc 2>/dev/null || echo '?') cores"
    echo "driver choices: ${choices[*]}"
    echo "POSEFILTER_GPU_DEVICE=${POSEFILTER_GPU_DEVICE:-<unset>}"
    echo "ICD files:"
    for j in "${ICDS[@]}" "${choices[@]:1}"; do
      [[ -f "$j" ]] && echo "  $j: $(tr -d ' \n\t' <"$j" 2>/dev/null | head -c 300)"
    done
    echo "host Vulkan and NVIDIA libraries (ldconfig -p):"
    { command -v ldconfig >/dev/null 2>&1 && ldconfig -p 2>/dev/null | grep -iE 'libvulkan|libGLX_nvidia|libnvidia-glcore' | head -n 10; } ||
      echo "  (none listed)"
    if command -v nvidia-smi >/dev/null 2>&1; then
      echo "nvidia-smi:"
      run_limited 30 nvidia-smi 2>&1 || true
      run_limited 30 nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>&1 || true
    else
      echo "nvidia-smi: not found"
    fi
  } >"$TMP/env.txt" 2>&1
  tee -a "$LOG" <"$TMP/env.txt" >&3

  # 1. Probe: does the gpu engine find a device through the bundle's loader? On failure, the same
  # with the Vulkan loader's messages, then the next driver choice.
  local rc=1 tried=0
  GPU_OK=0
  for c in "${choices[@]}"; do
    ((tried++ < 3)) || break
    use_driver "$c"
    log "== probe, driver choice '$c': VK_DRIVER_FILES=${VK_DRIVER_FILES:-<unset>}" \
      "VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-<unset>}; library path $LIBPATH"
    rc=0
    pf probe "$(step_limit 120)" bench --engines gpu --particles 128 --iterations 1 --repeats 1 --quiet \
      --json "$TMP/probe.json" || rc=$?
    if ((rc == 0)); then
      GPU_OK=1
      break
    fi
    log "== probe with driver choice '$c' failed (status $rc)"
    ((rc == 125)) && break
    if ((rc != 124)); then
      log "== probe again with the Vulkan loader's messages (VK_LOADER_DEBUG=error,warn,driver):"
      export VK_LOADER_DEBUG=error,warn,driver
      pf probe-debug "$(step_limit 60)" bench --engines gpu --particles 128 --iterations 1 --repeats 1 --quiet \
        >/dev/null 2>&1 || true
      unset VK_LOADER_DEBUG
    fi
  done
  {
    echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-<unset>}  VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-<unset>}"
    echo "library path: $LIBPATH"
  } >>"$TMP/env.txt"
  local engines=cpu,gpu
  if ((GPU_OK == 0)); then
    engines=cpu
    fail "probe: the gpu engine ran with no driver choice (${choices[*]})"
    log "== the gpu engine found no usable device: cpu-only bench, no gpu end-to-end runs"
  fi
  local gpu_device
  gpu_device="$(sed -n 's/.*"gpu_device": *"\([^"]*\)".*/\1/p' "$TMP/probe.json" 2>/dev/null | head -n 1)"

  # 2. Bench on the default scene.
  rc=0
  pf "bench $P" "$(step_limit)" bench --engines "$engines" --particles "$P" --iterations "$ITER" --repeats "$REP" \
    --json "$OUT/bench_torus.json" || rc=$?
  ((rc == 0)) || fail "bench $P particles (status $rc)"
  if ((P2 > 0)); then
    rc=0
    pf "bench $P2" "$(step_limit)" bench --engines "$engines" --particles "$P2" --iterations "$ITER" --repeats "$REP" \
      --json "$OUT/bench_torus_p$P2.json" || rc=$?
    ((rc == 0)) || fail "bench $P2 particles (status $rc)"
  fi
  if [[ -z "$gpu_device" && -f "$OUT/bench_torus.json" ]]; then
    gpu_device="$(sed -n 's/.*"gpu_device": *"\([^"]*\)".*/\1/p' "$OUT/bench_torus.json" | head -n 1)"
  fi
  {
    echo "gpu engine device (posefilter bench): ${gpu_device:-<none: the gpu engine did not run>}"
    cat "$TMP/env.txt"
  } >"$OUT/device.txt"
  log "== gpu engine device: ${gpu_device:-<none>}"

  # 3. The YCB-Video object end to end.
  e2e
}

e2e() {
  local txt="$OUT/ycb_e2e.txt" json="$OUT/ycb_e2e.json" Y="$B/ycb"
  if [[ ! -f "$Y/input.env" ]]; then
    log "== e2e: the bundle has no YCB-Video input (it was built without the data); skipped"
    echo "no YCB-Video input in the bundle; end-to-end estimate skipped" >"$txt"
    return 0
  fi
  local OBJ FRAME
  # shellcheck disable=SC1091  # written by gpu_bundle.sh: OBJ=..., FRAME=...
  source "$Y/input.env"
  local -a extra=()
  [[ -n "$E2E_ARGS" ]] && read -r -a extra <<<"$E2E_ARGS"
  local -a args=(estimate --depth "$Y/depth.png" --camera "$Y/camera.json" --mesh "$OBJ=$Y/$OBJ.ply"
    --prior "$Y/detections.json" --quiet "${extra[@]}")
  {
    echo "# YCB-Video frame $FRAME, object $OBJ, prior: gt-derived detection (jitter 8 px, seed 1)"
    echo "# posefilter ${args[*]} --engine E --out R"
    echo "# wall_ms: the whole process (date +%s%N around it: loading, Vulkan set-up, estimate);"
    echo "# cli_ms: the time the CLI reports for the object; pose: x y z [m] roll pitch yaw, weight, iterations"
  } >"$txt"
  local i e t0 t1 rc line cli
  local -A walls=() clis=()
  for ((i = 1; i <= E2E_REP; i++)); do
    for e in gpu cpu; do
      if [[ "$e" == gpu && "$GPU_OK" == 0 ]]; then
        echo "engine=gpu run=$i skipped (no usable Vulkan device)" >>"$txt"
        continue
      fi
      rc=0
      t0="$(now_ms)"
      pf "e2e $e $i" "$(step_limit)" "${args[@]}" --engine "$e" --out "$TMP/res_$e.json" >"$TMP/est.txt" || rc=$?
      t1="$(now_ms)"
      if ((rc != 0)); then
        fail "e2e $e run $i (status $rc)"
        echo "engine=$e run=$i status=$rc wall_ms=$((t1 - t0))" >>"$txt"
        continue
      fi
      line="$(awk -v o="$OBJ" '$1 == o' "$TMP/est.txt" | tail -n 1)"
      cli="$(awk '{print $NF}' <<<"$line")"
      echo "engine=$e run=$i status=0 wall_ms=$((t1 - t0)) cli_ms=${cli:-?} pose: $(awk '{$1=""; NF--; print}' <<<"$line")" >>"$txt"
      walls[$e]+="${walls[$e]:+, }$((t1 - t0))"
      clis[$e]+="${clis[$e]:+, }${cli:-null}"
    done
  done
  if [[ -f "$Y/gt.json" ]]; then
    for e in gpu cpu; do
      [[ -f "$TMP/res_$e.json" ]] || continue
      echo "# ADD-S of engine $e's last pose vs the ground truth:" >>"$txt"
      pf "eval $e" 60 eval --results "$TMP/res_$e.json" --gt "$Y/gt.json" --mesh "$OBJ=$Y/$OBJ.ply" \
        --points "$OBJ=$Y/$OBJ.xyz" >>"$txt" 2>&1 || fail "eval $e"
    done
  fi
  {
    echo "{"
    echo "  \"frame\": \"$FRAME\", \"object\": \"$OBJ\", \"extra_args\": \"$E2E_ARGS\", \"repeats\": $E2E_REP,"
    echo "  \"gpu\": {\"wall_ms\": [${walls[gpu]:-}], \"cli_ms\": [${clis[gpu]:-}]},"
    echo "  \"cpu\": {\"wall_ms\": [${walls[cpu]:-}], \"cli_ms\": [${clis[cpu]:-}]}"
    echo "}"
  } >"$json"
  tee -a "$LOG" <"$txt"
}

status=0
main || status=$?
if ((status == 0 && ${#FAILED[@]} > 0)); then status=1; fi
if ((${#FAILED[@]} > 0)); then
  log "== done in $((SECONDS - START_S)) s with failures: ${FAILED[*]}"
else
  log "== done in $((SECONDS - START_S)) s; outputs in $OUT"
fi
exit "$status"
