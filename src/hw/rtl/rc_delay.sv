// rc_delay.sv — sideband delay line of the raster core's pipelined dividers.
// A delay line of L ≥ 2 register stages for a valid bit and a W-bit sideband word; `any` is
// the OR of the valid bits over all stages (the caller's pipeline-busy flag); vpre/dpre are
// the stage before the output (one clock earlier).
module rc_delay #(
    parameter int W = 1,
    parameter int L = 1
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         vin,
    input  logic [W-1:0] din,
    output logic         vout,
    output logic [W-1:0] dout,
    output logic         vpre,
    output logic [W-1:0] dpre,
    output logic         any
);
  logic [W-1:0] s[L];
  logic         v[L];
  logic [L-1:0] vv;
  always_ff @(posedge clk) begin
    s[0] <= din;
    v[0] <= rst ? 1'b0 : vin;
    for (int j = 1; j < L; j++) begin
      s[j] <= s[j-1];
      v[j] <= rst ? 1'b0 : v[j-1];
    end
  end
  for (genvar j = 0; j < L; j++) begin : g_any
    assign vv[j] = v[j];
  end
  assign dout = s[L-1];
  assign vout = v[L-1];
  assign dpre = s[L-2];
  assign vpre = v[L-2];
  assign any  = |vv;
endmodule
