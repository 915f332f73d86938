// ft_distributor.sv — RTL of the FT distributor (thesis §7.5.3; C model DistributeFT in
// src/hw/distributor.h): the 12 full-transformation-matrix elements of each particle (ft_t raw
// F22, row-major 3 × 4, particle order) go to the core that renders the particle, core
// (p mod M) for particle p of a call of num_particles particles, one element per clock.
//
// A demultiplexer without storage: core c's valid is the input's valid while c is the current
// core, and the input's ready is the current core's ready (valid never depends on ready, so the
// AXI4-Stream rules hold through it). Counters: element e (0 … 11), core cur (0 … M − 1),
// particle p (0 … n − 1; after the call's last element the next call starts at core 0).
module ft_distributor #(
    parameter int M = 5  // raster cores, 1 … 10
) (
    input  logic         clk,
    input  logic         rst,
    input  logic [9:0]   num_particles,  // n ≤ 510; stable during a call
    input  logic         ft_valid,
    output logic         ft_ready,
    input  logic [35:0]  ft_data,        // ft_t raw, F22
    output logic [M-1:0] core_valid,
    input  logic [M-1:0] core_ready,
    output logic [35:0]  core_data       // the same word to every core; core_valid selects
);
  logic [3:0] e;
  logic [3:0] cur;
  logic [9:0] p;

  always_comb
    for (int c = 0; c < M; c++) core_valid[c] = ft_valid && cur == 4'(c);
  assign ft_ready  = core_ready[cur];
  assign core_data = ft_data;
  wire hs = ft_valid && ft_ready;

  always_ff @(posedge clk) begin
    if (rst) begin
      e <= '0;
      cur <= '0;
      p <= '0;
    end else if (hs) begin
      e <= e + 4'd1;
      if (e == 4'd11) begin  // the particle's last element (kFtElements = 12)
        e <= '0;
        if (p + 10'd1 >= num_particles) begin  // the call's last particle
          p <= '0;
          cur <= '0;
        end else begin
          p <= p + 10'd1;
          cur <= cur == 4'(M - 1) ? 4'd0 : cur + 4'd1;
        end
      end
    end
  end

`ifndef SYNTHESIS
  logic        hs_wait;
  logic [35:0] hs_data;
  always_ff @(posedge clk) begin
    hs_wait <= !rst && ft_valid && !ft_ready;
    hs_data <= ft_data;
    if (!rst) begin
      if (hs_wait)
        assert (ft_valid && ft_data == hs_data)
        else $error("ft_distributor: ft_valid dropped or ft_data changed before ft_ready");
      assert (32'(cur) < M && e < 4'd12)
      else $error("ft_distributor: core %0d / element %0d out of range", cur, e);
      assert ($onehot0(core_valid))
      else $error("ft_distributor: more than one core selected (%b)", core_valid);
    end
  end
`endif
endmodule
