#!/usr/bin/env python3
"""Summary of scripts/rtl/synth.sh's Yosys runs: per-module resources and logic levels, the
raster core as the sum of its parts, and the 5- and 10-core design estimates.

Usage: synth_report.py WORK_DIR SECONDS [OUT_JSON]
WORK_DIR holds parts.txt (name|count in one core, or pM for a module of the M-core pipeline
around the cores) and, per part, NAME.stat (Yosys `stat`) and NAME.levels (netlist_levels.py's
JSON), or NAME.reused (the part's entry of an earlier output JSON, synth.sh --only/--reuse).
"""
import json
import os
import re
import sys

# XCZU9EG (ZCU102): CLB LUTs (logic and memory together), flip-flops, DSP48E2, RAMB36.
DEVICE = {"name": "XCZU9EG", "lut": 274080, "ff": 548160, "dsp": 2520, "bram36": 912}

# Logic-level budget of one clock at 200 MHz on UltraScale+ (docs/HARDWARE.md §12, "Timing
# proxy"): 5.0 ns less clock-to-out, setup and clock uncertainty (≈ 0.5 ns) leaves ≈ 4.5 ns; a
# level (a LUT and the net into it) costs ≈ 0.4–0.45 ns on a routed -1/-2 part.
LEVEL_BUDGET = 10

# The rest of the design (FT chain, sample info, sorter, resampling, diffusion, initialisation,
# AXI adapters) is not synthesised here: it is the component estimate of docs/HARDWARE.md §13
# ("rest of the design"), less the parts that are RTL in weigh_pipeline.sv and synthesised with
# it (the "pM" parts): the weight merger's divider (50 stages, ≈ 6 500 LUT, ≈ 3 200 FF in the
# estimate), its ρ memory (2 BRAM36), the depth distributor's depth BRAM (114) and the vertex
# multiplier's model memories (3.5).
REST_BEFORE_RTL = {"lut": 55000, "lutram": 2000, "ff": 60000, "dsp": 50, "bram36": 185}
NOW_RTL = {"lut": 6500, "lutram": 0, "ff": 3200, "dsp": 0, "bram36": 119.5}
REST = {k: REST_BEFORE_RTL[k] - NOW_RTL[k] for k in REST_BEFORE_RTL}

# LUTs per LUT-based memory or shift-register cell (UltraScale+ CLB primitives).
LUTRAM_LUTS = {"RAM32X1S": 1, "RAM32X1D": 2, "RAM64X1S": 1, "RAM64X1D": 2, "RAM128X1S": 2,
               "RAM128X1D": 4, "RAM256X1S": 4, "RAM256X1D": 8, "RAM32M": 4, "RAM64M": 4,
               "RAM32M16": 8, "RAM64M8": 8, "SRL16E": 1, "SRLC32E": 1}


def counts(stat_path):
    text = open(stat_path).read()
    if "=== design hierarchy ===" in text:
        text = text.split("=== design hierarchy ===", 1)[1]
    cells = {}
    for line in text.splitlines():
        m = re.match(r"\s+(\S+)\s+(\d+)\s*$", line)
        if m and not m.group(1).startswith("$"):
            cells[m.group(1)] = cells.get(m.group(1), 0) + int(m.group(2))
    return {
        "lut": sum(n for k, n in cells.items() if re.fullmatch(r"LUT[1-6]", k)),
        "lutram": sum(n * LUTRAM_LUTS[k] for k, n in cells.items() if k in LUTRAM_LUTS),
        "ff": sum(cells.get(k, 0) for k in ("FDRE", "FDSE", "FDCE", "FDPE")),
        "carry": sum(n for k, n in cells.items() if k.startswith("CARRY")),
        "dsp": cells.get("DSP48E2", 0),
        "bram36": cells.get("RAMB36E2", 0) + 0.5 * cells.get("RAMB18E2", 0),
    }


