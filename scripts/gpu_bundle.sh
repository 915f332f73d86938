#!/usr/bin/env bash
# Pack the posefilter binary into a folder that runs the gpu engine's benchmark on another Linux
# machine: one with a Vulkan GPU and driver but none of this machine's (Debian's) libraries and
# perhaps another glibc.
#
# usage: scripts/gpu_bundle.sh [BUILD_DIR] [BUNDLE_DIR]
#   BUILD_DIR   the build with the posefilter binary (default: build/release)
#   BUNDLE_DIR  the bundle (default: .gpu_bundle); removed and written anew
# Relative paths are taken from the repository root.
#
# The bundle:
#   posefilter           the binary
#   lib/                 every shared library `ldd posefilter` lists (the Vulkan loader, libstdc++,
#                        libgomp, assimp, libpng, ..., glibc), glibc's other libraries that a
#                        Vulkan driver may link (libdl, libpthread, librt, ...) and the dynamic
#                        loader ld-linux-x86-64.so.2: run.sh starts the binary as
#                        `lib/ld-linux-x86-64.so.2 --library-path lib:... posefilter`, so nothing
#                        of the host but its kernel and its Vulkan driver is used
#   ycb/                 one YCB-Video frame (depth.png, camera.json), one object's mesh (.ply) and
#                        official model points (.xyz), its ground truth (gt.json) and a stage-1
#                        detections prior made from that ground truth (posefilter gt-detections,
#                        jitter 8 px, seed 1); input.env names the object and the frame. Left out,
#                        with a message, when the data folder is missing.
#   run.sh               scripts/gpu_device_bench.sh: the benchmark (see its header)
#   MANIFEST.txt         what was bundled, from which build and commit
# A bundle inside the repository is added to .git/info/exclude: a lent device machine carries
# ignored folders named in its `carry` list, and nothing of the bundle belongs in a commit.
#
# Environment:
#   YCBV_DATA   the YCB-Video folder (default: $POSEFILTER_DATA/ycbv, else ../shared/data/ycbv from the
#               repository root)
#   YCB_OBJECT  the object (default 025_mug), YCB_FRAME the frame folder (default ycbv_0000_000001)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
abs() { if [[ "$1" == /* ]]; then echo "$1"; else echo "$ROOT/$1"; fi; }
BUILD="$(abs "${1:-build/release}")"
BUNDLE="$(abs "${2:-.gpu_bundle}")"
DATA="${YCBV_DATA:-${POSEFILTER_DATA:-$ROOT/../shared/data}/ycbv}"
[[ -d "$DATA" ]] && DATA="$(cd "$DATA" && pwd)"
OBJ="${YCB_OBJECT:-025_mug}"
FRAME="${YCB_FRAME:-ycbv_0000_000001}"
BIN="$BUILD/posefilter"
MARK=".posefilter_gpu_bundle"

die() {
  echo "gpu_bundle: error: $*" >&2
  exit 1
}

[[ -x "$BIN" ]] || die "no posefilter binary at $BIN (build it first, or pass the build folder)"
command -v ldd >/dev/null 2>&1 || die "ldd is needed to list the binary's libraries"
[[ "$(uname -m)" == x86_64 ]] || die "the bundle is for x86-64 machines; this one is $(uname -m)"

# Recreate the folder; refuse to remove one that is not a bundle (nor empty).
BUNDLE="${BUNDLE%/}"
[[ -n "$BUNDLE" && "$BUNDLE" != / && "$BUNDLE" != "$ROOT" ]] || die "refusing bundle folder '$BUNDLE'"
if [[ -e "$BUNDLE" ]]; then
  if [[ -f "$BUNDLE/$MARK" || -z "$(ls -A "$BUNDLE" 2>/dev/null)" ]]; then
    rm -rf "$BUNDLE"
  else
    die "$BUNDLE exists and is not a bundle (no $MARK); not removing it"
  fi
fi
mkdir -p "$BUNDLE/lib"
touch "$BUNDLE/$MARK"

# The binary and its libraries under their sonames (ldd's left column), links resolved.
cp -L "$BIN" "$BUNDLE/posefilter"
ldd_out="$(ldd "$BIN")" || die "ldd $BIN failed"
if grep -q "not found" <<<"$ldd_out"; then
  die "libraries of $BIN are missing: $(grep 'not found' <<<"$ldd_out" | tr -s ' \t' ' ')"
fi
libc_dir=""
loader=""
while read -r name arrow path _; do
  if [[ "$arrow" == "=>" && "$path" == /* ]]; then
    cp -L "$path" "$BUNDLE/lib/$name"
    [[ "$name" == libc.so.6 ]] && libc_dir="$(dirname "$(readlink -f "$path")")"
  elif [[ "$name" == /*ld-linux-x86-64.so.2 ]]; then
    loader="$name"
  fi
done <<<"$ldd_out"
[[ -n "$loader" ]] || die "ldd names no ld-linux-x86-64.so.2 for $BIN"
[[ -n "$libc_dir" ]] || die "ldd names no libc.so.6 for $BIN"
cp -L "$loader" "$BUNDLE/lib/ld-linux-x86-64.so.2"
# glibc's other libraries: a Vulkan driver loaded into the process may link them, and they must
# come from the same glibc as the carried libc.so.6 and loader.
for extra in libdl.so.2 libpthread.so.0 librt.so.1 libresolv.so.2 libutil.so.1 libanl.so.1 libmvec.so.1; do
  [[ -e "$libc_dir/$extra" && ! -e "$BUNDLE/lib/$extra" ]] && cp -L "$libc_dir/$extra" "$BUNDLE/lib/$extra"
done
chmod 755 "$BUNDLE/posefilter" "$BUNDLE/lib/ld-linux-x86-64.so.2"
glibc="$("$BUNDLE/lib/ld-linux-x86-64.so.2" --version 2>/dev/null | head -n 1 | grep -oE '[0-9]+\.[0-9]+' | head -n 1 || true)"

# Every library must resolve inside the bundle.
listed="$("$BUNDLE/lib/ld-linux-x86-64.so.2" --library-path "$BUNDLE/lib" --list "$BUNDLE/posefilter")" ||
  die "the bundle's loader cannot load its posefilter"
outside="$(awk '$2 == "=>" && $3 ~ /^\// {print $3}' <<<"$listed" | grep -v "^$BUNDLE/lib/" || true)"
[[ -z "$outside" ]] || die "libraries resolved outside the bundle: $outside"

# The YCB-Video input: one frame, one object.
ycb="no data at $DATA; the bundle has no YCB-Video input (run.sh skips the end-to-end estimate)"
S="$DATA/scenes/$FRAME"
if [[ -f "$S/depth.png" && -f "$S/camera.json" && -f "$S/gt.json" && -f "$DATA/models/$OBJ.ply" ]]; then
  Y="$BUNDLE/ycb"
  mkdir -p "$Y"
  cp "$S/depth.png" "$S/camera.json" "$Y/"
  cp "$DATA/models/$OBJ.ply" "$Y/$OBJ.ply"
  [[ -f "$DATA/models/points/$OBJ.xyz" ]] && cp "$DATA/models/points/$OBJ.xyz" "$Y/$OBJ.xyz"
  # The frame's ground truth, cut to the one object (eval wants a mesh for every gt object).
  /usr/bin/env python3 - "$S/gt.json" "$OBJ" "$Y/gt.json" <<'EOF' || die "cutting $S/gt.json to $OBJ failed"
import json, sys
gt = json.load(open(sys.argv[1]))
gt["objects"] = [o for o in gt["objects"] if o["obj"] == sys.argv[2]]
if not gt["objects"]:
    sys.exit("no object %s in %s" % (sys.argv[2], sys.argv[1]))
json.dump(gt, open(sys.argv[3], "w"), indent=1)
EOF
  "$BIN" gt-detections --gt "$Y/gt.json" --camera "$Y/camera.json" --mesh "$OBJ=$Y/$OBJ.ply" \
    --jitter 8 --seed 1 --quiet --out "$Y/detections.json" || die "posefilter gt-detections failed"
  printf 'OBJ=%s\nFRAME=%s\n' "$OBJ" "$FRAME" >"$Y/input.env"
  ycb="YCB-Video $FRAME, object $OBJ (from $DATA)"
fi

cp "$ROOT/scripts/gpu_device_bench.sh" "$BUNDLE/run.sh"
chmod -R u+w "$BUNDLE"
chmod 755 "$BUNDLE/run.sh"
{
  echo "posefilter gpu bundle"
  echo "build: $BUILD"
  echo "commit: $(git -C "$ROOT" rev-parse HEAD 2>/dev/null || echo unknown)$(git -C "$ROOT" diff --quiet HEAD 2>/dev/null || echo ' (with uncommitted changes)')"
  echo "glibc: ${glibc:-unknown}"
  echo "ycb: $ycb"
  echo "libraries:"
  (cd "$BUNDLE/lib" && ls -1)
} >"$BUNDLE/MANIFEST.txt"

# Keep a bundle inside the repository out of git.
case "$BUNDLE/" in
  "$ROOT"/*)
    rel="/${BUNDLE#"$ROOT"/}/"
    exclude="$(git -C "$ROOT" rev-parse --git-path info/exclude 2>/dev/null || true)"
    if [[ -n "$exclude" ]]; then
      [[ "$exclude" == /* ]] || exclude="$ROOT/$exclude"
      mkdir -p "$(dirname "$exclude")"
      touch "$exclude"
      grep -qxF "$rel" "$exclude" || echo "$rel" >>"$exclude"
    fi
    ;;
esac

echo "gpu_bundle: $BUNDLE"
echo "  $ycb"
echo "  glibc ${glibc:-unknown}, $(find "$BUNDLE/lib" -type f | wc -l) libraries"
echo "  size: $(du -sh "$BUNDLE" | cut -f1) ($(du -sb "$BUNDLE" | cut -f1) bytes)"
echo "run it: bash $BUNDLE/run.sh   (outputs in \$OUT, default ./gpu_out)"
