#!/usr/bin/env python3
"""The ZCU102 board package agrees with the RTL, the register map and the host transport.

  board_package_test.py [--root REPO]

Reads (paths relative to the repository root):
  scripts/board/zcu102_bd.tcl          the block design: its `set` constants, the accelerator's
                                       module reference, its connections, assign_bd_address
  scripts/board/weigh_accel_bd.v       the Verilog wrapper the module reference names
  scripts/board/weigh_accel_overlay.dts the device-tree overlay (UIO and u-dma-buf nodes)
  src/hw/rtl/weigh_accel.sv            the top's port list and its default M
  src/hw/rtl/weigh_regs.json           the register map (addr_bits, data_bits, offsets, buffers)
  src/hw/host/uio_transport.h          kGmemWindows, the default device names and register base
  src/hw/host/verilator_transport.h    kDdrBase (the simulated DDR must be a board address too)
  src/hw/hw_types.h                    the largest call (buffer sizes against the u-dma-buf)
and checks:
  * the wrapper has exactly the top's ports (names, directions, widths), connects each to the
    same-named top port, and tags each AXI port with its interface and signal name;
  * every port of the top belongs to an interface or pin the tcl connects, and every
    accelerator pin the tcl connects exists; clock, reset, interrupt are connected;
  * widths: s_axi_ctrl address = addr_bits (JSON, tcl, wrapper parameter), data = data_bits =
    32 (tcl), strobes = data/8; m_axi_gmem data = the tcl's gmem_data_bits = the HP0 width the
    PS is configured to, address and ID widths, 8-bit burst lengths (AXI4);
  * the address map: s_axi_ctrl's range a power of two ≥ 4 KiB and ≥ 2^addr_bits, its offset
    aligned to it, inside M_AXI_HPM0_FPD's 0xA000_0000–0xAFFF_FFFF window; every register at a
    multiple of 4 with its 32 bits below 2^addr_bits; assign_bd_address uses these values;
  * m_axi_gmem's DDR segments = uio_transport.h's kGmemWindows; kDdrBase lies in one of them;
    the transport's default register_base = ctrl_offset;
  * the overlay: reg = ctrl_offset/ctrl_range, interrupts = <0 irq_spi 4> (level high, the
    wrapper's SENSITIVITY), node names = the transport's defaults, the u-dma-buf holds every
    buffer at its largest (4 KiB aligned) and lies in DDR_LOW by its DMA mask;
  * the part, board part and 200 MHz PL clock; the cores 5 and 10 in the CORES field;
  * where tclsh is installed, the tcl itself runs under it with Vivado's commands stubbed
    (HARNESS: they log their calls): to the end for --cores 5 and for --cores 10 --impl, not
    for --cores 7, with M set and its assign_bd_address calls, as Tcl evaluates them, equal to
    the address map above. (No Vivado here: what Vivado would say of the IP configuration is
    not checked.)
Then the negative controls: broken copies of those files in a scratch folder (each mutation
must apply and must be reported with its expected message). Exit 0 when the real files pass and
every broken copy fails; standard-library Python, about a second at most (most of it Python's
start and the tclsh runs).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

TCL = "scripts/board/zcu102_bd.tcl"
WRAPPER = "scripts/board/weigh_accel_bd.v"
DTS = "scripts/board/weigh_accel_overlay.dts"
TOP = "src/hw/rtl/weigh_accel.sv"
REGS = "src/hw/rtl/weigh_regs.json"
UIO = "src/hw/host/uio_transport.h"
VT = "src/hw/host/verilator_transport.h"
HWT = "src/hw/hw_types.h"
FILES = [TCL, WRAPPER, DTS, TOP, REGS, UIO, VT, HWT]

HPM0_FPD = (0xA000_0000, 0xB000_0000)  # the PS's M_AXI_HPM0_FPD window below 4 GiB
AXI_LITE = ["awaddr", "awvalid", "awready", "wdata", "wstrb", "wvalid", "wready", "bresp", "bvalid",
            "bready", "araddr", "arvalid", "arready", "rdata", "rresp", "rvalid", "rready"]
AXI4_MASTER = AXI_LITE + ["awlen", "awsize", "awburst", "awid", "wlast", "bid", "arlen", "arsize",
                          "arburst", "arid", "rlast", "rid"]
PINS = {"ap_clk", "ap_rst_n", "interrupt"}  # the accelerator's non-AXI pins


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def ports_of(text, module, path):
    """{name: (direction, width)} and the header's text of `module`'s ANSI port list."""
    m = re.search(r"\bmodule\s+" + module + r"\b", text)
    if not m:
        raise ValueError(f"{path}: no module {module}")
    end = text.find(");", m.end())
    header = text[m.end():end]
    ports = {}
    for d, msb, lsb, name in re.findall(
            r"\b(input|output)\s+(?:logic|wire|reg)?\s*(?:\[\s*(\d+)\s*:\s*(\d+)\s*\])?\s*(\w+)", header):
        ports[name] = (d, int(msb) - int(lsb) + 1 if msb else 1)
    return ports, header


def tcl_sets(tcl):
    return dict(re.findall(r"^set\s+(\w+)\s+(\S+)", tcl, flags=re.M))


def tcl_commands(tcl, name):
    """Every `name ...` command of the tcl, continuation lines joined."""
    joined = re.sub(r"\\\n\s*", " ", tcl)
    return [l.strip() for l in joined.split("\n") if l.strip().startswith(name + " ")]


def tcl_value(tcl_vars, token):
    """A number or a $variable of the tcl's `set` lines, as an int."""
    if token.startswith("$"):
        token = tcl_vars.get(token[1:], "")
    return int(token, 0)