def main():
    work, secs = sys.argv[1], int(sys.argv[2])
    out = sys.argv[3] if len(sys.argv) > 3 else ""
    modules, core = {}, {"lut": 0, "lutram": 0, "ff": 0, "carry": 0, "dsp": 0, "bram36": 0}
    pipe = {}  # M → the sum of the M-core pipeline's modules around the cores
    core_levels, core_dsp_series = 0, 0
    reused = []
    for line in open(f"{work}/parts.txt"):
        name, count = line.strip().split("|")
        if os.path.exists(f"{work}/{name}.reused"):
            r = json.load(open(f"{work}/{name}.reused"))
            c = {k: r[k] for k in ("lut", "lutram", "ff", "carry", "dsp", "bram36")}
            lv = {"logic_levels": r["logic_levels"], "dsp_in_series": r["dsp_in_series"],
                  "path": r["longest_path"]}
            reused.append(name)
        else:
            c = counts(f"{work}/{name}.stat")
            lv = json.load(open(f"{work}/{name}.levels"))
        if count.startswith("p"):  # a module of the M-core pipeline
            m = int(count[1:])
            modules[name] = dict(c, logic_levels=lv["logic_levels"], level_budget=LEVEL_BUDGET,
                                 dsp_in_series=lv["dsp_in_series"], count_in_core=0,
                                 pipeline_cores=m, longest_path=lv["path"])
            acc = pipe.setdefault(m, {"lut": 0, "lutram": 0, "ff": 0, "carry": 0, "dsp": 0,
                                      "bram36": 0, "logic_levels": 0, "parts": []})
            for k in ("lut", "lutram", "ff", "carry", "dsp", "bram36"):
                acc[k] += c[k]
            acc["logic_levels"] = max(acc["logic_levels"], lv["logic_levels"])
            acc["parts"].append(name)
            continue
        modules[name] = dict(c, logic_levels=lv["logic_levels"], level_budget=LEVEL_BUDGET,
                             dsp_in_series=lv["dsp_in_series"], count_in_core=int(count),
                             longest_path=lv["path"])
        for k in core:
            core[k] += c[k] * int(count)
        if int(count):
            core_levels = max(core_levels, lv["logic_levels"])
            core_dsp_series = max(core_dsp_series, lv["dsp_in_series"])
    modules["raster_core"] = dict(core, logic_levels=core_levels, level_budget=LEVEL_BUDGET,
                                  dsp_in_series=core_dsp_series, count_in_core=1,
                                  composed_of="raster_core_shell + rc_div_iz + 2 x rc_div_snap + rc_div_z")
    for m, acc in sorted(pipe.items()):
        modules[f"weigh_pipeline_glue_m{m}"] = {
            k: acc[k] for k in ("lut", "lutram", "ff", "carry", "dsp", "bram36", "logic_levels")}
        modules[f"weigh_pipeline_glue_m{m}"].update(
            level_budget=LEVEL_BUDGET, count_in_core=0, pipeline_cores=m,
            composed_of=" + ".join(acc["parts"]))
    designs = []
    for n in (5, 10):
        g = pipe.get(n, {"lut": 0, "lutram": 0, "ff": 0, "dsp": 0, "bram36": 0})
        lut = n * (core["lut"] + core["lutram"]) + g["lut"] + g["lutram"] + REST["lut"] + REST["lutram"]
        d = {"cores": n, "lut": lut, "lut_fraction": round(lut / DEVICE["lut"], 4),
             "ff": n * core["ff"] + g["ff"] + REST["ff"], "dsp": n * core["dsp"] + g["dsp"] + REST["dsp"],
             "bram36": n * core["bram36"] + g["bram36"] + REST["bram36"],
             "pipeline_glue": {k: g[k] for k in ("lut", "lutram", "ff", "dsp", "bram36")}}
        d["ff_fraction"] = round(d["ff"] / DEVICE["ff"], 4)
        d["dsp_fraction"] = round(d["dsp"] / DEVICE["dsp"], 4)
        d["bram36_fraction"] = round(d["bram36"] / DEVICE["bram36"], 4)
        designs.append(d)

    print(f"{'module':<24} {'x':>2} {'LUT':>7} {'LUTRAM':>7} {'FF':>7} {'CARRY':>6} {'DSP':>4} "
          f"{'BRAM36':>6} {'levels':>6} {'budget':>6} {'DSPser':>6}")
    for name, c in modules.items():
        print(f"{name:<24} {c['count_in_core']:>2} {c['lut']:>7} {c['lutram']:>7} {c['ff']:>7} "
              f"{c['carry']:>6} {c['dsp']:>4} {c['bram36']:>6g} {c['logic_levels']:>6} "
              f"{c['level_budget']:>6} {c.get('dsp_in_series', 0):>6}")
    for d in designs:
        print(f"{d['cores']:>2} cores: LUT {d['lut']} ({100 * d['lut_fraction']:.1f} % of "
              f"{DEVICE['lut']}), FF {d['ff']}, DSP {d['dsp']}, BRAM36 {d['bram36']:g}")
    print(f"synthesis: {secs} s, Yosys synth_xilinx -family xcup")
    if reused:
        print(f"reused from an earlier run (not synthesised): {', '.join(reused)}")
    if out:
        extra = {"reused": reused} if reused else {}
        with open(out, "w") as f:
            json.dump({"modules": modules, "designs": designs, "device": DEVICE, **extra,
                       "rest_of_design_estimate": REST,
                       "rest_of_design_estimate_before_rtl": REST_BEFORE_RTL,
                       "lut_definition": "module lut: logic LUTs (LUT1-LUT6); lutram: LUTs used as "
                                         "distributed RAM or shift registers; design lut: both, "
                                         "against the device's CLB LUTs",
                       "synth_seconds": secs,
                       "tool": "yosys 0.23 synth_xilinx -family xcup (scripts/rtl/synth.sh)"},
                      f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
