#!/usr/bin/env bash
# Synthesises the RTL raster core (src/hw/rtl/*.sv, top `raster_core`) with Yosys for
# UltraScale+ (synth_xilinx -family xcup) and prints its LUT, FF, DSP48E2, BRAM and LUTRAM
# counts. Usage: scripts/rtl/synth_raster_core.sh [out.json]
#   out.json  also write the counts (and the run time) as JSON
# Env: YOSYS (default yosys), SYNTH_LOG (default a temporary file: Yosys's full log).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rtl=$root/src/hw/rtl
yosys=${YOSYS:-yosys}
out_json=${1:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
log=${SYNTH_LOG:-$work/yosys.log}

start=$(date +%s)
"$yosys" -q -l "$log" -p "
read_verilog -sv $rtl/rc_div.sv $rtl/rc_delay.sv $rtl/rc_fifo.sv $rtl/rc_compare.sv $rtl/raster_core.sv
synth_xilinx -family xcup -top raster_core -flatten
tee -o $work/stat.txt stat
" >/dev/null
end=$(date +%s)

python3 - "$work/stat.txt" "$((end - start))" "$out_json" <<'PY'
import json, re, sys
stat, secs, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
cells = {}
for line in open(stat):
    m = re.match(r"\s+(\S+)\s+(\d+)\s*$", line)
    if m:
        cells[m.group(1)] = cells.get(m.group(1), 0) + int(m.group(2))
def total(pred):
    return sum(n for c, n in cells.items() if pred(c))
lut = total(lambda c: re.fullmatch(r"LUT[1-6]", c) is not None)
lutram_cells = {c: n for c, n in cells.items() if re.match(r"RAM(32|64|128|256)[XM]", c) or c.startswith("SRL")}
res = {
    "LUT": lut,
    "FF": total(lambda c: c in ("FDRE", "FDSE", "FDCE", "FDPE")),
    "DSP48E2": cells.get("DSP48E2", 0),
    "RAMB36E2": cells.get("RAMB36E2", 0),
    "RAMB18E2": cells.get("RAMB18E2", 0),
    "LUTRAM_cells": dict(sorted(lutram_cells.items())),
    "CARRY8": cells.get("CARRY8", 0),
    "synth_seconds": secs,
    "tool": "yosys synth_xilinx -family xcup -flatten",
}
res["BRAM36_equivalent"] = res["RAMB36E2"] + 0.5 * res["RAMB18E2"]
for k, v in res.items():
    print(f"{k}: {v}")
if out:
    with open(out, "w") as f:
        json.dump(res, f, indent=2)
        f.write("\n")
PY