def check(root, dry=True):
    """The list of disagreements (empty: the package agrees); dry: with the stubbed tcl runs."""
    errors = []
    err = errors.append
    read = lambda rel: open(os.path.join(root, rel), encoding="utf-8").read()
    try:
        tcl, wrapper_raw, dts, top_raw, uio, hwt = (read(TCL), read(WRAPPER), read(DTS), read(TOP), read(UIO), read(HWT))
        regs = json.loads(read(REGS))
        vt = read(VT) if os.path.exists(os.path.join(root, VT)) else None
    except (OSError, ValueError) as e:
        return [f"cannot read the package: {e}"]
    v = tcl_sets(tcl)
    try:
        num = {k: int(v[k], 0) for k in ("ctrl_offset", "ctrl_range", "ctrl_addr_bits", "ctrl_data_bits",
                                          "hpm0_data_bits", "gmem_data_bits", "gmem_addr_bits", "gmem_id_bits",
                                          "ddr_low_offset", "ddr_low_range", "ddr_high_offset", "ddr_high_range",
                                          "irq_spi", "pl_clk_mhz")}
    except (KeyError, ValueError) as e:
        return [f"{TCL}: a board constant is missing or not a number: {e}"]

    # ---- The top and the wrapper ----
    top_ports, _ = ports_of(strip_comments(top_raw), "weigh_accel", TOP)
    wrapper = strip_comments(wrapper_raw)
    ref = re.search(r"create_bd_cell\s+-type\s+module\s+-reference\s+(\w+)\s+(\w+)", tcl)
    if not ref:
        err(f"{TCL}: no module reference (create_bd_cell -type module -reference …)")
        return errors
    wrapper_module = ref.group(1)
    wrap_ports, wrap_header = ports_of(wrapper, wrapper_module, WRAPPER)
    for name, (d, w) in top_ports.items():
        if name not in wrap_ports:
            err(f"{WRAPPER}: {wrapper_module} lacks weigh_accel's port {name} ({d}, {w} bits)")
        elif wrap_ports[name] != (d, w):
            err(f"{WRAPPER}: port {name} is {wrap_ports[name][0]} {wrap_ports[name][1]} bits, weigh_accel's is {d} {w} bits")
    for name in wrap_ports:
        if name not in top_ports:
            err(f"{WRAPPER}: port {name} is not a port of weigh_accel ({TOP})")
    inst = re.search(r"\bweigh_accel\s*#\s*\(\s*\.M\s*\(\s*M\s*\)\s*\)\s*\w+\s*\((.*?)\)\s*;", wrapper, flags=re.S)
    if not inst:
        err(f"{WRAPPER}: no instance weigh_accel #(.M(M)) …")
        conns = {}
    else:
        conns = dict(re.findall(r"\.(\w+)\s*\(\s*(\w+)\s*\)", inst.group(1)))
    for name in top_ports:
        if conns.get(name) != name:
            err(f"{WRAPPER}: weigh_accel's port {name} is not connected to the wrapper's {name}")
    top_m = re.search(r"parameter\s+int\s+M\s*=\s*(\d+)", top_raw)
    wrap_m = re.search(r"parameter\s+integer\s+M\s*=\s*(\d+)", wrapper)
    if not top_m or not wrap_m or top_m.group(1) != wrap_m.group(1):
        err(f"{WRAPPER}: parameter M's default differs from weigh_accel's ({TOP})")

    # Interface tags: (* X_INTERFACE_INFO = "… BUS SIG" *) before each port.
    tags, params = {}, {}
    for attrs, name in re.findall(r"((?:\(\*.*?\*\)\s*)+)(?:input|output)\s+wire\s*(?:\[[^\]]*\])?\s*(\w+)", wrap_header):
        info = re.search(r'X_INTERFACE_INFO\s*=\s*"([^"]*)"', attrs)
        if info:
            vlnv, bus, sig = info.group(1).split()
            tags[name] = (vlnv, bus, sig)
        par = re.search(r'X_INTERFACE_PARAMETER\s*=\s*"([^"]*)"', attrs)
        if par:
            kv = dict(p.strip().split(None, 1) for p in par.group(1).split(",") if p.strip())
            params[kv.get("XIL_INTERFACENAME", name)] = kv
    buses = {}
    for name in top_ports:
        if name in PINS:
            continue
        m = re.match(r"(s_axi_\w+?|m_axi_\w+?)_([a-z]+)$", name)
        if not m:
            err(f"{TOP}: port {name} is neither an AXI port (s_axi_*/m_axi_*) nor ap_clk, ap_rst_n, interrupt")
            continue
        bus, sig = m.groups()
        buses.setdefault(bus, set()).add(sig)
        want = ("xilinx.com:interface:aximm:1.0", bus, sig.upper())
        if tags.get(name) != want:
            err(f"{WRAPPER}: port {name} is tagged {tags.get(name)}, expected X_INTERFACE_INFO \"{' '.join(want)}\"")
    for pin, sig in (("ap_clk", "clock"), ("ap_rst_n", "reset"), ("interrupt", "interrupt")):
        if pin not in top_ports:
            err(f"{TOP}: weigh_accel has no port {pin}")
        elif not tags.get(pin) or f":signal:{sig}:" not in tags[pin][0]:
            err(f"{WRAPPER}: {pin} is not tagged as a {sig} (X_INTERFACE_INFO)")
    clk = params.get("ap_clk", {})
    if set(clk.get("ASSOCIATED_BUSIF", "").split(":")) != set(buses):
        err(f"{WRAPPER}: ap_clk's ASSOCIATED_BUSIF {clk.get('ASSOCIATED_BUSIF')} is not the AXI interfaces {sorted(buses)}")
    if params.get("ap_rst_n", {}).get("POLARITY") != "ACTIVE_LOW":
        err(f"{WRAPPER}: ap_rst_n is not tagged POLARITY ACTIVE_LOW")
    if params.get("interrupt", {}).get("SENSITIVITY") != "LEVEL_HIGH":
        err(f"{WRAPPER}: interrupt is not tagged SENSITIVITY LEVEL_HIGH (weigh_accel's interrupt is a level)")

    # ---- Interfaces the tcl connects ----
    connects = tcl_commands(tcl, "connect_bd_net") + tcl_commands(tcl, "connect_bd_intf_net")
    accel_refs = set()
    for c in connects:
        accel_refs |= set(re.findall(r"get_bd_(?:intf_)?pins\s+\$accel/(\w+)", c))
    for bus in buses:
        if bus not in accel_refs:
            err(f"{TCL}: weigh_accel's interface {bus} ({len(buses[bus])} ports) is not connected")
    for pin in PINS:
        if pin not in accel_refs:
            err(f"{TCL}: weigh_accel's {pin} is not connected")
    for r in accel_refs:
        if r not in buses and r not in PINS:
            err(f"{TCL}: connects $accel/{r}, which weigh_accel has neither as a port nor as an AXI interface")
    # Which bus is which.
    ctrl = [b for b in buses if b.startswith("s_axi_")]
    gmem = [b for b in buses if b.startswith("m_axi_")]
    if ctrl != ["s_axi_ctrl"] or gmem != ["m_axi_gmem"]:
        err(f"{TOP}: expected one AXI slave s_axi_ctrl and one AXI master m_axi_gmem, found {sorted(buses)}")
        return errors
    for sig in AXI_LITE:
        if sig not in buses["s_axi_ctrl"]:
            err(f"{TOP}: s_axi_ctrl lacks the AXI4-Lite signal {sig}")
    for sig in AXI4_MASTER:
        if sig not in buses["m_axi_gmem"]:
            err(f"{TOP}: m_axi_gmem lacks the AXI4 signal {sig}")
    if not any("$ps/M_AXI_HPM0_FPD" in c for c in connects) or not any("$accel/s_axi_ctrl" in c for c in connects):
        err(f"{TCL}: M_AXI_HPM0_FPD does not reach s_axi_ctrl")
    if not any("$ps/S_AXI_HP0_FPD" in c for c in connects):
        err(f"{TCL}: nothing is connected to S_AXI_HP0_FPD")
    if not any("$ps/pl_ps_irq0" in c for c in connects):
        err(f"{TCL}: nothing drives pl_ps_irq0")

    # ---- Widths ----
    w = lambda p: top_ports.get(p, (None, None))[1]
    ab, db = regs["addr_bits"], regs["data_bits"]
    for p in ("s_axi_ctrl_awaddr", "s_axi_ctrl_araddr"):
        if w(p) != ab or num["ctrl_addr_bits"] != ab:
            err(f"s_axi_ctrl address bits: {p} {w(p)}, {REGS} addr_bits {ab}, {TCL} ctrl_addr_bits {num['ctrl_addr_bits']}")
    for p in ("s_axi_ctrl_wdata", "s_axi_ctrl_rdata"):
        if w(p) != db or db != 32 or num["ctrl_data_bits"] != db:
            err(f"s_axi_ctrl data bits: {p} {w(p)}, {REGS} data_bits {db}, {TCL} ctrl_data_bits {num['ctrl_data_bits']} (AXI4-Lite: 32)")
    if w("s_axi_ctrl_wstrb") != db // 8:
        err(f"{TOP}: s_axi_ctrl_wstrb is {w('s_axi_ctrl_wstrb')} bits for {db} data bits")
    gd = num["gmem_data_bits"]
    for p in ("m_axi_gmem_wdata", "m_axi_gmem_rdata"):
        if w(p) != gd:
            err(f"m_axi_gmem data bits: {p} is {w(p)}, {TCL} gmem_data_bits {gd}")
    if w("m_axi_gmem_wstrb") != gd // 8:
        err(f"{TOP}: m_axi_gmem_wstrb is {w('m_axi_gmem_wstrb')} bits for {gd} data bits")
    for p in ("m_axi_gmem_awaddr", "m_axi_gmem_araddr"):
        if w(p) != num["gmem_addr_bits"]:
            err(f"m_axi_gmem address bits: {p} is {w(p)}, {TCL} gmem_addr_bits {num['gmem_addr_bits']}")
    for p in ("m_axi_gmem_awid", "m_axi_gmem_arid", "m_axi_gmem_bid", "m_axi_gmem_rid"):
        if w(p) != num["gmem_id_bits"]:
            err(f"m_axi_gmem ID bits: {p} is {w(p)}, {TCL} gmem_id_bits {num['gmem_id_bits']}")
    for p in ("m_axi_gmem_awlen", "m_axi_gmem_arlen"):
        if w(p) != 8:
            err(f"{TOP}: {p} is {w(p)} bits; AXI4 burst lengths are 8")
    if gd not in (32, 64, 128) or num["hpm0_data_bits"] not in (32, 64, 128):
        err(f"{TCL}: gmem_data_bits {gd} / hpm0_data_bits {num['hpm0_data_bits']}: the PS ports take 32, 64 or 128")
    if not re.search(r"CONFIG\.PSU__SAXIGP2__DATA_WIDTH\s+\$gmem_data_bits", tcl):
        err(f"{TCL}: S_AXI_HP0_FPD's width (PSU__SAXIGP2__DATA_WIDTH) is not set to $gmem_data_bits")
    if not re.search(r"CONFIG\.PSU__USE__S_AXI_GP2\s+\{1\}", tcl) or not re.search(r"CONFIG\.PSU__USE__M_AXI_GP0\s+\{1\}", tcl):
        err(f"{TCL}: S_AXI_HP0_FPD (S_AXI_GP2) or M_AXI_HPM0_FPD (M_AXI_GP0) is not enabled")
    pw = params.get("s_axi_ctrl", {})
    if pw.get("PROTOCOL") != "AXI4LITE" or pw.get("ADDR_WIDTH") != str(ab) or pw.get("DATA_WIDTH") != str(db):
        err(f"{WRAPPER}: s_axi_ctrl's X_INTERFACE_PARAMETER {pw} is not AXI4LITE, {ab} address bits, {db} data bits")
    pg = params.get("m_axi_gmem", {})
    if (pg.get("PROTOCOL") != "AXI4" or pg.get("DATA_WIDTH") != str(gd) or pg.get("ADDR_WIDTH") != str(num["gmem_addr_bits"])
            or pg.get("ID_WIDTH") != str(num["gmem_id_bits"])):
        err(f"{WRAPPER}: m_axi_gmem's X_INTERFACE_PARAMETER {pg} disagrees with the top's widths")

    # ---- Address map ----
    off, rng = num["ctrl_offset"], num["ctrl_range"]
    if rng & (rng - 1) or rng < 4096:
        err(f"{TCL}: ctrl_range {rng:#x} is not a power of two of at least 4 KiB")
    if rng < (1 << ab):
        err(f"{TCL}: ctrl_range {rng:#x} is smaller than the register map's 2^{ab} bytes")
    if rng and off % rng:
        err(f"{TCL}: ctrl_offset {off:#x} is not aligned to ctrl_range {rng:#x}")
    if not (HPM0_FPD[0] <= off and off + rng <= HPM0_FPD[1]):
        err(f"{TCL}: s_axi_ctrl at {off:#x} + {rng:#x} is outside M_AXI_HPM0_FPD's window {HPM0_FPD[0]:#x}–{HPM0_FPD[1] - 1:#x}")
    seen = set()
    for r in regs["registers"]:
        o = int(r["offset"], 16)
        if o % 4 or o + db // 8 > (1 << ab) or o + db // 8 > rng or o in seen:
            err(f"{REGS}: register {r['name']} at {r['offset']} is repeated, unaligned or outside the 2^{ab}-byte map")
        seen.add(o)
    assigns = tcl_commands(tcl, "assign_bd_address")
    def assigned(seg_pattern, space_pattern):
        for a in assigns:
            if re.search(seg_pattern, a) and re.search(space_pattern, a):
                o = re.search(r"-offset\s+(\S+)", a)
                s = re.search(r"-range\s+(\S+)", a)
                if o and s:
                    return tcl_value(v, o.group(1)), tcl_value(v, s.group(1))
        return None
    a = assigned(r"\$accel/s_axi_ctrl/reg0", r"\$ps/Data")
    if a != (off, rng):
        err(f"{TCL}: assign_bd_address of $accel/s_axi_ctrl/reg0 in $ps/Data gives {a}, not ctrl_offset/ctrl_range")
    windows = []
    for seg, key in (("HP0_DDR_LOW", "ddr_low"), ("HP0_DDR_HIGH", "ddr_high")):
        a = assigned(r"SAXIGP2/" + seg, r"\$accel/m_axi_gmem")
        if a != (num[key + "_offset"], num[key + "_range"]):
            err(f"{TCL}: assign_bd_address of {seg} in m_axi_gmem's space gives {a}, not {key}_offset/{key}_range")
        windows.append((num[key + "_offset"], num[key + "_range"]))
    uio_windows = [(int(b.replace("'", ""), 16), int(s.replace("'", ""), 16))
                   for b, s in re.findall(r"\{\s*(0x[0-9a-fA-F']+)ull\s*,\s*(0x[0-9a-fA-F']+)ull\s*\}", uio)]
    if uio_windows != windows:
        err(f"{UIO}: kGmemWindows {[(hex(b), hex(s)) for b, s in uio_windows]} differ from the tcl's DDR segments "
            f"{[(hex(b), hex(s)) for b, s in windows]}")
    if vt is not None:
        m = re.search(r"kDdrBase\s*=\s*(0x[0-9a-fA-F']+)", vt)
        if m:
            base = int(m.group(1).replace("'", ""), 16)
            if not any(b <= base < b + s for b, s in windows):
                err(f"{VT}: the simulated DDR at kDdrBase {base:#x} is outside m_axi_gmem's DDR windows on the board")
    # A call's buffers at their largest (uio_transport.h's u-dma-buf must hold them).
    consts = {k: int(x) for k, x in re.findall(r"constexpr\s+int\s+(k\w+)\s*=\s*(\d+)\s*;", hwt)}
    largest = {"IMG_WIDTH": consts.get("kImageWidth"), "IMG_HEIGHT": consts.get("kImageHeight"),
               "NUM_PARTICLES": consts.get("kMaxParticles"), "NUM_FACES": consts.get("kMaxFaces")}
    need = 0
    for b in regs["buffers"]:
        expr = b["count"].replace("·", "*")
        for k, x in largest.items():
            expr = expr.replace(k, str(x))
        if not re.fullmatch(r"[\d\s*+]+", expr):
            err(f"{REGS}: buffer {b['name']}'s count '{b['count']}' is not a product of known sizes")
            continue
        total = eval(expr) * b["element_bytes"]  # digits, +, * only (checked above)
        need += (total + 4095) // 4096 * 4096

    # ---- Overlay ----
    dt = strip_comments(dts)
    node = next((n for n in re.finditer(r"(\w+)@([0-9a-fA-F]+)\s*\{([^{}]*)\}", dt) if "generic-uio" in n.group(3)), None)
    if not node:
        err(f"{DTS}: no node name@address compatible \"generic-uio\" for the accelerator")
    else:
        name, unit, body = node.groups()
        reg = re.search(r"reg\s*=\s*<\s*(0x\w+)\s+(0x\w+)\s+(0x\w+)\s+(0x\w+)\s*>", body)
        if not reg or ((int(reg.group(1), 16) << 32) | int(reg.group(2), 16), (int(reg.group(3), 16) << 32) | int(reg.group(4), 16)) != (off, rng):
            err(f"{DTS}: {name}'s reg is not <ctrl_offset ctrl_range> of {TCL} ({off:#x}, {rng:#x})")
        if int(unit, 16) != off:
            err(f"{DTS}: node {name}@{unit}'s unit address is not ctrl_offset {off:#x}")
        irq = re.search(r"interrupts\s*=\s*<\s*0\s+(\d+)\s+(\d+)\s*>", body)
        if not irq or int(irq.group(1)) != num["irq_spi"] or irq.group(2) != "4":
            err(f"{DTS}: {name}'s interrupts are not <0 {num['irq_spi']} 4> (SPI irq_spi, level high)")
        if '"generic-uio"' not in body:
            err(f"{DTS}: {name} is not compatible \"generic-uio\"")
        rb = re.search(r"register_base\s*=\s*(0x[0-9a-fA-F']+)", uio)
        if not rb or int(rb.group(1).replace("'", ""), 16) != off:
            err(f"{UIO}: UioTransportOptions::register_base {rb.group(1) if rb else None} is not ctrl_offset {off:#x} of {TCL}")
        default_name = re.search(r'uio_name\s*=\s*"(\w+)"', uio)
        if not default_name or default_name.group(1) != name:
            err(f"{DTS}: node {name} is not UioTransportOptions::uio_name ({default_name.group(1) if default_name else None})")
    ub = re.search(r'device-name\s*=\s*"(\w+)"', dt)
    default_buf = re.search(r'udmabuf\s*=\s*"(\w+)"', uio)
    if not ub or not default_buf or ub.group(1) != default_buf.group(1):
        err(f"{DTS}: the u-dma-buf's device-name is not UioTransportOptions::udmabuf")
    size = re.search(r"\bsize\s*=\s*<\s*(0x\w+|\d+)\s*>", dt)
    if not size or int(size.group(1), 0) < need:
        err(f"{DTS}: the u-dma-buf's size {size.group(1) if size else None} is below the {need} bytes of a call's buffers")
    mask = re.search(r"dma-mask\s*=\s*<\s*(\d+)\s*>", dt)
    if not mask or int(mask.group(1)) > 32:
        err(f"{DTS}: the u-dma-buf has no dma-mask of at most 32 bits (below 4 GiB the only DDR is HP0_DDR_LOW)")

    # ---- Part, clock, cores ----
    if v.get("part") != "xczu9eg-ffvb1156-2-e" or v.get("board_part") != "xilinx.com:zcu102:part0:3.4":
        err(f"{TCL}: part {v.get('part')} / board part {v.get('board_part')} are not the ZCU102's")
    if num["pl_clk_mhz"] != 200 or not re.search(r"PL0_REF_CTRL__FREQMHZ\s+\$pl_clk_mhz", tcl):
        err(f"{TCL}: pl_clk0 is not set to 200 MHz")
    cores_field = next((f for r in regs["registers"] if r["name"] == "CORES" for f in r["fields"] if f["name"] == "M"), None)
    if not cores_field or (1 << (cores_field["bits"][0] - cores_field["bits"][1] + 1)) <= 10:
        err(f"{REGS}: CORES.M cannot hold 10")
    if not re.search(r"\$cores != 5 && \$cores != 10", tcl) or not re.search(r"set_property CONFIG\.M \$cores \$accel", tcl):
        err(f"{TCL}: the module reference's M is not the --cores 5|10 argument")
    if dry:
        errors += dry_run_errors(root, num)
    return errors


