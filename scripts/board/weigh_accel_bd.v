// weigh_accel_bd.v — the weighing accelerator (src/hw/rtl/weigh_accel.sv) as the Vivado block
// design's module reference (scripts/board/zcu102_bd.tcl). Vivado takes a Verilog or VHDL file,
// not SystemVerilog, as the top of a module reference (SystemVerilog below it is fine), so this
// Verilog-2001 file passes every port of weigh_accel straight through, unchanged in name and
// width, and tells IP integrator what the ports are (X_INTERFACE_INFO / X_INTERFACE_PARAMETER):
//   ap_clk      clock of both AXI interfaces (the block design's 200 MHz pl_clk0)
//   ap_rst_n    synchronous reset, active low (proc_sys_reset's peripheral_aresetn)
//   s_axi_ctrl  AXI4-Lite slave, 32 data bits, 8 address bits (the register map,
//               src/hw/rtl/weigh_regs.json: 256 bytes, aliased through the 64 KiB window the
//               block design assigns)
//   m_axi_gmem  AXI4 master, 128 data bits, 64 address bits, 3 ID bits, INCR bursts of ≤ 16
//               beats; up to 6 readers × 2 bursts = 12 reads in flight (axi_burst_reader.sv),
//               writes limited by the interconnect
//   interrupt   level, high while GIE ∧ ISR ≠ 0
// tests/hw/board/board_package_test.py checks that this port list is weigh_accel's, that every
// port is connected by name below, and that the block design's widths agree with it.
module weigh_accel_bd #(
    parameter integer M = 5  // raster cores: 5 (default) or 10 (zcu102_bd.tcl --cores 10)
) (
    (* X_INTERFACE_INFO = "xilinx.com:signal:clock:1.0 ap_clk CLK" *) (* X_INTERFACE_PARAMETER = "XIL_INTERFACENAME ap_clk, ASSOCIATED_BUSIF s_axi_ctrl:m_axi_gmem, ASSOCIATED_RESET ap_rst_n" *)
    input  wire           ap_clk,
    (* X_INTERFACE_INFO = "xilinx.com:signal:reset:1.0 ap_rst_n RST" *) (* X_INTERFACE_PARAMETER = "XIL_INTERFACENAME ap_rst_n, POLARITY ACTIVE_LOW" *)
    input  wire           ap_rst_n,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl AWVALID" *) (* X_INTERFACE_PARAMETER = "XIL_INTERFACENAME s_axi_ctrl, PROTOCOL AXI4LITE, DATA_WIDTH 32, ADDR_WIDTH 8" *)
    input  wire           s_axi_ctrl_awvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl AWREADY" *)
    output wire           s_axi_ctrl_awready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl AWADDR" *)
    input  wire [7:0]     s_axi_ctrl_awaddr,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl WVALID" *)
    input  wire           s_axi_ctrl_wvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl WREADY" *)
    output wire           s_axi_ctrl_wready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl WDATA" *)
    input  wire [31:0]    s_axi_ctrl_wdata,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl WSTRB" *)
    input  wire [3:0]     s_axi_ctrl_wstrb,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl BVALID" *)
    output wire           s_axi_ctrl_bvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl BREADY" *)
    input  wire           s_axi_ctrl_bready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl BRESP" *)
    output wire [1:0]     s_axi_ctrl_bresp,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl ARVALID" *)
    input  wire           s_axi_ctrl_arvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl ARREADY" *)
    output wire           s_axi_ctrl_arready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl ARADDR" *)
    input  wire [7:0]     s_axi_ctrl_araddr,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl RVALID" *)
    output wire           s_axi_ctrl_rvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl RREADY" *)
    input  wire           s_axi_ctrl_rready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl RDATA" *)
    output wire [31:0]    s_axi_ctrl_rdata,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 s_axi_ctrl RRESP" *)
    output wire [1:0]     s_axi_ctrl_rresp,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWVALID" *) (* X_INTERFACE_PARAMETER = "XIL_INTERFACENAME m_axi_gmem, PROTOCOL AXI4, DATA_WIDTH 128, ADDR_WIDTH 64, ID_WIDTH 3, MAX_BURST_LENGTH 16, NUM_READ_OUTSTANDING 16, NUM_WRITE_OUTSTANDING 16, SUPPORTS_NARROW_BURST 0" *)
    output wire           m_axi_gmem_awvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWREADY" *)
    input  wire           m_axi_gmem_awready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWADDR" *)
    output wire [63:0]    m_axi_gmem_awaddr,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWLEN" *)
    output wire [7:0]     m_axi_gmem_awlen,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWSIZE" *)
    output wire [2:0]     m_axi_gmem_awsize,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWBURST" *)
    output wire [1:0]     m_axi_gmem_awburst,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWID" *)
    output wire [2:0]     m_axi_gmem_awid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWLOCK" *)
    output wire           m_axi_gmem_awlock,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWCACHE" *)
    output wire [3:0]     m_axi_gmem_awcache,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWPROT" *)
    output wire [2:0]     m_axi_gmem_awprot,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem AWQOS" *)
    output wire [3:0]     m_axi_gmem_awqos,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem WVALID" *)
    output wire           m_axi_gmem_wvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem WREADY" *)
    input  wire           m_axi_gmem_wready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem WDATA" *)
    output wire [127:0]   m_axi_gmem_wdata,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem WSTRB" *)
    output wire [15:0]    m_axi_gmem_wstrb,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem WLAST" *)
    output wire           m_axi_gmem_wlast,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem BVALID" *)
    input  wire           m_axi_gmem_bvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem BREADY" *)
    output wire           m_axi_gmem_bready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem BRESP" *)
    input  wire [1:0]     m_axi_gmem_bresp,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem BID" *)
    input  wire [2:0]     m_axi_gmem_bid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARVALID" *)
    output wire           m_axi_gmem_arvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARREADY" *)
    input  wire           m_axi_gmem_arready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARADDR" *)
    output wire [63:0]    m_axi_gmem_araddr,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARLEN" *)
    output wire [7:0]     m_axi_gmem_arlen,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARSIZE" *)
    output wire [2:0]     m_axi_gmem_arsize,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARBURST" *)
    output wire [1:0]     m_axi_gmem_arburst,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARID" *)
    output wire [2:0]     m_axi_gmem_arid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARLOCK" *)
    output wire           m_axi_gmem_arlock,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARCACHE" *)
    output wire [3:0]     m_axi_gmem_arcache,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARPROT" *)
    output wire [2:0]     m_axi_gmem_arprot,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem ARQOS" *)
    output wire [3:0]     m_axi_gmem_arqos,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RVALID" *)
    input  wire           m_axi_gmem_rvalid,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RREADY" *)
    output wire           m_axi_gmem_rready,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RDATA" *)
    input  wire [127:0]   m_axi_gmem_rdata,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RRESP" *)
    input  wire [1:0]     m_axi_gmem_rresp,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RLAST" *)
    input  wire           m_axi_gmem_rlast,
    (* X_INTERFACE_INFO = "xilinx.com:interface:aximm:1.0 m_axi_gmem RID" *)
    input  wire [2:0]     m_axi_gmem_rid,
    (* X_INTERFACE_INFO = "xilinx.com:signal:interrupt:1.0 interrupt INTERRUPT" *) (* X_INTERFACE_PARAMETER = "XIL_INTERFACENAME interrupt, SENSITIVITY LEVEL_HIGH" *)
    output wire           interrupt
);
  weigh_accel #(
      .M(M)
  ) u_accel (
      .ap_clk(ap_clk),
      .ap_rst_n(ap_rst_n),
      .s_axi_ctrl_awvalid(s_axi_ctrl_awvalid),
      .s_axi_ctrl_awready(s_axi_ctrl_awready),
      .s_axi_ctrl_awaddr(s_axi_ctrl_awaddr),
      .s_axi_ctrl_wvalid(s_axi_ctrl_wvalid),
      .s_axi_ctrl_wready(s_axi_ctrl_wready),
      .s_axi_ctrl_wdata(s_axi_ctrl_wdata),
      .s_axi_ctrl_wstrb(s_axi_ctrl_wstrb),
      .s_axi_ctrl_bvalid(s_axi_ctrl_bvalid),
      .s_axi_ctrl_bready(s_axi_ctrl_bready),
      .s_axi_ctrl_bresp(s_axi_ctrl_bresp),
      .s_axi_ctrl_arvalid(s_axi_ctrl_arvalid),
      .s_axi_ctrl_arready(s_axi_ctrl_arready),
      .s_axi_ctrl_araddr(s_axi_ctrl_araddr),
      .s_axi_ctrl_rvalid(s_axi_ctrl_rvalid),
      .s_axi_ctrl_rready(s_axi_ctrl_rready),
      .s_axi_ctrl_rdata(s_axi_ctrl_rdata),
      .s_axi_ctrl_rresp(s_axi_ctrl_rresp),
      .m_axi_gmem_awvalid(m_axi_gmem_awvalid),
      .m_axi_gmem_awready(m_axi_gmem_awready),
      .m_axi_gmem_awaddr(m_axi_gmem_awaddr),
      .m_axi_gmem_awlen(m_axi_gmem_awlen),
      .m_axi_gmem_awsize(m_axi_gmem_awsize),
      .m_axi_gmem_awburst(m_axi_gmem_awburst),
      .m_axi_gmem_awid(m_axi_gmem_awid),
      .m_axi_gmem_awlock(m_axi_gmem_awlock),
      .m_axi_gmem_awcache(m_axi_gmem_awcache),
      .m_axi_gmem_awprot(m_axi_gmem_awprot),
      .m_axi_gmem_awqos(m_axi_gmem_awqos),
      .m_axi_gmem_wvalid(m_axi_gmem_wvalid),
      .m_axi_gmem_wready(m_axi_gmem_wready),
      .m_axi_gmem_wdata(m_axi_gmem_wdata),
      .m_axi_gmem_wstrb(m_axi_gmem_wstrb),
      .m_axi_gmem_wlast(m_axi_gmem_wlast),
      .m_axi_gmem_bvalid(m_axi_gmem_bvalid),
      .m_axi_gmem_bready(m_axi_gmem_bready),
      .m_axi_gmem_bresp(m_axi_gmem_bresp),
      .m_axi_gmem_bid(m_axi_gmem_bid),
      .m_axi_gmem_arvalid(m_axi_gmem_arvalid),
      .m_axi_gmem_arready(m_axi_gmem_arready),
      .m_axi_gmem_araddr(m_axi_gmem_araddr),
      .m_axi_gmem_arlen(m_axi_gmem_arlen),
      .m_axi_gmem_arsize(m_axi_gmem_arsize),
      .m_axi_gmem_arburst(m_axi_gmem_arburst),
      .m_axi_gmem_arid(m_axi_gmem_arid),
      .m_axi_gmem_arlock(m_axi_gmem_arlock),
      .m_axi_gmem_arcache(m_axi_gmem_arcache),
      .m_axi_gmem_arprot(m_axi_gmem_arprot),
      .m_axi_gmem_arqos(m_axi_gmem_arqos),
      .m_axi_gmem_rvalid(m_axi_gmem_rvalid),
      .m_axi_gmem_rready(m_axi_gmem_rready),
      .m_axi_gmem_rdata(m_axi_gmem_rdata),
      .m_axi_gmem_rresp(m_axi_gmem_rresp),
      .m_axi_gmem_rlast(m_axi_gmem_rlast),
      .m_axi_gmem_rid(m_axi_gmem_rid),
      .interrupt(interrupt)
  );
endmodule
