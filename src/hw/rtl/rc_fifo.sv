// rc_fifo.sv — the triangle FIFO between the vertex stage and the pixel stage of a raster
// core (Fig. 7.20's internal dataflow). First-word-fall-through: `head` is the oldest entry,
// read asynchronously from distributed RAM (LUTRAM), so the pixel stage can pop a triangle in
// the cycle its previous triangle's last pixel issues. DEPTH is a power of two. Pushing into a
// full FIFO or popping an empty one is the caller's error, caught by the simulation assertions.
module rc_fifo #(
    parameter int W     = 32,
    parameter int DEPTH = 16
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         push,
    input  logic [W-1:0] din,
    input  logic         pop,
    output logic [W-1:0] head,
    output logic         empty,
    output logic [$clog2(DEPTH):0] count
);
  localparam int AW = $clog2(DEPTH);
  logic [W-1:0] mem[DEPTH];
  logic [AW-1:0] wp, rp;
  always_ff @(posedge clk) begin
    if (push) mem[wp] <= din;
    if (rst) begin
      wp    <= '0;
      rp    <= '0;
      count <= '0;
    end else begin
      if (push) wp <= wp + 1'b1;
      if (pop) rp <= rp + 1'b1;
      count <= count + (push ? 1 : 0) - (pop ? 1 : 0);
    end
  end
  assign head  = mem[rp];
  assign empty = count == 0;

`ifndef SYNTHESIS
  // Simulation checks (Verilator --assert): the caller must not push into a full FIFO (an
  // entry would be lost) nor pop an empty one (the head is stale).
  always_ff @(posedge clk)
    if (!rst) begin
      assert (!(push && !pop && count == (AW + 1)'(DEPTH)))
      else $error("rc_fifo: overflow (push into a full FIFO of %0d entries)", DEPTH);
      assert (!(pop && count == 0))
      else $error("rc_fifo: underflow (pop from an empty FIFO)");
      assert (count <= (AW + 1)'(DEPTH))
      else $error("rc_fifo: count %0d exceeds the depth %0d", count, DEPTH);
    end
`endif
endmodule
