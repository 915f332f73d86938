#!/usr/bin/env bash
# Synthesises the RTL raster core (src/hw/rtl/*.sv) with Yosys for UltraScale+
# (synth_xilinx -family xcup), per module: LUT, FF, DSP48E2, block RAM and a timing proxy (the
# longest register-to-register path in logic levels, scripts/rtl/netlist_levels.py), and
# composes the 5- and 10-core design estimates.
#
# Usage: scripts/rtl/synth.sh [--json FILE] [--only NAME,NAME,... --reuse JSON]
#   --json FILE  write {"modules": {NAME: {...}}, "designs": [{"cores": 5|10, ...}], ...}
#   --only LIST  synthesise only these parts (names below, e.g. vertex_multiplier_m5,
#                vertex_multiplier_m10 after a change to that module alone) and take every other
#                part's figures from --reuse JSON (an earlier output of this script for the same
#                sources of those parts); the output lists the reused parts ("reused")
# Env: YOSYS (default yosys), SYNTH_JOBS (parallel Yosys runs, default 2).
#
# Parts, each its own flattened Yosys run (one flattened run of the whole core does not finish
# in 45 minutes on a 2-core machine: Yosys's constant propagation through the dividers):
#   raster_core_shell  the core with its four rc_div instances as black boxes
#   rc_div_iz          the 1/W divider with its constant dividend (div_context.sv)
#   rc_div_snap        one snapping divider (the core has two: x and y)
#   rc_div_z           the depth divider with its dividend's 46 zero bits (div_context.sv)
#   rc_fifo, rc_compare  the triangle FIFO and CompareFragment on their own (they are also
#                      inside raster_core_shell, so they do not add to the core's sum)
# and the weighing pipeline's modules around the cores (weigh_pipeline.sv), each at M = 5 and
# M = 10 cores (their per-core FIFOs, comparators and multiplexers grow with M):
#   ft_distributor_mM, vertex_multiplier_mM, depth_distributor_mM, weight_merger_mM
# The core (`raster_core`) is the sum shell + iz + 2 × snap + z: the parts share no logic. The
# M-core pipeline is M cores + its four modules at M; the design adds the estimate of the rest
# (synth_report.py).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rtl=$root/src/hw/rtl
yosys=${YOSYS:-yosys}
jobs=${SYNTH_JOBS:-2}
out_json=
only=
reuse=
usage="usage: scripts/rtl/synth.sh [--json FILE] [--only NAME,NAME,... --reuse JSON]"
while [ $# -gt 0 ]; do
  case "$1" in
    --json) out_json=${2:?--json needs a file}; shift 2 ;;
    --json=*) out_json=${1#--json=}; shift ;;
    --only) only=${2:?--only needs a list of parts}; shift 2 ;;
    --reuse) reuse=${2:?--reuse needs a JSON file}; shift 2 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
if [ -n "$only" ] && [ -z "$reuse" ]; then
  echo "synth.sh: --only needs --reuse JSON (the figures of the other parts)" >&2
  exit 2
fi
if [ -n "$reuse" ]; then
  # Read it now: --reuse and --json may name the same file.
  reuse_copy=$(mktemp)
  cp "$reuse" "$reuse_copy"
  reuse=$reuse_copy
fi
if ! command -v "$yosys" >/dev/null; then
  echo "synth.sh: needs Yosys ('$yosys' not found; scripts/setup.sh hw installs it)" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work" ${reuse:+"$reuse"}' EXIT

syn="synth_xilinx -family xcup -flatten -noiopad"
# name|count in one core|top|yosys script (read + synth)
parts=(
  "raster_core_shell|1|raster_core|read_verilog -sv -lib $rtl/rc_div.sv; read_verilog -sv $rtl/rc_pkg.sv $rtl/rc_delay.sv $rtl/rc_fifo.sv $rtl/rc_compare.sv $rtl/rc_vertex_stage.sv $rtl/raster_core.sv; $syn -top raster_core"
  "rc_div_iz|1|div_iz_context|read_verilog -sv $rtl/rc_div.sv $here/div_context.sv; $syn -top div_iz_context"
  "rc_div_snap|2|rc_div|read_verilog -sv $rtl/rc_div.sv; chparam -set QW 21 -set NW 61 -set DW 51 -set PAD 9 rc_div; $syn -top rc_div"
  "rc_div_z|1|div_z_context|read_verilog -sv $rtl/rc_div.sv $here/div_context.sv; $syn -top div_z_context"
  "rc_fifo|0|rc_fifo|read_verilog -sv $rtl/rc_fifo.sv; chparam -set W 446 -set DEPTH 16 rc_fifo; $syn -top rc_fifo"
  "rc_compare|0|rc_compare|read_verilog -sv $rtl/rc_compare.sv; $syn -top rc_compare"
)
# Pipeline modules: count field pM = part of the M-core pipeline.
for m in 5 10; do
  parts+=(
    "ft_distributor_m$m|p$m|ft_distributor|read_verilog -sv $rtl/ft_distributor.sv; chparam -set M $m ft_distributor; $syn -top ft_distributor"
    "vertex_multiplier_m$m|p$m|vertex_multiplier|read_verilog -sv $rtl/rc_fifo.sv $rtl/vertex_multiplier.sv; chparam -set M $m vertex_multiplier; $syn -top vertex_multiplier"
    "depth_distributor_m$m|p$m|depth_distributor|read_verilog -sv $rtl/rc_fifo.sv $rtl/depth_distributor.sv; chparam -set M $m depth_distributor; $syn -top depth_distributor"
    "weight_merger_m$m|p$m|weight_merger|read_verilog -sv $rtl/rc_div.sv $rtl/rc_delay.sv $rtl/rc_fifo.sv $rtl/weight_merger.sv; chparam -set M $m weight_merger; $syn -top weight_merger"
  )
done

start=$(date +%s)
run_part() {
  local name=${1%%|*} rest=${1#*|}
  rest=${rest#*|}
  local top=${rest%%|*} script=${rest#*|}
  "$yosys" -q -l "$work/$name.log" \
    -p "$script; tee -q -o $work/$name.stat stat; write_json $work/$name.json" >/dev/null 2>&1 &&
    /usr/bin/python3 "$here/netlist_levels.py" "$work/$name.json" "$top" > "$work/$name.levels"
}
pids=()
for part in "${parts[@]}"; do
  name=${part%%|*}
  if [ -n "$only" ] && [[ ",$only," != *",$name,"* ]]; then
    # Not re-synthesised: its figures from the --reuse JSON (synth_report.py reads NAME.reused).
    /usr/bin/python3 -c 'import json, sys; json.dump(json.load(open(sys.argv[1]))["modules"][sys.argv[2]], sys.stdout)' \
      "$reuse" "$name" > "$work/$name.reused" || { echo "synth.sh: $name is not in $reuse" >&2; exit 1; }
    continue
  fi
  run_part "$part" &
  pids+=($!)
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
done
status=0
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
if [ $status -ne 0 ]; then
  echo "synth.sh: a Yosys run failed; logs:" >&2
  tail -n 20 "$work"/*.log >&2
  exit 1
fi
end=$(date +%s)

printf '%s\n' "${parts[@]}" | cut -d'|' -f1,2 > "$work/parts.txt"
/usr/bin/python3 "$here/synth_report.py" "$work" "$((end - start))" "$out_json"
