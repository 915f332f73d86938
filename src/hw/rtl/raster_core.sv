// raster_core.sv — RTL of one raster core of the render/score pipeline (thesis §7.5.3
// "Raster Core (partial inlier)", Fig. 7.20; rasterization eq. 6.12–6.22 [ALGORITHM.md]; soft inlier §7.5.1),
// bit-exact with the C model posefilter::hw::RasterCore (src/hw/raster_core.h) for one
// particle at a time. Microarchitecture (src/hw/rtl/README.md):
//
//   IDLE   accept the Window word (u0, v0, width, height)
//   FILL   width·height depth pixels, row-major, II = 1: fragment memory and z-buffer clear
//          at address y·200 + x (row/column counters, no division); N_depth
//   FT     12 FT words, II = 1, into the vertex stage's registers
//   FACES  vertex stage ──triangle FIFO──▶ pixel stage, concurrently:
//          vertex stage (rc_vertex_stage.sv; the core keeps its flow control, the face
//            credits): 3·num_faces vertices, II = 1 across faces: FT·[v;1] (exact),
//            near test, 1/W (32-stage divider) and the two snapping dividers (21 stages,
//            padded to 30: x, y two clocks ahead of 1/W), guard band; per face: 2·Area,
//            culling, clipped bounding box, edge setup (A, B, E at the first pixel, owned-edge
//            minimum, sh) → FIFO, every product between registers
//          pixel stage: one pixel of the current triangle's clipped box per cycle, no bubble
//            between rows or triangles; inside test, depth recovery (24-stage divider), then
//            zbuffer = 0: CompareFragment against the fragment memory;
//            zbuffer = 1: z-buffer read-modify-write (min); memories read through two
//            registers, the two writes a read cannot see forwarded
//   ZPASS  (zbuffer = 1) the window in raster order from both memories, line buffers for the
//          4-neighbours; pixel (x, y) is evaluated when (x, y + 1) is read: width·(height + 1)
//   OUT    the RasterCoreOutput word
//
// Every stream is valid/ready (a source holds valid and data until ready). Simulation-only
// assertions (ifndef SYNTHESIS) check the handshakes, the state code, the face credits and
// the memory addresses (at the end of this module) and the FIFO (rc_fifo).
//
// Number formats (as raster_core.h; Fn = n fractional bits of the raw integer):
//   FT element ap_int<36> F22, vertex ap_int<13> F10, U V W ap_int<52> F32,
//   screen x y ap_int<23> F8 (guard band ±2^21), 1/W ap_uint<32> F26, 2·Area and edge
//   functions ap_int<50> F16, z_r ap_uint<24> F20, z-buffer word ap_uint<18> F16
//   (all ones = empty), depth pixel ap_uint<12> F10, χ ap_uint<11> F10, Σχ 42 bits F10,
//   Σ(z_s − z_r) ap_int<56> F20.
module raster_core #(
    parameter int TRI_FIFO_DEPTH = 16  // triangle FIFO entries (power of two)
) (
    input  logic        clk,
    input  logic        rst,
    // Runtime parameters (RasterParams raw words; stable while a particle is processed).
    input  logic        prm_zbuffer,
    input  logic        prm_hard,
    input  logic [23:0] prm_thr1,        // F20 m
    input  logic [19:0] prm_inv_thr1,    // F8 1/m
    input  logic [23:0] prm_hard_thr,    // F20 m
    input  logic [23:0] prm_align_band,  // F20 m
    input  logic [23:0] prm_edge_band,   // F20 m
    input  logic [23:0] prm_near_plane,  // F20 m
    input  logic [11:0] num_faces,       // ≤ kMaxFaces = 2048
    // Window word (sample info).
    input  logic        win_valid,
    output logic        win_ready,
    input  logic [9:0]  win_u0,
    input  logic [9:0]  win_v0,
    input  logic [7:0]  win_width,
    input  logic [7:0]  win_height,
    // Depth pixels of the window, row-major (depth_t raw, F10 m).
    input  logic        depth_valid,
    output logic        depth_ready,
    input  logic [11:0] depth_data,
    // FT elements, row-major 3×4 (ft_t raw, F22).
    input  logic        ft_valid,
    output logic        ft_ready,
    input  logic [35:0] ft_data,
    // Vertices, three per face (xyz_t raw, F10 m).
    input  logic        vert_valid,
    output logic        vert_ready,
    input  logic [12:0] vert_x,
    input  logic [12:0] vert_y,
    input  logic [12:0] vert_z,
    // RasterCoreOutput.
    output logic        out_valid,
    input  logic        out_ready,
    output logic [41:0] out_inlier_sum,      // F10
    output logic [31:0] out_n_raster,
    output logic [31:0] out_n_occluded,
    output logic [31:0] out_n_depth,
    output logic [55:0] out_depth_diff_sum,  // F20
    output logic [31:0] out_depth_diff_count,
    output logic [31:0] out_n_edge,
    output logic [31:0] out_n_edge_continued,
    output logic [11:0] out_faces_front,
    output logic [11:0] out_faces_total
);
  localparam int KW = rc_pkg::KW;          // kMaxWindow: memory row stride
  localparam int KPIX = KW * KW;           // 40000 words per memory
  localparam logic [17:0] ZEMPTY = '1;     // kZbufEmpty

  typedef enum logic [2:0] {S_IDLE, S_FILL, S_FT, S_FACES, S_ZPASS, S_OUT} state_t;
  state_t state;

  // ---------------------------------------------------------------- window and accumulators
  logic [9:0] u0, v0;
  logic [7:0] ww, wh;
  logic [41:0] acc_inlier;
  logic [31:0] acc_n_raster, acc_n_occluded, acc_n_depth, acc_diff_count, acc_n_edge, acc_n_cont;
  logic [55:0] acc_diff;
  logic [11:0] acc_front;

  // ---------------------------------------------------------------- memories (BRAM)
  // Fragment memory 40000 × 12 (depth_t) and z-buffer 40000 × 18: one write and one read port
  // each (simple dual port, read-before-write). The read has two registers, the memory's own
  // (frag_r, zbuf_r) and one behind it (frag_q, zbuf_q: the block RAM's output register, or a
  // fabric register next to it), so no logic follows the RAM in the clock of its read: data
  // read in clock t is used in clock t + 2. The pixel stage reads the fragment memory one clock
  // before the z-buffer (its CompareFragment starts in P4, the z-buffer update is in P5).
  logic [11:0] frag_mem[KPIX];
  logic [17:0] zbuf_mem[KPIX];
  logic        frag_we, zbuf_we;
  logic [15:0] frag_wa, zbuf_wa, frag_ra, zbuf_ra;
  logic [11:0] frag_wd, frag_r, frag_q;
  logic [17:0] zbuf_wd, zbuf_r, zbuf_q;
  always_ff @(posedge clk) begin
    if (frag_we) frag_mem[frag_wa] <= frag_wd;
    frag_r <= frag_mem[frag_ra];
    frag_q <= frag_r;
  end
  always_ff @(posedge clk) begin
    if (zbuf_we) zbuf_mem[zbuf_wa] <= zbuf_wd;
    zbuf_r <= zbuf_mem[zbuf_ra];
    zbuf_q <= zbuf_r;
  end

  // ---------------------------------------------------------------- FILL
  logic [7:0]  fx, fy;
  logic [15:0] faddr, frow;
  wire fill_hs = depth_valid && depth_ready;
  assign depth_ready = state == S_FILL;

  // ---------------------------------------------------------------- FT
  logic [3:0]  ftc;
  assign ft_ready = state == S_FT;

  // ================================================================ vertex stage
  // Credits: a face may start (its first vertex be accepted) only if the FIFO has room for
  // it and for every face already in the vertex/face pipeline.
  logic [12:0] vcnt;          // vertices accepted (≤ 3·2048)
  logic [1:0]  vk;            // corner of the next vertex
  logic [7:0]  inflight;      // faces between their first vertex and the FIFO
  logic [$clog2(TRI_FIFO_DEPTH):0] fifo_count;
  // nverts: 3·num_faces, registered (num_faces is stable while a particle is processed, and
  // FACES starts at least 13 clocks after the window word), so no multiplier is in front of the
  // end-of-faces test.
  logic [12:0] nverts;
  always_ff @(posedge clk) nverts <= 13'(num_faces) * 13'd3;
  wire credit_ok = (32'(fifo_count) + 32'(inflight)) < TRI_FIFO_DEPTH;
  assign vert_ready = state == S_FACES && vcnt != nverts && (vk != 0 || credit_ok);
  wire vert_hs = vert_valid && vert_ready;

  // V0–V4, VI, F0–F5: transform, near test, dividers, face setup → triangle FIFO entries.
  logic        ft_hs, face_v, tri_push, face_front_now, vert_busy;
  logic [rc_pkg::TRI_W-1:0] tri_entry;
  assign ft_hs = ft_valid && ft_ready;
  rc_vertex_stage u_vertex (
      .clk, .rst, .ft_we(!rst && ft_hs), .ft_idx(ftc), .ft_data, .u0, .v0, .ww, .wh,
      .prm_near_plane, .vert_hs, .vk, .vert_x, .vert_y, .vert_z, .face_v, .tri_push, .tri_entry,
      .face_front(face_front_now), .busy(vert_busy));

  // ---------------------------------------------------------------- triangle FIFO
  logic tri_pop, tri_empty;
  rc_pkg::tri_t tri_head;
  rc_fifo #(.W(rc_pkg::TRI_W), .DEPTH(TRI_FIFO_DEPTH)) u_fifo (
      .clk, .rst, .push(tri_push), .din(tri_entry), .pop(tri_pop), .head(tri_head),
      .empty(tri_empty), .count(fifo_count));

  // ================================================================ pixel stage
  // Pixel generator: the current pixel of the current triangle (registers), stepped by
  // +256·A per column and +256·B per row (eq. 6.19–6.20 [ALGORITHM.md]).
  logic        pg_act;
  logic [7:0]  pg_x, pg_y, pg_xlo, pg_xhm1, pg_yhi;
  logic [15:0] pg_addr, pg_rowaddr;
  logic signed [49:0] pg_e[3], pg_rowe[3];
  logic signed [23:0] pg_a[3], pg_b[3];
  logic [2:0]  pg_mine;
  logic [4:0]  pg_sh;
  logic [31:0] pg_iz[3];
  // pg_lastcol: the current pixel is in the box's last column, a register formed for the next
  // clock (at the pop: x_lo = x_hi; at a row change: pg_w1, x_lo = x_hi of the current
  // triangle; within a row: x = x_hi − 1, against pg_xhm1 = x_hi − 1), so the step's select
  // has no comparator in front of it.
  logic        pg_lastcol, pg_w1;
  wire pg_last = pg_lastcol && pg_y == pg_yhi;
  // One adder per edge: the next column (E + 256·A) or the next row's first pixel
  // (E at the row start + 256·B).
  logic signed [49:0] pg_next[3];
  for (genvar k = 0; k < 3; k++) begin : g_pgstep
    assign pg_next[k] = (pg_lastcol ? pg_rowe[k] : pg_e[k]) +
                        (50'(pg_lastcol ? pg_b[k] : pg_a[k]) <<< 8);
  end
  assign tri_pop = !tri_empty && (!pg_act || pg_last);
  always_ff @(posedge clk) begin
    if (rst) pg_act <= 1'b0;
    else if (tri_pop) pg_act <= 1'b1;
    else if (pg_last) pg_act <= 1'b0;
    if (tri_pop) begin
      pg_x <= tri_head.xlo;
      pg_y <= tri_head.ylo;
      pg_xlo <= tri_head.xlo;
      pg_xhm1 <= tri_head.xhi - 1'b1;
      pg_w1 <= tri_head.xlo == tri_head.xhi;
      pg_lastcol <= tri_head.xlo == tri_head.xhi;
      pg_yhi <= tri_head.yhi;
      pg_addr <= tri_head.addr0;
      pg_rowaddr <= tri_head.addr0;
      for (int k = 0; k < 3; k++) begin
        pg_e[k] <= tri_head.e[k];
        pg_rowe[k] <= tri_head.e[k];
        pg_a[k] <= tri_head.a[k];
        pg_b[k] <= tri_head.b[k];
        pg_iz[k] <= tri_head.iz[k];
      end
      pg_mine <= tri_head.mine;
      pg_sh <= tri_head.sh;
    end else if (pg_act) begin
      pg_lastcol <= pg_lastcol ? pg_w1 : pg_x == pg_xhm1;
      if (pg_lastcol) begin
        pg_x <= pg_xlo;
        pg_y <= pg_y + 1'b1;
        pg_addr <= pg_rowaddr + 16'(KW);
        pg_rowaddr <= pg_rowaddr + 16'(KW);
        for (int k = 0; k < 3; k++) begin
          pg_rowe[k] <= pg_next[k];
          pg_e[k] <= pg_next[k];
        end
      end else begin
        pg_x <= pg_x + 1'b1;
        pg_addr <= pg_addr + 1'b1;
        for (int k = 0; k < 3; k++) pg_e[k] <= pg_next[k];
      end
    end
  end

  // P1: inside test (E_k > 0, or E_k = 0 on an owned edge) and e_k' = (E_k >> sh)[23:0].
  // p*_v: an inside fragment; p*_s: the slot is occupied (inside or not) — the drain of the
  // pixel stage is data-independent.
  logic        p1_v, p1_s, p2_s, p2b_s, p3_s, p4_s, p5_s, c1_s, c2_s;
  // E_k ≥ min_e (min_e ∈ {0, 1}) from the sign and a zero test, without a comparator.
  logic [2:0]  pg_in;
  for (genvar k = 0; k < 3; k++) begin : g_inside
    assign pg_in[k] = !pg_e[k][49] && (pg_e[k] != '0 || !pg_mine[k]);
  end
  logic [23:0] p1_en[3];
  logic [31:0] p1_iz[3];
  logic [15:0] p1_addr;
  always_ff @(posedge clk) begin
    p1_s <= rst ? 1'b0 : pg_act;
    p1_v <= rst ? 1'b0 : (pg_act && pg_in[0] && pg_in[1] && pg_in[2]);
    for (int k = 0; k < 3; k++) begin
      p1_en[k] <= 24'(pg_e[k] >>> pg_sh);
      p1_iz[k] <= pg_iz[k];
    end
    p1_addr <= pg_addr;
  end

  // P2: Σe' (ap_uint<26>) and the partial products of e_k'·(1/W_k): e'·iz[16:0] (24 × 17 bits)
  // and e'·iz[31:17] (24 × 15 bits), one DSP48E2 each with its output register.
  logic        p2_v;
  logic [25:0] p2_se;
  logic [40:0] p2_lo[3];
  logic [38:0] p2_hi[3];
  logic [15:0] p2_addr;
  always_ff @(posedge clk) begin
    p2_v <= rst ? 1'b0 : p1_v;
    p2_s <= rst ? 1'b0 : p1_s;
    p2_se <= 26'(p1_en[0]) + 26'(p1_en[1]) + 26'(p1_en[2]);
    for (int k = 0; k < 3; k++) begin
      p2_lo[k] <= 41'(p1_en[k]) * 41'(p1_iz[k][16:0]);
      p2_hi[k] <= 39'(p1_en[k]) * 39'(p1_iz[k][31:17]);
    end
    p2_addr <= p1_addr;
  end

  // P2b: the products e_k'·(1/W_k) = lo + hi·2^17 (F26, 56 bits).
  logic        p2b_v;
  logic [25:0] p2b_se;
  logic [55:0] p2b_pr[3];
  logic [15:0] p2b_addr;
  always_ff @(posedge clk) begin
    p2b_v <= rst ? 1'b0 : p2_v;
    p2b_s <= rst ? 1'b0 : p2_s;
    p2b_se <= p2_se;
    for (int k = 0; k < 3; k++) p2b_pr[k] <= 56'(p2_lo[k]) + (56'(p2_hi[k]) << 17);
    p2b_addr <= p2_addr;
  end

  // P3: Σ e_k'·(1/W_k) (ap_uint<58>).
  logic        p3_v;
  logic [25:0] p3_se;
  logic [57:0] p3_sez;
  logic [15:0] p3_addr;
  always_ff @(posedge clk) begin
    p3_v <= rst ? 1'b0 : p2b_v;
    p3_s <= rst ? 1'b0 : p2b_s;
    p3_se <= p2b_se;
    p3_sez <= 58'(p2b_pr[0]) + 58'(p2b_pr[1]) + 58'(p2b_pr[2]);
    p3_addr <= p2b_addr;
  end

  // Depth recovery (eq. 6.21–6.22 [ALGORITHM.md] on 1/z): z_r = floor(Σe'·2^46 / Σe'·iz), F20, 24 stages;
  // overflow (Σe'·iz = 0 or z ≥ 16 m) saturates to all ones.
  logic [23:0] q_z;
  logic        ov_z;
  rc_div #(.QW(24), .NW(72), .DW(58), .PAD(0)) u_div_z (
      .clk, .n({p3_se, 46'b0}), .d(p3_sez), .q(q_z), .ovf(ov_z));
  // pe_*: the same sideband one clock earlier (the fragment memory's read).
  logic        pd_v, pd_s, pd_any, pe_v, pe_s;
  logic [15:0] pd_addr, pe_addr;
  rc_delay #(.W(17), .L(24)) u_pdel (
      .clk, .rst, .vin(p3_s), .din({p3_v, p3_addr}), .vout(pd_s), .dout({pd_v, pd_addr}),
      .vpre(pe_s), .dpre({pe_v, pe_addr}), .any(pd_any));

  // P4: z_r and the z-buffer word zq = min((z_r + 8) >> 4, kZbufEmpty − 1). The z-buffer read of
  // the fragment's address was issued one clock earlier, from the delay line's output (pd_addr),
  // so its data is registered twice when the fragment reaches P5; the fragment memory's read
  // two clocks earlier (pe_addr), so its word is here in P4, where CompareFragment starts.
  logic        p4_v;
  logic [23:0] p4_z;
  logic [17:0] p4_zq;
  logic [15:0] p4_addr;
  wire [24:0] t = (25'(q_z) + 25'd8) >> 4;
  always_ff @(posedge clk) begin
    p4_v <= rst ? 1'b0 : pd_s && pd_v;
    p4_s <= rst ? 1'b0 : pd_s;
    p4_z <= q_z;
    p4_zq <= t >= 25'(ZEMPTY) ? ZEMPTY - 1'b1 : t[17:0];
    p4_addr <= pd_addr;
  end

  // P5: zbuffer = 1: the z-buffer word is here → strict-less update. The read was issued two clocks ago (read-before-write),
  // so it could not see the writes of the two fragments ahead (in the two previous clocks);
  // they are forwarded from two registers, the newer first.
  logic        p5_v;
  logic [23:0] p5_z;
  logic [17:0] p5_zq;
  logic [15:0] p5_addr;
  logic        lw_v[2];     // [0]: the write of the previous clock, [1]: the one before
  logic [15:0] lw_addr[2];
  logic [17:0] lw_val[2];
  // Address matches, compared one clock ahead (P4 → P5), so P5 has only the select: p5_eq[0]:
  // the fragment's address equals that of the fragment ahead (in P5 now, lw[0] next clock);
  // p5_eq[1]: equals the address that lw[0] holds now (lw[1] next clock).
  logic        p5_eq[2];
  always_ff @(posedge clk) begin
    p5_eq[0] <= p4_addr == p5_addr;
    p5_eq[1] <= p4_addr == lw_addr[0];
  end
  always_ff @(posedge clk) begin
    p5_v <= rst ? 1'b0 : p4_v;
    p5_s <= rst ? 1'b0 : p4_s;
    c1_s <= rst ? 1'b0 : p5_s;  // the two CompareFragment stages
    c2_s <= rst ? 1'b0 : c1_s;
    p5_z <= p4_z;
    p5_zq <= p4_zq;
    p5_addr <= p4_addr;
  end
  wire [17:0] zcur = (lw_v[0] && p5_eq[0]) ? lw_val[0] : (lw_v[1] && p5_eq[1]) ? lw_val[1] : zbuf_q;
  wire zwrite = state == S_FACES && prm_zbuffer && p5_v && p5_zq < zcur;
  always_ff @(posedge clk) begin
    lw_v[0] <= rst ? 1'b0 : zwrite;
    lw_addr[0] <= p5_addr;
    lw_val[0] <= p5_zq;
    lw_v[1] <= rst ? 1'b0 : lw_v[0];
    lw_addr[1] <= lw_addr[0];
    lw_val[1] <= lw_val[0];
  end

  // ================================================================ ZPASS (zbuffer = 1)
  // Read counters (x, y) over width × (height + 1); row `height` reads nothing and only
  // drains the line buffers. The first position is issued in the last clock of FACES (the
  // pixel pipeline is empty then), so the memory's two read registers cost the z pass no clock.
  logic [7:0]  zx, zy;
  logic [15:0] zaddr, zrow;
  logic        zp_start;  // the last clock of FACES, z-buffer mode
  logic        zp_issue;  // a position is issued this cycle
  logic        zp_done;   // all positions issued
  assign zp_issue = zp_start || (state == S_ZPASS && !zp_done);
  // ZA, Z1 sideband (the memory data arrives two clocks after the read is issued).
  logic        za_v, za_rd, z1_v, z1_rd;
  logic [7:0]  za_x, za_y, z1_x, z1_y;
  always_ff @(posedge clk) begin
    za_v  <= rst ? 1'b0 : zp_issue;
    za_rd <= zy < wh;
    za_x  <= zx;
    za_y  <= zy;
    z1_v  <= rst ? 1'b0 : za_v;
    z1_rd <= za_rd;
    z1_x  <= za_x;
    z1_y  <= za_y;
  end
  // Line buffers: lb1 = row y − 1 (z-buffer word, fragment), lb2 = row y − 2 (empty flag,
  // fragment); distributed RAM, asynchronous read.
  logic [29:0] lb1[256];
  logic [12:0] lb2[256];
  logic [29:0] zl_prev;  // (x − 1, y − 1)
  wire  [29:0] zc  = lb1[z1_x];
  wire  [29:0] zr_ = lb1[8'(z1_x + 1'b1)];
  wire  [12:0] zu  = lb2[z1_x];
  wire  [29:0] zd  = {zbuf_q, frag_q};
  always_ff @(posedge clk) begin
    if (z1_v) begin
      if (z1_rd) lb1[z1_x] <= zd;
      lb2[z1_x] <= {zc[29:12] == ZEMPTY, zc[11:0]};
      zl_prev <= zc;
    end
  end
  // Z2: the centre (x, y − 1) and its neighbours (exists, empty, fragment); the centre's
  // own compare started in Z1.
  logic        z2_v;
  logic [17:0] z2_cw;
  logic [3:0]  z2_ne_ok, z2_ne_empty;  // left, right, up, down
  logic [11:0] z2_ne_f[4];
  // The centre's edge-band interval [z_r − edge_band, z_r + edge_band] (F20, signed 26 bits),
  // computed once per centre for its four neighbours.
  logic signed [25:0] z2_lo, z2_hi;
  always_ff @(posedge clk) begin
    z2_v <= rst ? 1'b0 : (z1_v && z1_y != 0);
    z2_lo <= $signed({4'b0, zc[29:12], 4'b0}) - $signed({2'b0, prm_edge_band});
    z2_hi <= $signed({4'b0, zc[29:12], 4'b0}) + $signed({2'b0, prm_edge_band});
    z2_cw <= zc[29:12];
    z2_ne_ok <= {z1_rd, z1_y >= 2, 9'(z1_x) + 9'd1 < 9'(ww), z1_x != 0};
    z2_ne_empty <= {zd[29:12] == ZEMPTY, zu[12], zr_[29:12] == ZEMPTY, zl_prev[29:12] == ZEMPTY};
    z2_ne_f[0] <= zl_prev[11:0];
    z2_ne_f[1] <= zr_[11:0];
    z2_ne_f[2] <= zu[11:0];
    z2_ne_f[3] <= zd[11:0];
  end
  // Edge samples of a covered centre: uncovered neighbours in the window (n_edge), continued
  // when the neighbour's depth is valid and |z_s − z_r| ≤ edge_band (z_r = word << 4, F20),
  // i.e. z_r − edge_band ≤ z_s ≤ z_r + edge_band.
  logic [2:0] ne_cnt, nc_cnt;
  wire        z2_cov = z2_v && z2_cw != ZEMPTY;
  logic [3:0] ne_hit, nc_hit;
  for (genvar n = 0; n < 4; n++) begin : g_nb
    wire [23:0] zs = 24'({z2_ne_f[n], 10'b0});
    wire signed [25:0] zs26 = $signed({2'b0, zs});
    assign ne_hit[n] = z2_ne_ok[n] && z2_ne_empty[n];
    assign nc_hit[n] = ne_hit[n] && zs != 0 && zs26 >= z2_lo && zs26 <= z2_hi;
  end
  assign ne_cnt = 3'(ne_hit[0]) + 3'(ne_hit[1]) + 3'(ne_hit[2]) + 3'(ne_hit[3]);
  assign nc_cnt = 3'(nc_hit[0]) + 3'(nc_hit[1]) + 3'(nc_hit[2]) + 3'(nc_hit[3]);

  // ---------------------------------------------------------------- shared CompareFragment
  // Three stages. z pass: the centre (x, y − 1) as it leaves the line buffer in Z1 (one clock
  // ahead of its neighbour counts in Z2); pixel stage (zbuffer = 0): the fragment in P4 against
  // the fragment word read for it (pe_addr). Either way the results land in the clock they
  // would with a two-stage compare started in Z2 / P5, so the drain (z3_s, z4_s; c1_s, c2_s)
  // is unchanged.
  logic        cf_in_v, cf_v, cf_occ, cf_band;
  logic [23:0] cf_zr, cf_zs;
  logic [10:0] cf_chi;
  logic [25:0] cf_d;
  always_comb begin
    if (state == S_ZPASS) begin
      cf_in_v = z1_v && z1_y != 0 && zc[29:12] != ZEMPTY;  // a covered centre
      cf_zr = 24'({zc[29:12], 4'b0});
      cf_zs = 24'({zc[11:0], 10'b0});
    end else begin
      cf_in_v = state == S_FACES && !prm_zbuffer && p4_v;
      cf_zr = p4_z;
      cf_zs = 24'({frag_q, 10'b0});
    end
  end
  rc_compare u_cmp (
      .clk, .rst, .hard(prm_hard), .thr1(prm_thr1), .inv_thr1(prm_inv_thr1),
      .hard_thr(prm_hard_thr), .align_band(prm_align_band), .in_valid(cf_in_v), .zr(cf_zr),
      .zs(cf_zs), .out_valid(cf_v), .chi(cf_chi), .occluded(cf_occ), .in_band(cf_band),
      .d(cf_d));

  // ---------------------------------------------------------------- memory ports
  always_comb begin
    frag_we = fill_hs;
    frag_wa = faddr;
    frag_wd = depth_data;
    zbuf_we = fill_hs || zwrite;
    zbuf_wa = fill_hs ? faddr : p5_addr;
    zbuf_wd = fill_hs ? ZEMPTY : p5_zq;
    // Read addresses: a pixel-stage fragment (fragment memory one clock before it leaves the
    // depth divider, pe_s; z-buffer as it leaves, pd_s), else the z pass's position (a read has
    // no side effect, so reading it while the pixel stage has a bubble is harmless).
    frag_ra = pe_s ? pe_addr : zaddr;
    zbuf_ra = pd_s ? pd_addr : zaddr;
  end

  // ---------------------------------------------------------------- control
  wire pix_busy = !tri_empty || pg_act || p1_s || p2_s || p2b_s || p3_s || pd_any || p4_s || p5_s || c1_s || c2_s;
  wire faces_done = vcnt == nverts && !vert_busy && !pix_busy;
  logic z3_s, z4_s;  // the two CompareFragment stages behind Z2
  // Z3: a covered centre's counts, registered before they are accumulated.
  logic       z3_cov;
  logic [2:0] z3_ne, z3_nc;
  always_ff @(posedge clk) begin
    z3_s <= rst ? 1'b0 : z2_v;
    z4_s <= rst ? 1'b0 : z3_s;
    z3_cov <= rst ? 1'b0 : (state == S_ZPASS && z2_cov);
    z3_ne <= ne_cnt;
    z3_nc <= nc_cnt;
  end
  wire zp_busy = za_v || z1_v || z2_v || z3_s || z4_s;
  assign zp_start = state == S_FACES && faces_done && prm_zbuffer;

  assign win_ready = state == S_IDLE;
  assign out_valid = state == S_OUT;

  always_ff @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE;
      inflight <= '0;
    end else begin
      // Face credits.
      inflight <= inflight + ((vert_hs && vk == 0) ? 1 : 0) - (face_v ? 1 : 0);
      case (state)
        S_IDLE:
          if (win_valid) begin
            u0 <= win_u0;
            v0 <= win_v0;
            ww <= win_width;
            wh <= win_height;
            fx <= '0;
            fy <= '0;
            faddr <= '0;
            frow <= '0;
            acc_inlier <= '0;
            acc_n_raster <= '0;
            acc_n_occluded <= '0;
            acc_n_depth <= '0;
            acc_diff_count <= '0;
            acc_n_edge <= '0;
            acc_n_cont <= '0;
            acc_diff <= '0;
            acc_front <= '0;
            zx <= '0;
            zy <= '0;
            zaddr <= '0;
            zrow <= '0;
            zp_done <= 1'b0;
            state <= S_FILL;
          end
        S_FILL:
          if (fill_hs) begin
            if (depth_data != 0) acc_n_depth <= acc_n_depth + 1;
            if (fx == ww - 1'b1) begin
              fx <= '0;
              fy <= fy + 1'b1;
              faddr <= frow + 16'(KW);
              frow <= frow + 16'(KW);
              if (fy == wh - 1'b1) begin
                state <= S_FT;
                ftc <= '0;
              end
            end else begin
              fx <= fx + 1'b1;
              faddr <= faddr + 1'b1;
            end
          end
        S_FT:
          if (ft_valid) begin
            ftc <= ftc + 1'b1;
            if (ftc == 11) begin
              state <= S_FACES;
              vcnt <= '0;
              vk <= '0;
            end
          end
        S_FACES: begin
          if (vert_hs) begin
            vcnt <= vcnt + 1'b1;
            vk <= vk == 2 ? 2'd0 : vk + 1'b1;
          end
          if (faces_done) state <= prm_zbuffer ? S_ZPASS : S_OUT;
        end
        S_ZPASS:
          if (zp_done && !zp_busy) state <= S_OUT;
        S_OUT:
          if (out_ready) state <= S_IDLE;
        default: state <= S_IDLE;
      endcase

      // z pass read positions (from zp_start, the last clock of FACES).
      if (zp_issue) begin
        if (zx == ww - 1'b1) begin
          zx <= '0;
          zy <= zy + 1'b1;
          zaddr <= zrow + 16'(KW);
          zrow <= zrow + 16'(KW);
          if (zy == wh) zp_done <= 1'b1;
        end else begin
          zx <= zx + 1'b1;
          zaddr <= zaddr + 1'b1;
        end
      end

      // Accumulators.
      if (face_front_now) acc_front <= acc_front + 1'b1;
      if (state == S_FACES && !prm_zbuffer && p5_v) acc_n_raster <= acc_n_raster + 1;
      if (z3_cov) begin
        acc_n_raster <= acc_n_raster + 1;
        acc_n_edge <= acc_n_edge + 32'(z3_ne);
        acc_n_cont <= acc_n_cont + 32'(z3_nc);
      end
      if (cf_v) begin
        acc_inlier <= acc_inlier + 42'(cf_chi);
        if (cf_occ) acc_n_occluded <= acc_n_occluded + 1;
        if (cf_band) begin
          acc_diff <= acc_diff + 56'($signed(cf_d));
          acc_diff_count <= acc_diff_count + 1;
        end
      end
    end
  end

`ifndef SYNTHESIS
  // ---------------------------------------------------------------- simulation assertions
  // Checked by the Verilator co-simulation (--assert); absent from synthesis.
  // Handshakes (valid/ready): a valid that is not taken stays up with the same data in the next
  // clock — on the output (this core's duty) and on the four inputs (the source's duty).
  logic        hs_out_wait, hs_win_wait, hs_depth_wait, hs_ft_wait, hs_vert_wait;
  logic [41:0] hs_out_inlier;
  logic [55:0] hs_out_diff;
  logic [31:0] hs_out_raster, hs_out_occl, hs_out_depth, hs_out_cnt, hs_out_edge, hs_out_cont;
  logic [11:0] hs_out_front, hs_out_total;
  logic [35:0] hs_win, hs_ft;
  logic [11:0] hs_depth;
  logic [38:0] hs_vert;
  always_ff @(posedge clk) begin
    hs_out_wait <= !rst && out_valid && !out_ready;
    hs_win_wait <= !rst && win_valid && !win_ready;
    hs_depth_wait <= !rst && depth_valid && !depth_ready;
    hs_ft_wait <= !rst && ft_valid && !ft_ready;
    hs_vert_wait <= !rst && vert_valid && !vert_ready;
    {hs_out_inlier, hs_out_diff, hs_out_raster, hs_out_occl, hs_out_depth, hs_out_cnt,
     hs_out_edge, hs_out_cont, hs_out_front, hs_out_total} <=
        {out_inlier_sum, out_depth_diff_sum, out_n_raster, out_n_occluded, out_n_depth,
         out_depth_diff_count, out_n_edge, out_n_edge_continued, out_faces_front, out_faces_total};
    hs_win <= {win_u0, win_v0, win_width, win_height};
    hs_depth <= depth_data;
    hs_ft <= ft_data;
    hs_vert <= {vert_x, vert_y, vert_z};
    if (!rst) begin
      if (hs_out_wait)
        assert (out_valid && {out_inlier_sum, out_depth_diff_sum, out_n_raster, out_n_occluded,
                              out_n_depth, out_depth_diff_count, out_n_edge, out_n_edge_continued,
                              out_faces_front, out_faces_total} ==
                             {hs_out_inlier, hs_out_diff, hs_out_raster, hs_out_occl, hs_out_depth,
                              hs_out_cnt, hs_out_edge, hs_out_cont, hs_out_front, hs_out_total})
        else $error("raster_core: out_valid dropped or output data changed before out_ready");
      if (hs_win_wait)
        assert (win_valid && {win_u0, win_v0, win_width, win_height} == hs_win)
        else $error("raster_core: win_valid dropped or the window word changed before win_ready");
      if (hs_depth_wait)
        assert (depth_valid && depth_data == hs_depth)
        else $error("raster_core: depth_valid dropped or depth_data changed before depth_ready");
      if (hs_ft_wait)
        assert (ft_valid && ft_data == hs_ft)
        else $error("raster_core: ft_valid dropped or ft_data changed before ft_ready");
      if (hs_vert_wait)
        assert (vert_valid && {vert_x, vert_y, vert_z} == hs_vert)
        else $error("raster_core: vert_valid dropped or the vertex changed before vert_ready");
      // Legal state encoding (3-bit binary enum: six of eight codes are states).
      assert (state inside {S_IDLE, S_FILL, S_FT, S_FACES, S_ZPASS, S_OUT})
      else $error("raster_core: illegal state %0d", state);
      // Face credits: faces in flight plus queued triangles never exceed the FIFO's depth.
      assert (32'(fifo_count) + 32'(inflight) <= TRI_FIFO_DEPTH)
      else $error("raster_core: %0d queued + %0d in-flight faces exceed the FIFO depth %0d",
                  fifo_count, inflight, TRI_FIFO_DEPTH);
      // Memory addresses inside the 200 × 200 window memories.
      assert (!frag_we || frag_wa < 16'(KPIX))
      else $error("raster_core: fragment memory write address %0d out of range", frag_wa);
      assert (!zbuf_we || zbuf_wa < 16'(KPIX))
      else $error("raster_core: z-buffer write address %0d out of range", zbuf_wa);
      assert (!pd_s || pd_addr < 16'(KPIX))
      else $error("raster_core: fragment address %0d out of range", pd_addr);
      // The z-buffer is written only in FILL (clear) and by FACES' read-modify-write.
      assert (!zbuf_we || state == S_FILL || (state == S_FACES && prm_zbuffer))
      else $error("raster_core: z-buffer write in state %0d", state);
    end
  end
`endif

  assign out_inlier_sum = acc_inlier;
  assign out_n_raster = acc_n_raster;
  assign out_n_occluded = acc_n_occluded;
  assign out_n_depth = acc_n_depth;
  assign out_depth_diff_sum = acc_diff;
  assign out_depth_diff_count = acc_diff_count;
  assign out_n_edge = acc_n_edge;
  assign out_n_edge_continued = acc_n_cont;
  assign out_faces_front = acc_front;
  assign out_faces_total = num_faces;
endmodule
