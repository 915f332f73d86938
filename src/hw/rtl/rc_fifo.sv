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

// rc_fifo_bram — a deep first-word-fall-through FIFO whose storage is block RAM (the vertex
// multiplier's per-core vertex FIFOs). The RAM (DEPTH words, one write port, one read port) is
// read through two registers (the RAM's own and one behind it, so no logic follows the RAM in
// its read clock) into a 4-entry output FIFO in distributed RAM (rc_fifo), whose head is
// `head`. A read is issued when the RAM holds words and the output FIFO has room for it and for
// the reads in flight, so the output FIFO never overflows and a popping consumer is served one
// word per clock. A word pushed while the RAM and the read pipeline are empty and the output
// FIFO has room goes straight into the output FIFO (bypass), so `head` shows it in the next
// clock, as rc_fifo does. `count` is every word held (RAM, reads in flight, output FIFO); at most
// DEPTH. DEPTH is a power of two. Pushing into a full FIFO (count = DEPTH without a pop) or
// popping an empty one is the caller's error, caught by the simulation assertions.
module rc_fifo_bram #(
    parameter int W     = 39,
    parameter int DEPTH = 512
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
  logic [W-1:0]  mem[DEPTH];
  logic [AW-1:0] wp, rp;
  logic [AW:0]   rcnt;          // words in the RAM not yet read
  logic          v1, v2;        // read pipeline: RAM register, second register valid
  logic [W-1:0]  mem_r, mem_q;
  logic [2:0]    oc;            // output FIFO count
  logic          o_empty;

  wire bypass = push && rcnt == '0 && !v1 && !v2 && oc != 3'd4;
  wire ram_we = push && !bypass;
  wire rd     = rcnt != '0 && 4'(oc) + 4'(v1) + 4'(v2) <= 4'd3;

  always_ff @(posedge clk) begin
    if (ram_we) mem[wp] <= din;
    mem_r <= mem[rp];
    mem_q <= mem_r;
  end
  always_ff @(posedge clk) begin
    if (rst) begin
      wp    <= '0;
      rp    <= '0;
      rcnt  <= '0;
      v1    <= 1'b0;
      v2    <= 1'b0;
      count <= '0;
    end else begin
      if (ram_we) wp <= wp + 1'b1;
      if (rd) rp <= rp + 1'b1;
      rcnt  <= rcnt + (AW + 1)'(ram_we) - (AW + 1)'(rd);
      v1    <= rd;
      v2    <= v1;
      count <= count + (push ? 1 : 0) - (pop ? 1 : 0);
    end
  end

  rc_fifo #(.W(W), .DEPTH(4)) u_out (
      .clk, .rst, .push(bypass || v2), .din(bypass ? din : mem_q), .pop, .head, .empty(o_empty), .count(oc));
  assign empty = o_empty;

`ifndef SYNTHESIS
  // Simulation checks (Verilator --assert): the caller must not push into a full FIFO nor pop
  // an empty one; inside, the RAM and the output FIFO stay within their sizes.
  always_ff @(posedge clk)
    if (!rst) begin
      assert (!(push && !pop && count == (AW + 1)'(DEPTH)))
      else $error("rc_fifo_bram: overflow (push into a full FIFO of %0d entries)", DEPTH);
      assert (!(pop && o_empty))
      else $error("rc_fifo_bram: underflow (pop from an empty FIFO)");
      assert (count <= (AW + 1)'(DEPTH))
      else $error("rc_fifo_bram: count %0d exceeds the depth %0d", count, DEPTH);
      assert (32'(count) == 32'(rcnt) + 32'(v1) + 32'(v2) + 32'(oc))
      else $error("rc_fifo_bram: count %0d is not RAM %0d + in flight %0d + output %0d", count, rcnt,
                  32'(v1) + 32'(v2), oc);
    end
`endif
endmodule
