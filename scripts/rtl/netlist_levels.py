#!/usr/bin/env python3
"""Timing proxy of a Yosys-mapped UltraScale+ netlist: the longest register-to-register path
in logic levels.

Reads the JSON that `write_json` writes after `synth_xilinx -family xcup -flatten` and prints
{"logic_levels": L, "dsp_in_series": D, "path": [...]} as JSON. A path starts at a top-level
input, a register output (FD*, a block RAM's read data, a DSP48E2 whose P register is on, a
LUTRAM/SRL read that is not addressed combinationally, a black box's output) and ends at a
register input, a top-level output or a black box's input. What counts on it:

  LUT1–LUT6, MUXF7/F8/F9       1 level each
  CARRY4                      1/2 level: Yosys 0.23 maps every carry chain to CARRY4 cells,
                              and UltraScale+ has CARRY8 (8 bits, one cell); two CARRY4 in a
                              cascade are one CARRY8, i.e. one level as Vivado counts them
  LUTRAM/SRL read             1 level (address → data is a LUT read)
  DSP48E2 without P register  DSP_LEVELS levels (the multiplier and ALU between registers)

The sum is rounded up. `dsp_in_series` is the most DSP48E2 cells on one such path.
Usage: netlist_levels.py netlist.json [top]
"""
import json
import math
import re
import sys

# A combinational DSP48E2 (A/B → M → ALU → P with neither M nor P register) takes about as
# long as four LUT levels with their nets at UltraScale+ speeds (≈ 1.8 ns of 5 ns).
DSP_LEVELS = 4

WEIGHT = {"MUXF7": 1, "MUXF8": 1, "MUXF9": 1, "CARRY4": 0.5, "CARRY8": 1}


def is_lut(t):
    return re.fullmatch(r"LUT[1-6]", t) is not None


def param_on(params, name):
    v = params.get(name)
    if v is None:
        return False
    try:
        return int(str(v), 2) != 0 if re.fullmatch(r"[01]+", str(v)) else int(v) != 0
    except ValueError:
        return False


def arcs(cell):
    """(weight, comb input pins, output pins) of a cell; weight None: sequential only."""
    t, conns, dirs = cell["type"], cell["connections"], cell.get("port_directions", {})
    outs = [p for p, d in dirs.items() if d == "output"]
    ins = [p for p, d in dirs.items() if d == "input"]
    if is_lut(t):
        return 1, [p for p in conns if p.startswith("I")], ["O"]
    if t in WEIGHT:
        return WEIGHT[t], [p for p in ins if p in ("CI", "CYINIT", "DI", "S", "I0", "I1", "I2", "I3")], outs
    if re.match(r"RAM\d+(X\d+[SD]|M\d*)$", t):  # LUTRAM: the read address is combinational
        return 1, [p for p in ins if re.match(r"(ADDR[A-H]|A\d?|DPRA\d?|RADR)", p)], outs
    if t.startswith("SRL"):
        return 1, [p for p in ins if re.fullmatch(r"A\d?", p)], [p for p in outs if p in ("Q",)]
    if t == "DSP48E2":
        prm = cell.get("parameters", {})
        if param_on(prm, "PREG"):
            return None, [], outs
        comb = []
        for p in ins:
            if p in ("CLK",) or p.startswith(("CE", "RST")):
                continue
            if p.startswith(("A", "B", "D")) and not p.startswith(("ALUMODE",)):
                if param_on(prm, "MREG") and p[0] in "AB" or param_on(prm, p[0] + "REG"):
                    continue
            if p.startswith("C") and not p.startswith("CARRY") and param_on(prm, "CREG"):
                continue
            comb.append(p)
        return DSP_LEVELS, comb, outs
    return None, [], outs  # FD*, RAMB*, black boxes, anything else: registered boundary


def main():
    data = json.load(open(sys.argv[1]))
    mods = data["modules"]
    top = sys.argv[2] if len(sys.argv) > 2 else next(
        n for n, m in mods.items() if m.get("attributes", {}).get("top"))
    m = mods[top]
    drivers = {}  # bit → (cell, weight) for combinational outputs
    comb_in = {}  # cell → list of input bits that propagate
    info = {}
    for name, cell in m["cells"].items():
        w, cins, outs = arcs(cell)
        info[name] = (w, cell["type"])
        if w is None:
            continue
        comb_in[name] = [b for p in cins for b in cell["connections"].get(p, []) if isinstance(b, int)]
        for p in outs:
            for b in cell["connections"].get(p, []):
                if isinstance(b, int):
                    drivers[b] = name
    # Longest path ending at each combinational cell's output (memoised DFS).
    sys.setrecursionlimit(1000000)
    memo = {}

    def depth(cell):
        if cell in memo:
            if memo[cell] is None:
                raise RuntimeError(f"combinational loop through {cell}")
            return memo[cell]
        memo[cell] = None
        best = (0.0, 0, None)
        for b in comb_in[cell]:
            c = drivers.get(b)
            if c is not None:
                d = depth(c)
                if d[0] > best[0]:
                    best = (d[0], d[1], c)
        w, t = info[cell]
        memo[cell] = (best[0] + w, best[1] + (t == "DSP48E2"), best[2])
        return memo[cell]

    worst, worst_cell, dsp_max = 0.0, None, 0
    for c in comb_in:
        d = depth(c)
        if d[0] > worst:
            worst, worst_cell = d[0], c
        dsp_max = max(dsp_max, d[1])
    path = []
    c = worst_cell
    while c is not None:
        path.append(f"{info[c][1]}:{c}")
        c = memo[c][2]
    print(json.dumps({"logic_levels": math.ceil(worst), "dsp_in_series": dsp_max,
                      "path": list(reversed(path))[:40]}))


if __name__ == "__main__":
    main()
