#!/usr/bin/env bash
# The worked example of docs/DATASETS.md: run-dataset on the first N frames of the YCB-Video
# folder $POSEFILTER_DATA/ycbv (else ../shared/data/ycbv; README "Data") (ground-truth boxes jittered by 8 px as the prior, small budget), then
# eval --dataset on the same frames. Resumable: rerun to continue an interrupted run.
#   usage: scripts/ycbv_bop_example.sh [N frames (default 3)] [output dir (default build/ycbv_bop)]
set -euo pipefail
cd "$(dirname "$0")/.."
N="${1:-3}"
OUT="${2:-build/ycbv_bop}"
BIN="${POSEFILTER:-build/release/posefilter}"
DATA="${POSEFILTER_DATA:-../shared/data}/ycbv"
[ -x "$BIN" ] || { echo "no $BIN: run scripts/build.sh (or set POSEFILTER=path/to/posefilter)" >&2; exit 1; }
[ -d "$DATA" ] || { echo "no $DATA (the YCB-Video frames: set POSEFILTER_DATA, scripts/get_data.sh ycbv)" >&2; exit 1; }
mkdir -p "$OUT"
"$BIN" run-dataset --dataset "$DATA" --gt-boxes 8 --out "$OUT/ycbv.csv" --limit "$N" \
  --particles 200 --iterations 12 --restarts 1
"$BIN" eval --dataset "$DATA" --results "$OUT/ycbv.csv" --limit "$N" --json "$OUT/ycbv_eval.json"
