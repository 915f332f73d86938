#!/usr/bin/env bash
# Former name of scripts/rtl/synth.sh, kept for the commands that use it:
#   scripts/rtl/synth_raster_core.sh [out.json]  ==  scripts/rtl/synth.sh [--json out.json]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec "$here/synth.sh" ${1:+--json "$1"}
