#!/usr/bin/env bash
# The gpu engine's device bundle (scripts/gpu_bundle.sh), end to end on this machine: build a
# bundle from BUILD_DIR into a temporary folder, run its run.sh in quick mode on whatever Vulkan
# device this machine has (Mesa's lavapipe on a machine without a GPU), and check that
#   - the bundle's libraries all resolve inside it, through its own dynamic loader;
#   - run.sh exits 0 and starts posefilter through the bundle's lib/ld-linux-x86-64.so.2;
#   - it does not point the Vulkan loader at NVIDIA's ICD file where that file does not exist;
#   - the bench JSON says the engines agree and names the gpu engine's device;
#   - the end-to-end file has gpu and cpu timings (when the YCB-Video data was there to bundle).
#
# usage: tests/scripts/gpu_bundle_test.sh BUILD_DIR
set -euo pipefail

BUILD="${1:?usage: gpu_bundle_test.sh BUILD_DIR}"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$(cd "$BUILD" && pwd)"
T="$(mktemp -d "${TMPDIR:-/tmp}/gpu_bundle_test.XXXXXX")"
trap 'rm -rf "$T"' EXIT
B="$T/bundle"
OUT="$T/out"

fail() {
  echo "gpu_bundle_test: FAIL: $*" >&2
  if [[ -f "$OUT/log.txt" ]]; then
    echo "---- last lines of run.sh's log:" >&2
    tail -n 40 "$OUT/log.txt" >&2
  fi
  exit 1
}

"$ROOT/scripts/gpu_bundle.sh" "$BUILD" "$B" || fail "scripts/gpu_bundle.sh failed"
for f in posefilter run.sh lib/ld-linux-x86-64.so.2 lib/libc.so.6 lib/libvulkan.so.1 lib/libstdc++.so.6; do
  [[ -e "$B/$f" ]] || fail "the bundle has no $f"
done
size=$(du -sb "$B" | cut -f1)
((size < 60 * 1024 * 1024)) || fail "the bundle is $size bytes, over 60 MiB"

# Self-contained: every library the binary needs resolves inside the bundle.
listed="$("$B/lib/ld-linux-x86-64.so.2" --library-path "$B/lib" --list "$B/posefilter")" ||
  fail "the bundle's loader cannot load its posefilter"
outside="$(awk '$2 == "=>" {print $3}' <<<"$listed" | grep -v "^$B/lib/" || true)"
[[ -z "$outside" ]] || fail "libraries resolved outside the bundle: $outside"

rc=0
(cd "$T" && env GPU_BENCH_QUICK=1 OUT="$OUT" GPU_BENCH_DEADLINE=300 bash "$B/run.sh") >"$T/run.txt" 2>&1 || rc=$?
((rc == 0)) || {
  tail -n 40 "$T/run.txt" >&2
  fail "run.sh exited with $rc"
}

grep -qF "+ $B/lib/ld-linux-x86-64.so.2 --library-path $B/lib" "$OUT/log.txt" ||
  fail "run.sh did not start posefilter through the bundle's lib/ld-linux-x86-64.so.2"
if grep -E "^\+ " "$OUT/log.txt" | grep -vqF "+ $B/lib/ld-linux-x86-64.so.2 "; then
  fail "run.sh started a command other than through the bundle's loader"
fi

nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [[ ! -e "$nvidia_icd" ]] && grep -qF "VK_DRIVER_FILES=$nvidia_icd" "$OUT/device.txt"; then
  fail "run.sh set VK_DRIVER_FILES to $nvidia_icd, which does not exist here"
fi

for j in "$OUT/bench_torus.json" "$OUT/bench_torus_p510.json"; do
  [[ -s "$j" ]] || fail "no bench JSON $j"
  grep -qE '"engines_agree": *true' "$j" || fail "$j: the engines do not agree (or no engines_agree)"
  grep -qE '"gpu_device": *"[^"]+"' "$j" || fail "$j: no gpu_device"
  grep -qE '"engine": *"gpu"' "$j" || fail "$j: no gpu engine entry"
done
grep -q "^gpu engine device (posefilter bench): .*[^>]$" "$OUT/device.txt" || fail "device.txt names no gpu device"

if [[ -f "$B/ycb/input.env" ]]; then
  for e in gpu cpu; do
    grep -qE "^engine=$e run=1 status=0 wall_ms=[0-9]+ cli_ms=[0-9.]+ " "$OUT/ycb_e2e.txt" ||
      fail "ycb_e2e.txt has no $e timing"
    grep -qE "\"$e\": \{\"wall_ms\": \[[0-9]+\]" "$OUT/ycb_e2e.json" || fail "ycb_e2e.json has no $e wall time"
  done
  grep -q "^ADD-S recall" "$OUT/ycb_e2e.txt" || fail "ycb_e2e.txt has no ADD-S evaluation"
else
  echo "gpu_bundle_test: no YCB-Video data was bundled; the end-to-end check is skipped"
fi

echo "gpu_bundle_test: OK (bundle $((size / 1024 / 1024)) MiB; $(grep -m 1 '^gpu engine device' "$OUT/device.txt"))"
