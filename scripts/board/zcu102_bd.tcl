# scripts/board/zcu102_bd.tcl — the weighing accelerator (src/hw/rtl/weigh_accel.sv) on a ZCU102
# (XCZU9EG-FFVB1156-2-E): a Vivado 2023.1/2023.2 project with one block design:
#
#   zynq_ultra_ps_e_0 (PS8, ZCU102 board preset)
#     pl_clk0 200 MHz ──▶ every clock below; pl_resetn0 ──▶ rst_pl_clk0 (proc_sys_reset)
#     M_AXI_HPM0_FPD (32-bit) ──▶ ctrl_smc (SmartConnect) ──▶ weigh_accel_0/s_axi_ctrl
#                                  at 0xA000_0000, 64 KiB (the register map needs 2^8 bytes)
#     S_AXI_HP0_FPD  (128-bit) ◀── gmem_smc (SmartConnect) ◀── weigh_accel_0/m_axi_gmem
#                                  sees DDR_LOW (0x0, 2 GiB) and DDR_HIGH (0x8_0000_0000, 32 GiB
#                                  window; 2 GiB populated on the ZCU102)
#     pl_ps_irq0[0] ◀── irq_concat ◀── weigh_accel_0/interrupt (level high; GIC SPI 89)
#
# The accelerator is a module reference to scripts/board/weigh_accel_bd.v, a Verilog wrapper that
# passes weigh_accel's ports through (Vivado does not take a SystemVerilog top as a module
# reference); its sources are every src/hw/rtl/*.sv. Parameter M (raster cores): 5, or 10 with
# --cores 10.
#
# Usage (from any folder; nothing here has been run: this machine has no Vivado):
#   vivado -mode batch -source scripts/board/zcu102_bd.tcl -tclargs [--cores 5|10] [--dir DIR]
#          [--impl] [--jobs N]
#     creates DIR/posefilter_zcu102.xpr (DIR default build/zcu102_m<M> under the repository),
#     the block design, validates it and makes its HDL wrapper the top. With --impl also
#     synthesis, implementation and the bitstream (the optional tail at the end of this file):
#     DIR/posefilter_zcu102.bit, .bin (for fpgautil / the FPGA manager), .xsa, and the timing
#     and utilisation reports; it fails when the routed design misses timing (WNS < 0).
#
# The values below that come from the register map (src/hw/rtl/weigh_regs.json) or from
# weigh_accel's ports are checked against them by tests/hw/board/board_package_test.py (ctest
# board_package, labels hw;rtl), as are the DDR windows against src/hw/host/uio_transport.h.

# ---- Board and design constants (board_package_test.py reads these `set` lines) ----
set part            xczu9eg-ffvb1156-2-e
set board_part      xilinx.com:zcu102:part0:3.4
set pl_clk_mhz      200          ;# pl_clk0, MHz (the clock the cycle model counts in)
set ctrl_offset     0xA0000000   ;# s_axi_ctrl in the PS's M_AXI_HPM0_FPD window 0xA000_0000–0xAFFF_FFFF
set ctrl_range      0x00010000   ;# bytes: 64 KiB (≥ 2^ctrl_addr_bits; the UIO map is this size)
set ctrl_addr_bits  8            ;# s_axi_ctrl address bits = weigh_regs.json addr_bits
set ctrl_data_bits  32           ;# s_axi_ctrl data bits = weigh_regs.json data_bits
set hpm0_data_bits  32           ;# M_AXI_HPM0_FPD data bits (no width converter before the slave)
set gmem_data_bits  128          ;# m_axi_gmem data bits = S_AXI_HP0_FPD data bits
set gmem_addr_bits  64           ;# m_axi_gmem address bits (HP0 takes 49; the upper bits are 0)
set gmem_id_bits    3            ;# m_axi_gmem ID bits (readers 0–5, writer 6)
set ddr_low_offset  0x000000000000
set ddr_low_range   0x000080000000   ;# 2 GiB
set ddr_high_offset 0x000800000000
set ddr_high_range  0x000800000000   ;# 32 GiB window (2 GiB of it populated on the ZCU102)
set irq_spi         89           ;# pl_ps_irq0[0] = GIC SPI 89 (IRQ ID 121); device tree <0 89 4>

# IP versions of Vivado 2023.1 and 2023.2.
set vlnv_ps    xilinx.com:ip:zynq_ultra_ps_e:3.5
set vlnv_smc   xilinx.com:ip:smartconnect:1.0
set vlnv_rst   xilinx.com:ip:proc_sys_reset:5.0
set vlnv_concat xilinx.com:ip:xlconcat:2.1

