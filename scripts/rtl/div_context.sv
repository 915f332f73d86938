// scripts/rtl/div_context.sv — the raster core's dividers with the constant inputs they have in
// src/hw/rtl/rc_vertex_stage.sv (1/W) and raster_core.sv (depth), for synthesising them one at a
// time (synth.sh): the 1/W divider's dividend is the constant 2^58, and the depth divider's
// dividend is Σe'·2^46 (46 low bits zero). The snapping dividers have no constant input and are
// synthesised as rc_div itself.
module div_iz_context (
    input  logic        clk,
    input  logic [50:0] d,
    output logic [31:0] q,
    output logic        ovf
);
  rc_div #(.QW(32), .NW(60), .DW(51), .PAD(0)) u (.clk, .n(60'h1 << 58), .d(d), .q(q), .ovf(ovf));
endmodule

module div_z_context (
    input  logic        clk,
    input  logic [25:0] sum_e,
    input  logic [57:0] d,
    output logic [23:0] q,
    output logic        ovf
);
  rc_div #(.QW(24), .NW(72), .DW(58), .PAD(0)) u (.clk, .n({sum_e, 46'b0}), .d(d), .q(q), .ovf(ovf));
endmodule
