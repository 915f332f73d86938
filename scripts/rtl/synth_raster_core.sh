#!/usr/bin/env bash
# Synthesises the RTL raster core (src/hw/rtl/*.sv, top `raster_core`) with Yosys for
# UltraScale+ (synth_xilinx -family xcup) and prints its LUT, FF, DSP48E2, BRAM and LUTRAM
# counts. Usage: scripts/rtl/synth_raster_core.sh [out.json]
#   out.json  also write the counts (per part and in total, and the run time) as JSON
# Env: YOSYS (default yosys), SYNTH_JOBS (parallel Yosys runs, default 2).
#
# The core is synthesised in four parts, which takes minutes where one flattened run takes
# more than 45 minutes on a 2-core machine (Yosys's constant propagation through the
# dividers' stages): `raster_core` with its four `rc_div` instances as black boxes, and each
# divider on its own with the constant inputs it has in the core (div_context.sv): the 1/W
# divider, one snapping divider (counted twice: x and y) and the depth divider. The parts
# share no logic, so the sum is the core's count; optimisations across the divider
# boundaries (none expected: their other inputs are computed) are not made.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rtl=$root/src/hw/rtl
yosys=${YOSYS:-yosys}
jobs=${SYNTH_JOBS:-2}
out_json=${1:-}
if ! command -v "$yosys" >/dev/null; then
  echo "synth_raster_core.sh: needs Yosys ('$yosys' not found; scripts/setup.sh hw installs it)" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# name|count|yosys script
parts=(
  "raster_core|1|read_verilog -sv -lib $rtl/rc_div.sv; read_verilog -sv $rtl/rc_delay.sv $rtl/rc_fifo.sv $rtl/rc_compare.sv $rtl/raster_core.sv; synth_xilinx -family xcup -top raster_core -noiopad"
  "div_iz|1|read_verilog -sv $rtl/rc_div.sv $here/div_context.sv; synth_xilinx -family xcup -top div_iz_context -flatten -noiopad"
  "div_snap|2|read_verilog -sv $rtl/rc_div.sv; chparam -set QW 22 -set NW 62 -set DW 54 -set PAD 10 rc_div; synth_xilinx -family xcup -top rc_div -flatten -noiopad"
  "div_z|1|read_verilog -sv $rtl/rc_div.sv $here/div_context.sv; synth_xilinx -family xcup -top div_z_context -flatten -noiopad"
)

start=$(date +%s)
run_part() {
  local name=${1%%|*} rest=${1#*|}
  local script=${rest#*|}
  "$yosys" -q -l "$work/$name.log" -p "$script; tee -o $work/$name.stat stat" >/dev/null 2>&1
}
pids=()
for part in "${parts[@]}"; do
  run_part "$part" &
  pids+=($!)
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
done
status=0
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
if [ $status -ne 0 ]; then
  echo "synth_raster_core.sh: a Yosys run failed; logs:" >&2
  tail -n 20 "$work"/*.log >&2
  exit 1
fi
end=$(date +%s)

printf '%s\n' "${parts[@]}" | cut -d'|' -f1,2 > "$work/parts.txt"
/usr/bin/python3 - "$work" "$((end - start))" "$out_json" <<'PY'
import json, re, sys
work, secs, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
# LUT-based memories and shift registers, in LUTs per cell (UltraScale+ CLB primitives).
lutram_luts = {"RAM32X1S": 1, "RAM32X1D": 2, "RAM64X1S": 1, "RAM64X1D": 2, "RAM128X1S": 2, "RAM128X1D": 4,
               "RAM256X1S": 4, "RAM256X1D": 8, "RAM32M": 4, "RAM64M": 4, "RAM32M16": 8, "RAM64M8": 8,
               "SRL16E": 1, "SRLC32E": 1}
def counts(stat):
    # A hierarchical design's `stat` lists each module, then the whole hierarchy: count that.
    text = open(stat).read()
    if "=== design hierarchy ===" in text:
        text = text.split("=== design hierarchy ===", 1)[1]
    cells = {}
    for line in text.splitlines():
        m = re.match(r"\s+(\S+)\s+(\d+)\s*$", line)
        if m and not m.group(1).startswith("$"):
            cells[m.group(1)] = cells.get(m.group(1), 0) + int(m.group(2))
    c = {
        "LUT": sum(n for k, n in cells.items() if re.fullmatch(r"LUT[1-6]", k)),
        "LUTRAM_SRL_LUTs": sum(n * lutram_luts[k] for k, n in cells.items() if k in lutram_luts),
        "FF": sum(cells.get(k, 0) for k in ("FDRE", "FDSE", "FDCE", "FDPE")),
        "CARRY": sum(n for k, n in cells.items() if k.startswith("CARRY")),
        "DSP48E2": cells.get("DSP48E2", 0),
        "RAMB36E2": cells.get("RAMB36E2", 0),
        "RAMB18E2": cells.get("RAMB18E2", 0),
    }
    return c
parts, total = {}, {}
for line in open(f"{work}/parts.txt"):
    name, count = line.strip().split("|")
    c = counts(f"{work}/{name}.stat")
    parts[name] = dict(c, count=int(count))
    for k, v in c.items():
        total[k] = total.get(k, 0) + v * int(count)
total["BRAM36_equivalent"] = total["RAMB36E2"] + 0.5 * total["RAMB18E2"]
print(f"{'part':<12} {'x':>2} {'LUT':>7} {'LUTRAM/SRL':>10} {'FF':>7} {'CARRY':>6} {'DSP':>4} {'RAMB36':>6} {'RAMB18':>6}")
for name, c in parts.items():
    print(f"{name:<12} {c['count']:>2} {c['LUT']:>7} {c['LUTRAM_SRL_LUTs']:>10} {c['FF']:>7} {c['CARRY']:>6} "
          f"{c['DSP48E2']:>4} {c['RAMB36E2']:>6} {c['RAMB18E2']:>6}")
print(f"{'one core':<12} {'':>2} {total['LUT']:>7} {total['LUTRAM_SRL_LUTs']:>10} {total['FF']:>7} {total['CARRY']:>6} "
      f"{total['DSP48E2']:>4} {total['RAMB36E2']:>6} {total['RAMB18E2']:>6}")
print(f"synthesis: {secs} s, yosys synth_xilinx -family xcup")
if out:
    with open(out, "w") as f:
        json.dump({"core": total, "parts": parts, "synth_seconds": secs,
                   "tool": "yosys synth_xilinx -family xcup, four parts (scripts/rtl/synth_raster_core.sh)"}, f, indent=2)
        f.write("\n")
PY