# ---- Arguments ----
set cores 5
set impl 0
set jobs 4
set dir ""
set script_dir [file dirname [file normalize [info script]]]
set repo [file normalize [file join $script_dir .. ..]]
set rtl_dir [file join $repo src hw rtl]
for {set i 0} {$i < [llength $argv]} {incr i} {
  set a [lindex $argv $i]
  switch -- $a {
    --cores { incr i; set cores [lindex $argv $i] }
    --dir   { incr i; set dir [file normalize [lindex $argv $i]] }
    --jobs  { incr i; set jobs [lindex $argv $i] }
    --impl  { set impl 1 }
    default { error "zcu102_bd.tcl: unknown argument '$a' (--cores 5|10, --dir DIR, --impl, --jobs N)" }
  }
}
if {$cores != 5 && $cores != 10} {
  error "zcu102_bd.tcl: --cores $cores: the design is built with 5 or 10 raster cores"
}
if {$dir eq ""} { set dir [file join $repo build zcu102_m$cores] }
set proj posefilter_zcu102
set bd   weigh_bd

# ---- Project and sources ----
create_project $proj $dir -part $part -force
set_property board_part $board_part [current_project]
set_property target_language Verilog [current_project]
set rtl_sources [lsort [glob -nocomplain [file join $rtl_dir *.sv]]]
if {[llength $rtl_sources] == 0} { error "zcu102_bd.tcl: no SystemVerilog sources in $rtl_dir" }
add_files -norecurse -fileset sources_1 $rtl_sources
set_property file_type SystemVerilog [get_files -of_objects [get_filesets sources_1] *.sv]
add_files -norecurse -fileset sources_1 [file join $script_dir weigh_accel_bd.v]
update_compile_order -fileset sources_1

create_bd_design $bd

# ---- PS8 ----
set ps [create_bd_cell -type ip -vlnv $vlnv_ps zynq_ultra_ps_e_0]
apply_bd_automation -rule xilinx.com:bd_rule:zynq_ultra_ps_e -config {apply_board_preset "1"} $ps
set_property -dict [list \
  CONFIG.PSU__USE__M_AXI_GP0 {1} \
  CONFIG.PSU__MAXIGP0__DATA_WIDTH $hpm0_data_bits \
  CONFIG.PSU__USE__M_AXI_GP1 {0} \
  CONFIG.PSU__USE__M_AXI_GP2 {0} \
  CONFIG.PSU__USE__S_AXI_GP2 {1} \
  CONFIG.PSU__SAXIGP2__DATA_WIDTH $gmem_data_bits \
  CONFIG.PSU__FPGA_PL0_ENABLE {1} \
  CONFIG.PSU__CRL_APB__PL0_REF_CTRL__FREQMHZ $pl_clk_mhz \
  CONFIG.PSU__FPGA_PL1_ENABLE {0} \
  CONFIG.PSU__FPGA_PL2_ENABLE {0} \
  CONFIG.PSU__FPGA_PL3_ENABLE {0} \
  CONFIG.PSU__USE__IRQ0 {1} \
  CONFIG.PSU__NUM_FABRIC_RESETS {1} \
] $ps
# (M_AXI_GP0 = M_AXI_HPM0_FPD, M_AXI_GP1 = M_AXI_HPM1_FPD, M_AXI_GP2 = M_AXI_HPM0_LPD,
#  S_AXI_GP2 = S_AXI_HP0_FPD, whose address segments are SAXIGP2/HP0_*.)

# ---- The accelerator, interconnect, reset, interrupt ----
set accel [create_bd_cell -type module -reference weigh_accel_bd weigh_accel_0]
set_property CONFIG.M $cores $accel

set ctrl_smc [create_bd_cell -type ip -vlnv $vlnv_smc ctrl_smc]
set_property -dict [list CONFIG.NUM_SI {1} CONFIG.NUM_MI {1}] $ctrl_smc
set gmem_smc [create_bd_cell -type ip -vlnv $vlnv_smc gmem_smc]
set_property -dict [list CONFIG.NUM_SI {1} CONFIG.NUM_MI {1}] $gmem_smc
set rst [create_bd_cell -type ip -vlnv $vlnv_rst rst_pl_clk0]
set irq [create_bd_cell -type ip -vlnv $vlnv_concat irq_concat]
set_property CONFIG.NUM_PORTS {1} $irq

# Clock: pl_clk0 everywhere.
connect_bd_net [get_bd_pins $ps/pl_clk0] \
  [get_bd_pins $ps/maxihpm0_fpd_aclk] [get_bd_pins $ps/saxihp0_fpd_aclk] \
  [get_bd_pins $accel/ap_clk] [get_bd_pins $ctrl_smc/aclk] [get_bd_pins $gmem_smc/aclk] \
  [get_bd_pins $rst/slowest_sync_clk]
