// rc_fifo.sv — the triangle FIFO between the vertex stage and the pixel stage of a raster
// core (Fig. 7.20's internal dataflow). First-word-fall-through: `head` is the oldest entry,
// read asynchronously from distributed RAM (LUTRAM), so the pixel stage can pop a triangle in
// the cycle its previous triangle's last pixel issues. DEPTH is a power of two.
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
endmodule