HARNESS = r"""
# The Vivado commands zcu102_bd.tcl uses, as stubs that log their calls (any other command is
# an error, as it would be in Vivado). Objects are their paths: create_bd_cell gives /NAME.
set ::calls {}
proc log_call {name args} { lappend ::calls [concat [list $name] $args] }
foreach c {create_project set_property add_files update_compile_order create_bd_design apply_bd_automation
           connect_bd_net connect_bd_intf_net assign_bd_address exclude_bd_addr_seg validate_bd_design
           save_bd_design launch_runs wait_on_run open_run report_timing_summary report_utilization
           report_power write_cfgmem write_hw_platform} {
  proc $c args "log_call $c {*}\$args; return {}"
}
proc current_project args { return proj }
proc get_filesets args { return [lindex $args end] }
proc get_files args { return [lindex $args end] }
proc get_runs args { return [lindex $args end] }
proc get_bd_pins args { return [lindex $args end] }
proc get_bd_intf_pins args { return [lindex $args end] }
proc get_bd_addr_spaces args { return [lindex $args end] }
proc get_bd_addr_segs args { return [lindex $args end] }
proc get_timing_paths args { return path }
proc get_property {prop obj} { if {$prop eq "PROGRESS"} { return 100% } ; if {$prop eq "SLACK"} { return 0.125 } ; return {} }
proc create_bd_cell args { log_call create_bd_cell {*}$args; return /[lindex $args end] }
proc make_wrapper args { log_call make_wrapper {*}$args; return wrapper.v }
set argv $::env(BD_ARGS)
set argc [llength $argv]
if {[catch {source $::env(BD_TCL)} msg]} { puts "TCL-ERROR: $msg"; exit 3 }
foreach c $::calls { puts "CALL: $c" }
"""


