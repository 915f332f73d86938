// vertex_multiplier.sv — RTL of the vertex multiplier (thesis §7.5.3, Listing 7.1 [HARDWARE.md];
// C model VertexMultiplier in src/hw/transform.h): per call the model is copied on chip — the
// vertex memory (kMaxVertices = 1024 words {x, y, z}, xyz_t raw F10 m, 13 bits each) and the
// face memory (num_faces words of three 10-bit vertex indices, face_t: corner k at bits
// [10k +: 10]) — then per round of M particles the 3·num_faces vertices (face by face, corner by
// corner) are written to every active core of the round at once, one vertex per clock.
//
// Input `model` stream: 1024 vertex words (bits 38:26 x, 25:13 y, 12:0 z), then num_faces face
// words (bits 29:0). States (one-hot): VERT (vertex copy) → FACE (face copy) → RUN (rounds) →
// VERT (next call); the copies wait until no read is in flight.
// Read pipeline: face address → face word (two read registers) → vertex address (its corner's
// index) → vertex word (two read registers) → push, 4 clocks after the issue.
// Flow control: per core a FIFO of FD entries in block RAM (rc_fifo_bram; the C model's
// HW_STREAM(vert_core, FD) in src/hw/top.h) and a credit counter; a vertex is issued only when
// every active core has a credit left. The vertices go to all cores of a round in the same
// clock, so the FIFOs are what lets each core read them at its own rate, as the cycle model's
// rounds assume: a core whose pixel stage lags (large front faces) falls up to FD vertices behind
// the others, which meanwhile cull their back faces at 3 clocks per face. With FD = 2048
// (2.5 RAMB36 per core) the 2048-face torus is within 4 % of the cycle model; with 512, 18 %
// (docs/HARDWARE.md §12).
module vertex_multiplier #(
    parameter int M  = 5,    // raster cores, 1 … 10
    parameter int FD = 2048  // per-core vertex FIFO entries (power of two; block RAM)
) (
    input  logic            clk,
    input  logic            rst,
    input  logic [9:0]      num_particles,  // n ≤ 510; stable during a call
    input  logic [11:0]     num_faces,      // ≤ kMaxFaces = 2048; stable during a call
    input  logic            model_valid,
    output logic            model_ready,
    input  logic [38:0]     model_data,
    // Per core c: the vertex {x, y, z} at bits [39c +: 39].
    output logic [M-1:0]    vert_valid,
    input  logic [M-1:0]    vert_ready,
    output logic [M*39-1:0] vert_data
);
  localparam int NV = 1024;  // kMaxVertices
  localparam int NF = 2048;  // kMaxFaces
  localparam int CW = $clog2(FD) + 1;
  localparam int S_VERT = 0, S_FACE = 1, S_RUN = 2;
  logic [2:0] st;

  // ---------------------------------------------------------------- memories (BRAM)
  logic [38:0] vmem[NV];
  logic [29:0] fmem[NF];
  logic        vm_we, fm_we;
  logic [9:0]  vm_wa, vm_ra;
  logic [10:0] fm_wa, fm_ra;
  logic [38:0] vm_r, vm_q;
  logic [29:0] fm_r, fm_q;
  always_ff @(posedge clk) begin
    if (vm_we) vmem[vm_wa] <= model_data;
    vm_r <= vmem[vm_ra];
    vm_q <= vm_r;
  end
  always_ff @(posedge clk) begin
    if (fm_we) fmem[fm_wa] <= model_data[29:0];
    fm_r <= fmem[fm_ra];
    fm_q <= fm_r;
  end

  logic [10:0] cnt;          // copy counter
  logic [9:0]  first;        // first particle of the round
  logic [10:0] f;            // face of the next vertex
  logic [1:0]  k;            // its corner
  logic [M-1:0] act;         // active cores of the round
  logic [M-1:0] cred_ok, pop;
  logic [CW-1:0] cred[M];
  logic [3:0]  pv;           // issue valid after 1 … 4 clocks
  logic [1:0]  k1, k2;       // corner after 1, 2 clocks
  logic [M-1:0] m1, m2, m3, m4;  // target cores after 1 … 4 clocks

  // Active cores of a round whose first particle is f0: c < n − f0 (registered when the round
  // starts, so the issue test is an AND over the credits only).
  function automatic logic [M-1:0] active_mask(input logic [10:0] f0, input logic [9:0] n);
    for (int c = 0; c < M; c++) active_mask[c] = 11'(c) + f0 < 11'(n);
  endfunction

  wire busy = pv != '0;
  assign model_ready = (st[S_VERT] || st[S_FACE]) && !busy;
  wire model_hs = model_valid && model_ready;
  assign vm_we = model_hs && st[S_VERT];
  assign fm_we = model_hs && st[S_FACE];
  assign vm_wa = cnt[9:0];
  assign fm_wa = cnt;

  wire issue = st[S_RUN] && ((~act | cred_ok) == '1);
  assign fm_ra = f;
  assign vm_ra = fm_q[10*k2+:10];

  // Events (each register's next state is a short priority chain on them). nf_m1 and
  // last_round are registered: the parameters are stable during a call, and `first` changes
  // only at a round's end, thousands of clocks before it is tested again.
  logic [11:0] nf_m1;
  logic        last_round;
  always_ff @(posedge clk) begin
    nf_m1 <= num_faces - 12'd1;
    last_round <= 11'(first) + 11'(M) >= 11'(num_particles);
  end
  wire vert_last  = st[S_VERT] && model_hs && cnt == 11'(NV - 1);   // vertices copied
  wire face_last  = st[S_FACE] && model_hs && 12'(cnt) == nf_m1;    // faces copied
  wire round_end  = issue && 12'(f) == nf_m1 && k == 2'd2;           // the round's last vertex

  always_ff @(posedge clk) begin
    if (rst) st <= 3'b1 << S_VERT;
    else if (vert_last) st <= num_faces != 0 ? 3'b1 << S_FACE : 3'b1 << S_VERT;
    else if (face_last) st <= num_particles != 0 ? 3'b1 << S_RUN : 3'b1 << S_VERT;
    else if (round_end && last_round) st <= 3'b1 << S_VERT;
    if (rst || vert_last || face_last) cnt <= '0;
    else if (model_hs) cnt <= cnt + 11'd1;
    if (rst || face_last || (round_end && last_round)) first <= '0;
    else if (round_end) first <= first + 10'(M);
    if (rst) act <= '0;
    else if (face_last) act <= active_mask(11'd0, num_particles);
    else if (round_end) act <= active_mask(11'(first) + 11'(M), num_particles);
    if (rst || face_last || round_end) begin
      f <= '0;
      k <= '0;
    end else if (issue) begin
      k <= k == 2'd2 ? 2'd0 : k + 2'd1;
      if (k == 2'd2) f <= f + 11'd1;
    end
  end

  // Read pipeline.
  always_ff @(posedge clk) begin
    pv <= rst ? '0 : {pv[2:0], issue};
    k1 <= k;
    k2 <= k1;
    m1 <= act;
    m2 <= m1;
    m3 <= m2;
    m4 <= m3;
  end
  wire [M-1:0] push = pv[3] ? m4 : '0;

  for (genvar c = 0; c < M; c++) begin : g_core
    logic [$clog2(FD):0] fcnt;
    logic empty;
    logic [38:0] head;
    rc_fifo_bram #(.W(39), .DEPTH(FD)) u_fifo (
        .clk, .rst, .push(push[c]), .din(vm_q), .pop(pop[c]), .head(head), .empty(empty), .count(fcnt));
    assign vert_valid[c] = !empty;
    assign vert_data[39*c+:39] = head;
    assign pop[c] = vert_valid[c] && vert_ready[c];
    wire [CW-1:0] cred_n = cred[c] + CW'(issue && act[c]) - CW'(pop[c]);
    always_ff @(posedge clk) begin
      cred[c] <= rst ? '0 : cred_n;
      cred_ok[c] <= rst ? 1'b1 : cred_n < CW'(FD);
    end
`ifndef SYNTHESIS
    always_ff @(posedge clk)
      if (!rst) begin
        assert (cred[c] <= CW'(FD))
        else $error("vertex_multiplier: core %0d credits %0d exceed the FIFO depth %0d", c, cred[c], FD);
        assert (32'(fcnt) <= 32'(cred[c]))
        else $error("vertex_multiplier: core %0d FIFO holds %0d words but %0d credits are taken", c, fcnt, cred[c]);
      end
`endif
  end

`ifndef SYNTHESIS
  logic        hs_wait;
  logic [38:0] hs_data;
  logic [M-1:0] hs_out_wait;
  logic [M*39-1:0] hs_out;
  always_ff @(posedge clk) begin
    hs_wait <= !rst && model_valid && !model_ready;
    hs_data <= model_data;
    hs_out_wait <= rst ? '0 : vert_valid & ~vert_ready;
    hs_out <= vert_data;
    if (!rst) begin
      if (hs_wait)
        assert (model_valid && model_data == hs_data)
        else $error("vertex_multiplier: model_valid dropped or model_data changed before model_ready");
      for (int c = 0; c < M; c++)
        if (hs_out_wait[c])
          assert (vert_valid[c] && vert_data[39*c+:39] == hs_out[39*c+:39])
          else $error("vertex_multiplier: vert_valid[%0d] dropped or its vertex changed before ready", c);
      assert ($onehot(st))
      else $error("vertex_multiplier: state %b is not one-hot", st);
      assert (!issue || 12'(f) < num_faces)
      else $error("vertex_multiplier: face %0d read beyond num_faces %0d", f, num_faces);
    end
  end
`endif
endmodule
