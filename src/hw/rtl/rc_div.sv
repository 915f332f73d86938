// rc_div.sv — pipelined restoring divider of the raster core (the RTL of fx_math/transform.h
// DivFloor<QW>): q = floor(n / d), one quotient bit per stage, II = 1, latency QW + PAD cycles.
//
// DivFloor's contract, reproduced bit for bit: the quotient must fit QW bits, i.e.
// (n >> QW) < d; when d = 0 or (n >> QW) ≥ d the flag `ovf` is set and q is all ones.
// Stage i (i = 0 … QW−1) shifts the next dividend bit n[QW−1−i] into the partial remainder r
// (invariant r < d, so r fits DW + 1 bits) and subtracts d when r ≥ d. PAD extra register
// stages equalise the latency of dividers that run side by side (vertex stage: the 32-stage
// 1/W divider and the two 22-stage snapping dividers).
//
// No valid bit: the divider always advances; the caller carries its own sideband through a
// delay line of the same latency (rc_delay).
module rc_div #(
    parameter int QW = 24,  // quotient bits = pipeline stages
    parameter int NW = 72,  // dividend width
    parameter int DW = 58,  // divisor width
    parameter int PAD = 0   // extra output stages
) (
    input  logic          clk,
    input  logic [NW-1:0] n,
    input  logic [DW-1:0] d,
    output logic [QW-1:0] q,
    output logic          ovf
);
  // Stage registers; index 0 is the (combinational) input.
  logic [DW:0]   r   [QW+1];
  logic [QW-1:0] nlo [QW+1];
  logic [DW-1:0] dd  [QW+1];
  logic [QW-1:0] qq  [QW+1];
  logic          ov  [QW+1];

  logic [NW-QW-1:0] high;
  assign high   = n[NW-1:QW];
  assign r[0]   = (DW + 1)'(high);
  assign nlo[0] = n[QW-1:0];
  assign dd[0]  = d;
  assign qq[0]  = '0;
  assign ov[0]  = (d == '0) || ({{(DW > NW - QW ? DW - (NW - QW) : 0){1'b0}}, high} >=
                                {{(NW - QW > DW ? NW - QW - DW : 0){1'b0}}, d});

  for (genvar i = 0; i < QW; i++) begin : g_step
    logic [DW:0] rs;
    assign rs = {r[i][DW-1:0], nlo[i][QW-1-i]};  // r << 1 | next dividend bit
    always_ff @(posedge clk) begin
      if (rs >= {1'b0, dd[i]}) begin
        r[i+1]  <= rs - {1'b0, dd[i]};
        qq[i+1] <= qq[i] | (QW'(1) << (QW - 1 - i));
      end else begin
        r[i+1]  <= rs;
        qq[i+1] <= qq[i];
      end
      nlo[i+1] <= nlo[i];
      dd[i+1]  <= dd[i];
      ov[i+1]  <= ov[i];
    end
  end

  logic [QW-1:0] qo;
  assign qo = ov[QW] ? '1 : qq[QW];
  if (PAD == 0) begin : g_nopad
    assign q   = qo;
    assign ovf = ov[QW];
  end else begin : g_pad
    logic [QW-1:0] qp [PAD];
    logic          op [PAD];
    always_ff @(posedge clk) begin
      qp[0] <= qo;
      op[0] <= ov[QW];
      for (int j = 1; j < PAD; j++) begin
        qp[j] <= qp[j-1];
        op[j] <= op[j-1];
      end
    end
    assign q   = qp[PAD-1];
    assign ovf = op[PAD-1];
  end
endmodule