# Reset: the PS's fabric reset, synchronised to pl_clk0.
connect_bd_net [get_bd_pins $ps/pl_resetn0] [get_bd_pins $rst/ext_reset_in]
connect_bd_net [get_bd_pins $rst/peripheral_aresetn] [get_bd_pins $accel/ap_rst_n]
connect_bd_net [get_bd_pins $rst/interconnect_aresetn] [get_bd_pins $ctrl_smc/aresetn] [get_bd_pins $gmem_smc/aresetn]
# Registers: PS master → SmartConnect → s_axi_ctrl.
connect_bd_intf_net [get_bd_intf_pins $ps/M_AXI_HPM0_FPD] [get_bd_intf_pins $ctrl_smc/S00_AXI]
connect_bd_intf_net [get_bd_intf_pins $ctrl_smc/M00_AXI] [get_bd_intf_pins $accel/s_axi_ctrl]
# DDR: m_axi_gmem → SmartConnect → the PS's HP0 slave.
connect_bd_intf_net [get_bd_intf_pins $accel/m_axi_gmem] [get_bd_intf_pins $gmem_smc/S00_AXI]
connect_bd_intf_net [get_bd_intf_pins $gmem_smc/M00_AXI] [get_bd_intf_pins $ps/S_AXI_HP0_FPD]
# Interrupt: pl_ps_irq0 is 8 bits wide; the accelerator drives bit 0.
connect_bd_net [get_bd_pins $accel/interrupt] [get_bd_pins $irq/In0]
connect_bd_net [get_bd_pins $irq/dout] [get_bd_pins $ps/pl_ps_irq0]

# ---- Address map ----
# The PS sees the registers at ctrl_offset (the module reference's memory map is reg0).
assign_bd_address -offset $ctrl_offset -range $ctrl_range \
  -target_address_space [get_bd_addr_spaces $ps/Data] [get_bd_addr_segs $accel/s_axi_ctrl/reg0] -force
# The accelerator sees DDR at the CPU's physical addresses (a u-dma-buf's phys_addr is what the
# host writes into the *_ADDR registers); OCM and QSPI are not mapped.
assign_bd_address -offset $ddr_low_offset -range $ddr_low_range \
  -target_address_space [get_bd_addr_spaces $accel/m_axi_gmem] [get_bd_addr_segs $ps/SAXIGP2/HP0_DDR_LOW] -force
assign_bd_address -offset $ddr_high_offset -range $ddr_high_range \
  -target_address_space [get_bd_addr_spaces $accel/m_axi_gmem] [get_bd_addr_segs $ps/SAXIGP2/HP0_DDR_HIGH] -force
foreach seg {HP0_LPS_OCM HP0_QSPI} {
  set s [get_bd_addr_segs -quiet $ps/SAXIGP2/$seg]
  if {$s ne ""} {
    exclude_bd_addr_seg -target_address_space [get_bd_addr_spaces $accel/m_axi_gmem] $s
  }
}

validate_bd_design
save_bd_design
set wrapper [make_wrapper -files [get_files $bd.bd] -top]
add_files -norecurse -fileset sources_1 $wrapper
set_property top ${bd}_wrapper [get_filesets sources_1]
update_compile_order -fileset sources_1
puts "zcu102_bd.tcl: $dir/$proj.xpr: block design $bd, weigh_accel M = $cores, s_axi_ctrl at $ctrl_offset ($ctrl_range bytes)"

# ---- Optional tail: synthesis, implementation, bitstream (--impl) ----
if {!$impl} { return }
launch_runs synth_1 -jobs $jobs
wait_on_run synth_1
if {[get_property PROGRESS [get_runs synth_1]] ne "100%"} { error "zcu102_bd.tcl: synth_1 failed (see $dir/$proj.runs/synth_1)" }
launch_runs impl_1 -to_step write_bitstream -jobs $jobs
wait_on_run impl_1
if {[get_property PROGRESS [get_runs impl_1]] ne "100%"} { error "zcu102_bd.tcl: impl_1 failed (see $dir/$proj.runs/impl_1)" }
open_run impl_1
report_timing_summary -file [file join $dir timing_summary.rpt]
report_utilization -hierarchical -file [file join $dir utilization_hier.rpt]
report_utilization -file [file join $dir utilization.rpt]
report_power -file [file join $dir power.rpt]
set bit [lindex [glob [file join $dir $proj.runs impl_1 *.bit]] 0]
file copy -force $bit [file join $dir $proj.bit]
# .bin for the Linux FPGA manager (fpgautil -b, or the device-tree overlay's firmware-name).
write_cfgmem -force -format bin -interface SMAPx32 -disablebitswap -loadbit "up 0x0 $bit" [file join $dir $proj.bin]
write_hw_platform -fixed -include_bit -force [file join $dir $proj.xsa]
set wns [get_property SLACK [get_timing_paths -max_paths 1 -nworst 1 -setup]]
if {$wns < 0} { error "zcu102_bd.tcl: the routed design misses 200 MHz: WNS $wns ns (timing_summary.rpt)" }
puts "zcu102_bd.tcl: $dir/$proj.bit, .bin, .xsa; WNS $wns ns at $pl_clk_mhz MHz"