def tcl_dry_run(root, args):
    """Runs the tcl under tclsh with the Vivado commands stubbed; the list of (command, args)
    it calls, or an error string. None when tclsh is not installed."""
    tclsh = shutil.which("tclsh")
    if not tclsh:
        return None
    with tempfile.TemporaryDirectory(prefix="bd_dry_") as tmp:
        bit = os.path.join(tmp, "posefilter_zcu102.runs", "impl_1")
        os.makedirs(bit)
        open(os.path.join(bit, "weigh_bd_wrapper.bit"), "w").close()
        harness = os.path.join(tmp, "harness.tcl")
        open(harness, "w", encoding="utf-8").write(HARNESS)
        env = dict(os.environ, BD_TCL=os.path.join(root, TCL), BD_ARGS=" ".join(args + ["--dir", tmp]))
        r = subprocess.run([tclsh, harness], env=env, capture_output=True, text=True, timeout=30)
    if r.returncode != 0:
        return "tcl dry run (" + " ".join(args) + "): " + (r.stdout + r.stderr).strip().splitlines()[-1]
    return [l[6:].split() for l in r.stdout.splitlines() if l.startswith("CALL: ")]


def dry_run_errors(root, num):
    """What the stubbed run of the tcl says: it runs to the end for --cores 5 and 10 with and
    without --impl, refuses --cores 7, and its assign_bd_address calls, with Tcl's own values,
    are the address map above."""
    errors = []
    for args in (["--cores", "5"], ["--cores", "10", "--impl"]):
        calls = tcl_dry_run(root, args)
        if calls is None:
            return []
        if isinstance(calls, str):
            errors.append(calls)
            continue
        cores = args[1]
        if ["set_property", "CONFIG.M", cores, "/weigh_accel_0"] not in calls:
            errors.append(f"tcl dry run ({' '.join(args)}): the module reference's M is not set to {cores}")
        want = [("/weigh_accel_0/s_axi_ctrl/reg0", "/zynq_ultra_ps_e_0/Data", num["ctrl_offset"], num["ctrl_range"]),
                ("/zynq_ultra_ps_e_0/SAXIGP2/HP0_DDR_LOW", "/weigh_accel_0/m_axi_gmem", num["ddr_low_offset"], num["ddr_low_range"]),
                ("/zynq_ultra_ps_e_0/SAXIGP2/HP0_DDR_HIGH", "/weigh_accel_0/m_axi_gmem", num["ddr_high_offset"], num["ddr_high_range"])]
        got = []
        for c in calls:
            if c[0] == "assign_bd_address":
                o = dict(zip(c[1::2], c[2::2]))
                got.append((c[-2], o.get("-target_address_space"), int(o.get("-offset", "-1"), 0), int(o.get("-range", "-1"), 0)))
        if sorted(got) != sorted(want):
            errors.append(f"tcl dry run ({' '.join(args)}): assign_bd_address calls {got}, expected {want}")
        if ("--impl" in args) != any(c[0] == "write_cfgmem" for c in calls):
            errors.append(f"tcl dry run ({' '.join(args)}): the bitstream tail ran {'without' if '--impl' in args else 'with'} --impl")
    bad = tcl_dry_run(root, ["--cores", "7"])
    if isinstance(bad, list):
        errors.append("tcl dry run (--cores 7): accepted; the design is built with 5 or 10 cores")
    return errors



