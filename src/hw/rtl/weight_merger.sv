// weight_merger.sv — RTL of the weight merger (thesis §7.5.3 "Weigh/Inlier merger and final
// composition", Listing 7.8 [HARDWARE.md]; C model MergeWeights in src/hw/weight_merger.h):
// reads the raster cores' output words in particle order (particle p from core p mod M) and
// composes the weight of eq. 7.4 [ALGORITHM.md] with one divider shared by the three ratios:
//
//   w = max(0, α·min(1, I/N_raster) + β·min(1, I/N_depth) + γ·ρ − δ·n_edge_continued/n_edge)
//
// (each ratio 0 when its denominator is 0; N_raster = n_raster − n_occluded when
// occlusion_aware = 1), bit-exact with the C model:
//   ratio  CappedRatio = min(1, round-half-up(num/den)) with num F10 (Σχ; n_edge_continued as
//          an integer), den an integer, result ratio_t F17 (18 bits): q = floor(num·2^8 / den)
//          (Divide<18, 1>: 50-bit dividend), r = (q + 1) >> 1, capped at 1 = 2^17. As r ≥ 2^17
//          exactly when q ≥ 2^18 − 1, the divider needs 19 quotient bits only; its overflow
//          flag (q ≥ 2^19) also caps.
//   weight W = α·r_raster + β·r_depth + γ·ρ·2^9 − δ·r_edge, exact at F32 (coefficients F15,
//          ratios F17, ρ F8), signed 37 bits; weight_t raw (F17, 18 bits) =
//          min(⌊W / 2^15⌋, 2^18 − 1) for W ≥ 0, 0 for W < 0 (the C model's clamp to
//          [0, 2 − 2^-17] and truncation).
// ρ = class_prob[cell]: the prob memory (kNumCells = 6300 × 8 bits, prob_t F8) is copied from
// the `prob` stream at the start of each call (the C model's BurstLoad), and each particle's
// cell comes on the `cell` stream.
//
// Schedule: II = 3 (the C model's kWmParticlesII). A particle is accepted (its core word and its
// cell) in one clock; the divider (rc_div, 19 stages) takes I/N_raster, I/N_depth and the edge
// ratio in the three following clocks; their results are capped (R), multiplied by the
// coefficients (M1), summed in two clocks (M2, M3) and clamped (M4) into the weight FIFO.
// Output word: the weight, the particle's index in the call and the core's output word
// forwarded unchanged (the C model's `weights` and `stats_out`, written in the same iteration,
// as one stream). The core word enters the stats FIFO at acceptance and the weight its FIFO at
// M4; a particle is accepted only while the stats FIFO (OD entries) has room, so neither FIFO
// overflows whatever the sink's rate.
//
// Core output word (314 bits, RasterCoreOutput raw, MSB first): inlier_sum 42 (F10), n_raster
// 32, n_occluded 32, n_depth 32, depth_diff_sum 56 (F20 signed), depth_diff_count 32, n_edge
// 32, n_edge_continued 32, faces_front 12, faces_total 12.
module weight_merger #(
    parameter int M  = 5,  // raster cores, 1 … 10
    parameter int OD = 4   // output FIFO entries (power of two)
) (
    input  logic             clk,
    input  logic             rst,
    input  logic [9:0]       num_particles,   // n ≤ 510; stable during a call
    input  logic [15:0]      prm_alpha,       // coef_t raw, F15
    input  logic [15:0]      prm_beta,
    input  logic [15:0]      prm_gamma,
    input  logic [15:0]      prm_delta,
    input  logic             prm_occlusion_aware,
    // class_prob (prob_t raw F8), kNumCells words at the start of each call.
    input  logic             prob_valid,
    output logic             prob_ready,
    input  logic [7:0]       prob_data,
    // Each particle's cell (cell_index_t), particle order.
    input  logic             cell_valid,
    output logic             cell_ready,
    input  logic [12:0]      cell_data,
    // Per core c: its output word at bits [314c +: 314].
    input  logic [M-1:0]     core_valid,
    output logic [M-1:0]     core_ready,
    input  logic [M*314-1:0] core_data,
    // Weighed particles, particle order.
    output logic             out_valid,
    input  logic             out_ready,
    output logic [17:0]      out_weight,      // weight_t raw, F17
    output logic [9:0]       out_index,       // particle index in the call
    output logic [313:0]     out_stats        // the core's output word
);
  localparam int NC = 6300;  // kNumCells
  localparam int QW = 19;    // quotient bits (see the header)
  localparam int S_LOAD = 0, S_RUN = 1;
  logic [1:0] st;

  // ---------------------------------------------------------------- prob memory (BRAM)
  logic [7:0]  pmem[8192];   // 6300 used
  logic        pm_we;
  logic [12:0] pm_wa, pm_ra;
  logic [7:0]  pm_r, pm_q;
  always_ff @(posedge clk) begin
    if (pm_we) pmem[pm_wa] <= prob_data;
    pm_r <= pmem[pm_ra];
    pm_q <= pm_r;
  end

  logic [12:0] cnt;          // prob copy counter
  logic [9:0]  p;            // next particle
  logic [3:0]  cur;          // its core
  logic [1:0]  fc;           // divider feeds left for the accepted particle (3, 2, 1; 0 idle)
  // The accepted particle: dividends and divisors of its three ratios.
  logic [41:0] a_inlier;     // Σχ raw F10
  logic [31:0] a_nr, a_nd, a_ne, a_nc;
  logic [9:0]  a_index;
  logic [12:0] a_cell;       // its cell (the prob memory's read address)

  assign prob_ready = st[S_LOAD] && fc == 0;  // the last particle's ρ has been read
  wire prob_hs = prob_valid && prob_ready;
  assign pm_we = prob_hs;
  assign pm_wa = cnt;

  // Output FIFOs.
  logic [$clog2(OD):0] sf_cnt, wf_cnt;
  logic sf_empty, wf_empty;
  // The current core's word: an AND-OR multiplexer on the one-hot core select (an indexed
  // part-select would synthesise as a barrel shifter over all M·314 bits).
  logic [313:0] word;
  always_comb begin
    word = '0;
    for (int c = 0; c < M; c++) word = word | (cur == 4'(c) ? core_data[314*c+:314] : 314'(0));
  end
  wire accept = st[S_RUN] && fc <= 2'd1 && core_valid[cur] && cell_valid && sf_cnt < ($clog2(OD) + 1)'(OD);
  always_comb
    for (int c = 0; c < M; c++) core_ready[c] = accept && cur == 4'(c);
  assign cell_ready = accept;
  assign pm_ra = a_cell;

  always_ff @(posedge clk) begin
    if (rst) begin
      st <= 2'b1 << S_LOAD;
      cnt <= '0;
      p <= '0;
      cur <= '0;
      fc <= '0;
    end else begin
      if (fc != 0) fc <= fc - 2'd1;
      case (1'b1)
        st[S_LOAD]:
          if (prob_hs) begin
            cnt <= cnt + 13'd1;
            if (cnt == 13'(NC - 1)) begin
              cnt <= '0;
              if (num_particles != 0) st <= 2'b1 << S_RUN;
            end
          end
        st[S_RUN]:
          if (accept) begin
            fc <= 2'd3;
            if (p + 10'd1 >= num_particles) begin  // the call's last particle
              p <= '0;
              cur <= '0;
              st <= 2'b1 << S_LOAD;
            end else begin
              p <= p + 10'd1;
              cur <= cur == 4'(M - 1) ? 4'd0 : cur + 4'd1;
            end
          end
        default: st <= 2'b1 << S_LOAD;
      endcase
    end
  end

  always_ff @(posedge clk)
    if (accept) begin
      a_inlier <= word[313:272];
      // N_raster: n_raster − n_occluded when occlusion-aware (32-bit, as count_t).
      a_nr <= prm_occlusion_aware ? word[271:240] - word[239:208] : word[271:240];
      a_nd <= word[207:176];
      a_ne <= word[87:56];
      a_nc <= word[55:24];
      a_index <= p;
      a_cell <= cell_data;
    end

  // ---------------------------------------------------------------- shared divider
  // Feed (fc = 3, 2, 1 → ratio 0, 1, 2): dividend·2^8 (50 bits), divisor (32 bits).
  wire [1:0]  ph = 2'd3 - fc;
  wire        feed = fc != 0;
  wire [49:0] dv_n = ph == 2'd2 ? {a_nc, 18'b0} : {a_inlier, 8'b0};
  wire [31:0] dv_d = ph == 2'd0 ? a_nr : ph == 2'd1 ? a_nd : a_ne;
  logic [QW-1:0] dv_q;
  logic dv_ovf;
  rc_div #(.QW(QW), .NW(50), .DW(32), .PAD(0)) u_div (.clk, .n(dv_n), .d(dv_d), .q(dv_q), .ovf(dv_ovf));
  // Sideband: valid, ratio number, divisor = 0, the particle's index and ρ (the prob memory is
  // read at the first feed, so ρ leaves its two read registers at the third).
  logic        sb_v;
  logic [20:0] sb_d;
  rc_delay #(.W(21), .L(QW)) u_sb (
      .clk, .rst, .vin(feed), .din({ph, dv_d == 32'd0, a_index, pm_q}), .vout(sb_v), .dout(sb_d),
      .vpre(), .dpre(), .any());
  wire [1:0] sb_ph = sb_d[20:19];
  wire       sb_zero = sb_d[18];

  // R: the capped ratio (F17).
  logic [17:0] ratio;
  always_comb
    if (sb_zero) ratio = '0;
    else if (dv_ovf || dv_q >= QW'((1 << 18) - 1)) ratio = 18'(1 << 17);
    else ratio = 18'((20'(dv_q) + 20'd1) >> 1);
  logic [17:0] r_raster, r_depth, r_edge;
  logic [9:0]  r_index;
  logic [7:0]  r_rho;
  logic        r_v, m1_v, m2_v, m3_v;
  always_ff @(posedge clk) begin
    r_v <= !rst && sb_v && sb_ph == 2'd2;
    if (sb_v && sb_ph == 2'd0) r_raster <= ratio;
    if (sb_v && sb_ph == 2'd1) r_depth <= ratio;
    if (sb_v && sb_ph == 2'd2) begin
      r_edge <= ratio;
      r_index <= sb_d[17:8];
      r_rho <= sb_d[7:0];
    end
  end

  // M1 products (F32; γ·ρ F23), M2/M3 the sum, M4 the clamp.
  logic [33:0] m1_a, m1_b, m1_d;
  logic [23:0] m1_g;
  logic [9:0]  m1_i, m2_i, m3_i;
  logic signed [36:0] m2_s, m2_t, m3_w;
  always_ff @(posedge clk) begin
    m1_v <= !rst && r_v;
    m2_v <= !rst && m1_v;
    m3_v <= !rst && m2_v;
    m1_a <= prm_alpha * r_raster;
    m1_b <= prm_beta * r_depth;
    m1_g <= prm_gamma * r_rho;
    m1_d <= prm_delta * r_edge;
    m1_i <= r_index;
    m2_s <= 37'(m1_a) + 37'(m1_b);
    m2_t <= (37'(m1_g) << 9) - 37'(m1_d);
    m2_i <= m1_i;
    m3_w <= m2_s + m2_t;
    m3_i <= m2_i;
  end
  logic [17:0] w_out;
  always_comb
    if (m3_w < 0) w_out = '0;
    else if (m3_w[36:15] >= 22'(1 << 18)) w_out = '1;
    else w_out = m3_w[32:15];

  // ---------------------------------------------------------------- output FIFOs
  logic [313:0] sf_head;
  logic [27:0]  wf_head;
  wire out_hs = out_valid && out_ready;
  rc_fifo #(.W(314), .DEPTH(OD)) u_stats (
      .clk, .rst, .push(accept), .din(word), .pop(out_hs), .head(sf_head), .empty(sf_empty), .count(sf_cnt));
  rc_fifo #(.W(28), .DEPTH(OD)) u_weights (
      .clk, .rst, .push(m3_v), .din({w_out, m3_i}), .pop(out_hs), .head(wf_head), .empty(wf_empty), .count(wf_cnt));
  assign out_valid = !wf_empty;
  assign out_weight = wf_head[27:10];
  assign out_index = wf_head[9:0];
  assign out_stats = sf_head;

`ifndef SYNTHESIS
  logic        hs_prob_wait, hs_cell_wait, hs_out_wait;
  logic [7:0]  hs_prob;
  logic [12:0] hs_cell;
  logic [M-1:0] hs_core_wait;
  logic [M*314-1:0] hs_core;
  logic [341:0] hs_out;
  always_ff @(posedge clk) begin
    hs_prob_wait <= !rst && prob_valid && !prob_ready;
    hs_cell_wait <= !rst && cell_valid && !cell_ready;
    hs_out_wait <= !rst && out_valid && !out_ready;
    hs_core_wait <= rst ? '0 : core_valid & ~core_ready;
    hs_prob <= prob_data;
    hs_cell <= cell_data;
    hs_core <= core_data;
    hs_out <= {out_weight, out_index, out_stats};
    if (!rst) begin
      if (hs_prob_wait)
        assert (prob_valid && prob_data == hs_prob)
        else $error("weight_merger: prob_valid dropped or prob_data changed before prob_ready");
      if (hs_cell_wait)
        assert (cell_valid && cell_data == hs_cell)
        else $error("weight_merger: cell_valid dropped or cell_data changed before cell_ready");
      for (int c = 0; c < M; c++)
        if (hs_core_wait[c])
          assert (core_valid[c] && core_data[314*c+:314] == hs_core[314*c+:314])
          else $error("weight_merger: core_valid[%0d] dropped or its word changed before ready", c);
      if (hs_out_wait)
        assert (out_valid && {out_weight, out_index, out_stats} == hs_out)
        else $error("weight_merger: out_valid dropped or the output word changed before out_ready");
      assert ($onehot(st))
      else $error("weight_merger: state %b is not one-hot", st);
      assert (!accept || cell_data < 13'(NC))
      else $error("weight_merger: cell %0d outside the %0d cells", cell_data, NC);
      // The weight FIFO never holds a particle whose core word has left the stats FIFO.
      assert (wf_cnt <= sf_cnt)
      else $error("weight_merger: %0d weights but %0d core words queued", wf_cnt, sf_cnt);
    end
  end
`endif
endmodule
