// rc_div.sv — pipelined divider of the raster core (the RTL of fx_math/transform.h
// DivFloor<QW>): q = floor(n / d), one quotient bit per stage, II = 1, latency QW + PAD cycles.
//
// DivFloor's contract, reproduced bit for bit: the quotient must fit QW bits, i.e.
// (n >> QW) < d; when d = 0 or (n >> QW) ≥ d the flag `ovf` is set and q is all ones.
//
// Non-restoring recurrence, one carry chain per stage. The restoring divider keeps the partial
// remainder r ∈ [0, d) and, per stage, forms rs = 2r + (next dividend bit) and r' = rs − d when
// rs ≥ d (quotient bit 1), else r' = rs. Here each stage keeps p = r when the last quotient bit
// was 1 and p = r − d when it was 0 (p ∈ [−d, d), DW + 1 bits two's complement) and computes
// one add/subtract: p' = 2p + bit − d when p ≥ 0, p' = 2p + bit + d when p < 0. In both cases
// p' = rs − d, so the quotient bit (p' ≥ 0) is exactly the restoring divider's. The result lies
// in [−d, d) and is computed modulo 2^(DW+1), so the stage adder is DW + 1 bits wide: per bit one
// LUT (operand bit XOR d bit XOR sign) feeding the carry chain, and no restore multiplexer.
//
// PAD extra register stages set the latency of a divider that runs beside others (vertex stage:
// the two 21-stage snapping dividers padded to 30, two clocks ahead of the 32-stage 1/W divider).
//
// No valid bit: the divider always advances; the caller carries its own sideband through a
// delay line of the same latency (rc_delay).
module rc_div #(
    parameter int QW = 24,  // quotient bits = pipeline stages
    parameter int NW = 72,  // dividend width (bits)
    parameter int DW = 58,  // divisor width (bits, unsigned)
    parameter int PAD = 0   // extra output stages
) (
    input  logic          clk,
    input  logic [NW-1:0] n,
    input  logic [DW-1:0] d,
    output logic [QW-1:0] q,
    output logic          ovf
);
  // Stage registers; index 0 is the (combinational) input. p: signed partial remainder,
  // DW + 1 bits; qq: quotient bits so far (bit QW−1−i written by stage i).
  logic [DW:0]   p   [QW+1];
  logic [QW-1:0] nlo [QW+1];
  logic [DW-1:0] dd  [QW+1];
  logic [QW-1:0] qq  [QW+1];
  logic          ov  [QW+1];

  logic [NW-QW-1:0] high;
  assign high   = n[NW-1:QW];
  // Without overflow high < d, so it fits the DW + 1-bit remainder as a non-negative value
  // (with overflow the quotient is forced to all ones and p is irrelevant).
  assign p[0]   = (DW + 1)'(high);
  assign nlo[0] = n[QW-1:0];
  assign dd[0]  = d;
  assign qq[0]  = '0;
  assign ov[0]  = (d == '0) || ({{(DW > NW - QW ? DW - (NW - QW) : 0){1'b0}}, high} >=
                                {{(NW - QW > DW ? NW - QW - DW : 0){1'b0}}, d});

  for (genvar i = 0; i < QW; i++) begin : g_step
    logic [DW:0]   ps, pn;
    logic [DW+1:0] sum;
    logic          neg;
    assign neg = p[i][DW];                              // p < 0: the last quotient bit was 0
    assign ps  = {p[i][DW-1:0], nlo[i][QW-1-i]};        // 2p + next dividend bit, mod 2^(DW+1)
    // One two-operand subtraction (a subtraction, so synthesis keeps ps as the carry chain's
    // direct operand): y = d when p ≥ 0, y = ~d when p < 0, and the borrow-in (p < 0) rides
    // in an extra low bit: {ps, 0} − {y, neg} = 2·(ps − y) − neg, whose upper DW + 1 bits are
    // ps − y − neg, i.e. ps − d (p ≥ 0) or ps − ~d − 1 = ps + d (p < 0), mod 2^(DW+1). One LUT
    // per bit (ps XOR d XOR sign) in front of the carry chain.
    assign sum = {ps, 1'b0} - {({1'b0, dd[i]} ^ {(DW + 1){neg}}), neg};
    assign pn  = sum[DW+1:1];
    always_ff @(posedge clk) begin
      p[i+1]   <= pn;
      // The last stage also applies the overflow (all ones), so q leaves a register.
      if (i == QW - 1 && ov[i]) qq[i+1] <= '1;
      else qq[i+1] <= qq[i] | (pn[DW] ? QW'(0) : (QW'(1) << (QW - 1 - i)));
      nlo[i+1] <= nlo[i];
      dd[i+1]  <= dd[i];
      ov[i+1]  <= ov[i];
    end
  end

  logic [QW-1:0] qo;
  assign qo = qq[QW];
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
