#!/usr/bin/env bash
# Fetches a real data set and lays it out as posefilter's commands expect (README "Data"):
#
#   scripts/get_data.sh ycbv [DIR] [--images N]
#
# POSEFILTER_DATA=SRC with SRC/ycbv present: checks that local copy of the YCB-Video development
# set against scripts/data/ycbv_dev.sha256 (and copies it to DIR/ycbv when DIR is given).
# Otherwise: downloads BOP's YCB-V archives (models and the first N BOP'19 test images), checks
# each against the size and SHA-256 the hosting publishes, and unpacks them to DIR/ycbv_bop
# (DIR: $POSEFILTER_DATA, else ./data). Prints the `export POSEFILTER_DATA=...` to use.
# The work is scripts/data/get_data.py (Python standard library only).
set -euo pipefail
exec python3 "$(dirname "$0")/data/get_data.py" "$@"
