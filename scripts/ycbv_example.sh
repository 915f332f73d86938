#!/usr/bin/env bash
# Pose estimation on real YCB-Video frames with a ground-truth-derived stage-1 prior.
#
# usage: scripts/ycbv_example.sh [DATA]      DATA default: $POSEFILTER_DATA/ycbv, else ../shared/data/ycbv
#                                            (from the repo root; README "Data")
#
# For each DATA/scenes/<frame>/ (depth.png, rgb.png, camera.json, gt.json):
#   1. posefilter gt-detections: each gt object's silhouette box, jittered (σ 8 px, seed 1);
#   2. posefilter estimate: every gt object's mesh DATA/models/<obj>.ply (metres), --prior
#      the detections, results.json + overlay.png (on the RGB frame);
#   3. posefilter eval: ADD/ADD-S against gt.json with the official points DATA/models/points/<obj>.xyz;
# then a per-object table: frames, mean ADD-S (mm), recall of ADD-S < 10 % of the diameter.
#
# Environment:
#   POSEFILTER  the binary (default: build/release/posefilter)
#   OUT         output folder (default: build/ycbv_example), one subfolder per frame
#   FRAMES      process only the first N frames (default: all)
#   EXTRA_ARGS  extra `estimate` options, e.g. "--particles 128 --iterations 10" for a quick run
# The YCB meshes have ~16k faces: with the default filter settings a frame of 3 objects takes a few
# seconds on 2 cores (docs/PERFORMANCE.md, "Results").
set -euo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DATA="${1:-${POSEFILTER_DATA:-$ROOT/../shared/data}/ycbv}"
POSEFILTER="${POSEFILTER:-$ROOT/build/release/posefilter}"
OUT="${OUT:-$ROOT/build/ycbv_example}"
FRAMES="${FRAMES:-0}"
EXTRA_ARGS="${EXTRA_ARGS:-}"
PY=/usr/bin/python3

if [[ ! -d "$DATA/scenes" ]]; then
  echo "ycbv_example: no YCB-Video scenes at $DATA/scenes; nothing to do (pass the data folder as \$1)"
  exit 0
fi
if [[ ! -x "$POSEFILTER" ]]; then
  echo "ycbv_example: error: no posefilter binary at $POSEFILTER (run scripts/build.sh or set POSEFILTER)" >&2
  exit 1
fi
if [[ ! "$FRAMES" =~ ^[0-9]+$ ]]; then
  echo "ycbv_example: error: FRAMES must be a non-negative integer, got '$FRAMES'" >&2
  exit 1
fi
MODELS="$DATA/models"
mkdir -p "$OUT"

# Unique object names of a gt.json, one per line.
gt_objects() {
  "$PY" -c '
import json, sys
seen = []
for o in json.load(open(sys.argv[1]))["objects"]:
    if o["obj"] not in seen:
        seen.append(o["obj"])
print("\n".join(seen))' "$1"
}

n=0
evals=()
for scene in "$DATA"/scenes/*/; do
  scene="${scene%/}"
  name="$(basename "$scene")"
  [[ -f "$scene/gt.json" && -f "$scene/depth.png" && -f "$scene/camera.json" ]] || {
    echo "ycbv_example: skipping $scene (no gt.json, depth.png or camera.json)"
    continue
  }
  if [[ "$FRAMES" -gt 0 && "$n" -ge "$FRAMES" ]]; then break; fi
  n=$((n + 1))
  out="$OUT/$name"
  mkdir -p "$out"
  echo "== $name"

  mapfile -t objs < <(gt_objects "$scene/gt.json")
  mesh_args=()
  point_args=()
  for o in "${objs[@]}"; do
    mesh_args+=(--mesh "$o=$MODELS/$o.ply")
    point_args+=(--points "$o=$MODELS/points/$o.xyz")
  done
  rgb_args=()
  [[ -f "$scene/rgb.png" ]] && rgb_args=(--rgb "$scene/rgb.png")

  "$POSEFILTER" gt-detections --gt "$scene/gt.json" --camera "$scene/camera.json" --models-dir "$MODELS" \
    --jitter 8 --seed 1 --out "$out/detections.json"

  start=$(date +%s.%N)
  # shellcheck disable=SC2086  # EXTRA_ARGS is a list of options
  "$POSEFILTER" estimate --depth "$scene/depth.png" --camera "$scene/camera.json" "${mesh_args[@]}" \
    --prior "$out/detections.json" --out "$out/results.json" --overlay "$out/overlay.png" "${rgb_args[@]}" \
    $EXTRA_ARGS
  end=$(date +%s.%N)
  "$PY" -c 'import sys; print("estimate: %.1f s for %s objects" % (float(sys.argv[2]) - float(sys.argv[1]), sys.argv[3]))' \
    "$start" "$end" "${#objs[@]}"

  "$POSEFILTER" eval --results "$out/results.json" --gt "$scene/gt.json" "${mesh_args[@]}" "${point_args[@]}" \
    --json "$out/eval.json"
  evals+=("$out/eval.json")
  echo
done

if [[ ${#evals[@]} -eq 0 ]]; then
  echo "ycbv_example: no usable scene folder in $DATA/scenes"
  exit 0
fi

echo "== summary over ${#evals[@]} frame(s) (outputs in $OUT)"
"$PY" - "${evals[@]}" <<'EOF'
import json, sys
stats = {}  # obj -> [frames, adds_mm list (found results), adds_ok count]
threshold = None
for path in sys.argv[1:]:
    j = json.load(open(path))
    threshold = j["threshold"]
    for o in j["objects"]:
        s = stats.setdefault(o["obj"], [0, [], 0])
        s[0] += 1
        if o["status"] == "ok":
            s[1].append(o["adds_mm"])
        s[2] += 1 if o["adds_ok"] else 0
head = "recall ADD-S<%g%%" % (100 * threshold)
w = max([len("object")] + [len(k) for k in stats])
print("%-*s  %6s  %15s  %s" % (w, "object", "frames", "mean ADD-S (mm)", head))
tot_n = tot_ok = 0
for obj in sorted(stats):
    n, adds, ok = stats[obj]
    mean = "%.1f" % (sum(adds) / len(adds)) if adds else "-"
    if len(adds) < n:
        mean += " (%d missing)" % (n - len(adds))
    print("%-*s  %6d  %15s  %*.2f" % (w, obj, n, mean, len(head), ok / n))
    tot_n += n
    tot_ok += ok
print("%-*s  %6d  %15s  %*.2f" % (w, "all", tot_n, "", len(head), tot_ok / tot_n))
EOF