# Broken copies: (file, old, new, expected message fragment); old is literal text, or a regular
# expression after "RE:" (new then may use its groups); the first match is replaced.
MUTATIONS = [
    # The top's lines as regular expressions (RE: prefix): its column alignment may change.
    (TOP, r"RE:\[\s*7\s*:\s*0\s*\](\s*s_axi_ctrl_awaddr\b)", r"[11:0]\1", "s_axi_ctrl address bits"),
    (TOP, r"RE:\[\s*2\s*:\s*0\s*\](\s*m_axi_gmem_rid\b)", r"[5:0]\1", "m_axi_gmem ID bits"),
    (TOP, r"RE:(output\s+logic\s+interrupt)(\s*\n\s*\);)", r"\1,\n    output logic m_axi_gmem_awuser\2",
     "lacks weigh_accel's port m_axi_gmem_awuser"),
    (TCL, "set ctrl_offset     0xA0000000", "set ctrl_offset     0xA0008000", "not aligned to ctrl_range"),
    (TCL, "set ctrl_offset     0xA0000000", "set ctrl_offset     0xB0000000", "outside M_AXI_HPM0_FPD"),
    (TCL, "set gmem_data_bits  128", "set gmem_data_bits  64", "m_axi_gmem data bits"),
    (TCL, "connect_bd_net [get_bd_pins $accel/interrupt] [get_bd_pins $irq/In0]\n", "",
     "weigh_accel's interrupt is not connected"),
    (TCL, "connect_bd_intf_net [get_bd_intf_pins $accel/m_axi_gmem] [get_bd_intf_pins $gmem_smc/S00_AXI]\n", "",
     "interface m_axi_gmem"),
    (TCL, "set ddr_high_offset 0x000800000000", "set ddr_high_offset 0x001000000000", "kGmemWindows"),
    (REGS, '"addr_bits": 8', '"addr_bits": 7', "s_axi_ctrl address bits"),
    (REGS, '{"name": "DD_READS_UNSHARED", "offset": "0xAC"', '{"name": "DD_READS_UNSHARED", "offset": "0x100"',
     "outside the 2^8-byte map"),
    (WRAPPER, "      .m_axi_gmem_bid(m_axi_gmem_bid),\n", "", "port m_axi_gmem_bid is not connected"),
    (WRAPPER, "xilinx.com:interface:aximm:1.0 m_axi_gmem WDATA", "xilinx.com:interface:aximm:1.0 m_axi_gmem RDATA",
     "m_axi_gmem_wdata is tagged"),
    (DTS, "reg = <0x0 0xa0000000 0x0 0x10000>", "reg = <0x0 0xa0010000 0x0 0x10000>", "reg is not <ctrl_offset"),
    (DTS, "interrupts = <0 89 4>", "interrupts = <0 89 1>", "interrupts are not <0 89 4>"),
    (DTS, "size = <0x1000000>", "size = <0x10000>", "is below the"),
    (TCL, "set jobs 4\n", "set jobs 4 8\n", "tcl dry run (--cores 5): TCL-ERROR: wrong # args"),
    (UIO, "register_base = 0xA000'0000", "register_base = 0xA001'0000", "register_base"),
    (UIO, "{0x8'0000'0000ull, 0x8'0000'0000ull}", "{0x8'0000'0000ull, 0x4'0000'0000ull}", "kGmemWindows"),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")))
    args = ap.parse_args()
    ok = True
    errors = check(args.root)
    for e in errors:
        print("FAIL: " + e)
    if errors:
        ok = False
    else:
        print("board package agrees: block design, register map, weigh_accel's ports, wrapper, overlay, transport"
              + ("" if shutil.which("tclsh") else " (no tclsh: the tcl's stubbed run is left out)"))
    # Negative controls.
    ran = 0
    with tempfile.TemporaryDirectory(prefix="board_package_") as tmp:
        pristine = {}
        for f in FILES:
            src = os.path.join(args.root, f)
            if os.path.exists(src):
                os.makedirs(os.path.dirname(os.path.join(tmp, f)), exist_ok=True)
                shutil.copyfile(src, os.path.join(tmp, f))
                pristine[f] = open(src, encoding="utf-8").read()
        for rel, old, new, expect in MUTATIONS:
            if expect.startswith("tcl dry run") and not shutil.which("tclsh"):
                print(f"note: no tclsh; the negative control '{expect}' is not run")
                continue
            path = os.path.join(tmp, rel)
            text = pristine[rel]
            if old.startswith("RE:"):
                broken, count = re.subn(old[3:], new, text, count=1)
            else:
                broken, count = text.replace(old, new, 1), text.count(old)
            if count == 0:
                print(f"FAIL: negative control on {rel}: '{old.strip()}' not found (the file changed; update MUTATIONS)")
                ok = False
                continue
            open(path, "w", encoding="utf-8").write(broken)
            got = check(tmp, dry=expect.startswith("tcl dry run"))
            open(path, "w", encoding="utf-8").write(text)  # the next copy starts from the real files
            ran += 1
            if not any(expect in e for e in got):
                print(f"FAIL: negative control on {rel} ('{old.strip()[:50]}' → '{new.strip()[:50]}') was not reported "
                      f"as '{expect}'; got {got}")
                ok = False
        if ok:
            print(f"{ran} broken copies each reported")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
