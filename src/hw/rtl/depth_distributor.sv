// depth_distributor.sv — RTL of the depth fragment & sample-info distributor of the render/score
// pipeline (thesis §7.5.3, Listing 7.7, Fig. 7.18 [HARDWARE.md]; C model DistributeDepth in
// src/hw/distributor.h). Per call: the depth image (img_width · img_height pixels, row-major,
// depth_t raw F10 m) is copied into the depth memory (the thesis's depth BRAM, Fig. 7.19a), then
// the num_particles windows are dealt to the M raster cores in rounds (particle r·M + c on core
// c; the last round may be partial). Per round every pixel of the union of the round's windows
// is read once and written to the FIFO of every core whose window contains it, so core c
// receives its window word and then exactly its window's pixels in row-major order, the same
// streams as the C model's info_out[c] / depth_out[c].
//
// Traversal (the same set of reads as the C model's sorted, merged column intervals): rows from
// the round's lowest first row to its highest one-past-last row; per row the covering set
// cov[c] = (v_lo[c] ≤ row < v_hi[c]) is registered, and the merged column intervals of the
// covering windows are walked left to right, one pixel per clock: at column col the windows
// hit[c] = cov[c] ∧ u_lo[c] ≤ col < u_hi[c] receive the pixel; where no window covers col the
// walk jumps to min{u_lo[c] : cov[c] ∧ u_lo[c] ≥ col} (a registered min tree, ⌈log2 M⌉ + 1
// clocks; none left: next row). Touching or overlapping ranges join as in the C model's merge.
//
// States (one-hot): IMG (image copy, one pixel per clock) → WIN (the round's windows, one per
// clock, each to its core's window register) → BASE (row base address row·img_width) → ROWC
// (covering set, registered) → ROW (round done, empty row or first jump) → MIN (jump target)
// → HIT (the first column's cores) → WALK (pixels) → MIN … → ROWC (next row) … → WIN (next
// round) or IMG (next call). Reads: address row_base + col into the memory, two read registers
// (the RAM's and one behind it), then the push into the hit cores' FIFOs, 2 clocks after the
// issue.
//
// Flow control: per core a first-word-fall-through FIFO of FD entries (rc_fifo; the C model's
// HW_STREAM(depth_core, 8)) and a credit counter (FIFO entries + reads in flight); a pixel is
// issued only when every core it goes to has a credit left, so no FIFO overflows whatever the
// cores' rates. Every stream is valid/ready (AXI4-Stream rules).
//
// Counters (DepthDistributionCounts, valid from the end of a call until the end of the next
// call's image copy): reads_shared = depth pixels read (each shared pixel once per round),
// reads_unshared = Σ window areas (eq. 7.8 [HARDWARE.md]).
module depth_distributor #(
    parameter int M  = 5,  // raster cores, 1 … 10 (kMaxRasterCores)
    parameter int FD = 8   // per-core depth FIFO entries (power of two)
) (
    input  logic              clk,
    input  logic              rst,
    // Parameters: stable from two clocks before a call's first input word to its end.
    input  logic [9:0]        num_particles,  // n ≤ kMaxParticles = 510
    input  logic [9:0]        img_width,      // pixels, 1 … 640 (kImageWidth)
    input  logic [9:0]        img_height,     // pixels, 1 … 480 (kImageHeight)
    // Depth image, row-major (depth_t raw F10 m), img_width·img_height words per call.
    input  logic              img_valid,
    output logic              img_ready,
    input  logic [11:0]       img_data,
    // Windows in particle order: u0, v0 (10 bits), width, height (8 bits), inside the image.
    input  logic              win_valid,
    output logic              win_ready,
    input  logic [9:0]        win_u0,
    input  logic [9:0]        win_v0,
    input  logic [7:0]        win_width,
    input  logic [7:0]        win_height,
    // Per core c: the window word {u0, v0, width, height} at bits [36c +: 36] …
    output logic [M-1:0]      info_valid,
    input  logic [M-1:0]      info_ready,
    output logic [M*36-1:0]   info_data,
    // … and its pixels (depth_t raw) at bits [12c +: 12].
    output logic [M-1:0]      depth_valid,
    input  logic [M-1:0]      depth_ready,
    output logic [M*12-1:0]   depth_data,
    output logic [31:0]       reads_shared,
    output logic [31:0]       reads_unshared
);
  localparam int NPIX = 640 * 480;              // kImageWidth · kImageHeight
  localparam int NL   = M > 1 ? $clog2(M) : 0;  // min-tree levels
  localparam int NP   = 1 << NL;                // min-tree leaves (M padded to a power of two)
  localparam int CW   = $clog2(FD) + 1;         // credit counter bits (0 … FD)

  // ---------------------------------------------------------------- state (one-hot)
  localparam int S_IMG = 0, S_WIN = 1, S_BASE = 2, S_ROWC = 3, S_ROW = 4, S_MIN = 5, S_HIT = 6, S_WALK = 7;
  logic [7:0] st;

  // ---------------------------------------------------------------- depth memory (BRAM)
  // 307 200 × 12 bits, one write port (image copy) and one read port with two registers.
  logic [11:0] dmem[NPIX];
  logic        dm_we;
  logic [18:0] dm_wa, dm_ra;
  logic [11:0] dm_r, dm_q;
  always_ff @(posedge clk) begin
    if (dm_we) dmem[dm_wa] <= img_data;
    dm_r <= dmem[dm_ra];
    dm_q <= dm_r;
  end

  // ---------------------------------------------------------------- round registers
  logic [18:0] npix_m1;                      // img_width·img_height − 1
  logic [18:0] pix;                          // image copy counter
  logic [9:0]  first;                        // first particle of the round
  logic [3:0]  wc;                           // window counter in WIN
  logic [3:0]  nact_m1;                      // active cores − 1 = min(M, n − first) − 1
  logic [9:0]  u_lo[M], u_hi[M], v_lo[M], v_hi[M];  // window bounds, pixels, [lo, hi)
  logic [M-1:0] act, cov;                    // active cores; windows covering the row
  logic [9:0]  row, row_lo, row_hi;          // current row, round's row range [lo, hi)
  logic [18:0] row_base;                     // row·img_width
  logic [9:0]  col;
  logic [$clog2(NL + 2):0] mw;               // MIN wait counter
  logic [M-1:0] info_full;
  logic [35:0] info_w[M];

  always_ff @(posedge clk) npix_m1 <= 19'(img_width) * 19'(img_height) - 19'd1;

  wire [10:0] left = 11'(num_particles) - 11'(first);  // particles from this round on
  always_comb nact_m1 = left >= 11'(M) ? 4'(M - 1) : 4'(left - 11'd1);

  // Image copy.
  logic img_last_d;  // the clock after a copy (a call with n = 0 returns to IMG at once)
  assign img_ready = st[S_IMG] && !img_last_d;
  wire img_hs = img_valid && img_ready;
  assign dm_we = img_hs;
  assign dm_wa = pix;

  // Windows.
  assign win_ready = st[S_WIN] && !info_full[wc];
  wire win_hs = win_valid && win_ready;
  wire [9:0] w_vhi = win_v0 + 10'(win_height);
  wire [9:0] nrow_lo = (wc == 0 || win_v0 < row_lo) ? win_v0 : row_lo;
  wire [9:0] nrow_hi = (wc == 0 || w_vhi > row_hi) ? w_vhi : row_hi;

  // Covering set of `row`, registered in ROWC (ROW decides on it in the next clock).
  logic [M-1:0] cov_n;
  logic         row_last;  // row = the round's one-past-last row
  always_ff @(posedge clk) begin
    for (int c = 0; c < M; c++) cov_n[c] <= act[c] && v_lo[c] <= row && row < v_hi[c];
    row_last <= row == row_hi;
  end

  // Min tree: the smallest u_lo of the covering windows at or right of col (MSB set: none).
  logic [10:0] mt[NL+1][NP];
  always_ff @(posedge clk) begin
    for (int i = 0; i < M; i++) mt[0][i] <= (cov[i] && u_lo[i] >= col) ? {1'b0, u_lo[i]} : 11'h7ff;
    for (int i = M; i < NP; i++) mt[0][i] <= 11'h7ff;
    for (int l = 0; l < NL; l++)
      for (int i = 0; i < (NP >> (l + 1)); i++)
        mt[l+1][i] <= mt[l][2*i] < mt[l][2*i+1] ? mt[l][2*i] : mt[l][2*i+1];
  end
  wire [10:0] jump = mt[NL][0];

  // Walk: the cores the pixel at (row, col) goes to (hit, a register: formed in HIT for the
  // interval's first column, then in each WALK clock for the column of the next clock, col + 1
  // after an issue, col after a credit stall), and their credits.
  logic [M-1:0] hit, hit_same, hit_plus, cred_ok, push_q, push_r, pop;
  logic [CW-1:0] cred[M];
  wire [10:0] col1 = 11'(col) + 11'd1;
  always_comb
    for (int c = 0; c < M; c++) begin
      hit_same[c] = cov[c] && u_lo[c] <= col && col < u_hi[c];
      hit_plus[c] = cov[c] && 11'(u_lo[c]) <= col1 && col1 < 11'(u_hi[c]);
    end
  wire issue = st[S_WALK] && hit != '0 && ((~hit | cred_ok) == '1);
  always_ff @(posedge clk) hit <= st[S_WALK] && issue ? hit_plus : hit_same;
  assign dm_ra = row_base + 19'(col);

  // pix = npix_m1, from two comparisons registered a clock earlier (of pix and of pix + 1, the
  // one that applies chosen by the last clock's handshake), so no comparator precedes the
  // events.
  logic pix_eq0, pix_eq1, img_hs_d;
  always_ff @(posedge clk) begin
    pix_eq0 <= pix == npix_m1;
    pix_eq1 <= pix + 19'd1 == npix_m1;
    img_hs_d <= !rst && img_hs && !img_last;
    img_last_d <= !rst && img_last;
  end
  wire pix_last  = img_hs_d ? pix_eq1 : pix_eq0;
  // Events of the state machine (each register below is written by a few of them, so its
  // next-state logic is a short priority chain rather than a multiplexer over every state).
  wire img_last  = st[S_IMG] && img_hs && pix_last;              // the image is copied
  wire win_last  = win_hs && wc == nact_m1;                      // the round's last window
  wire row_end   = st[S_ROW] && row_last;                        // the round's rows are done
  wire call_end  = row_end && last_round;
  wire row_skip  = st[S_ROW] && !row_last && cov_n == '0;        // no window on this row
  wire row_go    = st[S_ROW] && !row_last && cov_n != '0;
  wire min_done  = st[S_MIN] && mw_done;
  wire row_next  = row_skip || (min_done && jump[10]);           // to the next row
  wire walk_gap  = st[S_WALK] && hit == '0;                      // end of a merged interval
  logic last_round, mw_done;
  always_ff @(posedge clk) begin
    last_round <= 11'(first) + 11'(M) >= 11'(num_particles);
    mw_done <= st[S_MIN] && 32'(mw) == NL;  // MIN's clock NL + 1 (the tree's output is valid)
  end

  always_ff @(posedge clk) begin
    if (rst) st <= 8'b1 << S_IMG;
    else if (img_last) st <= num_particles != 0 ? 8'b1 << S_WIN : 8'b1 << S_IMG;
    else if (win_last) st <= 8'b1 << S_BASE;
    else if (st[S_BASE] || row_next) st <= 8'b1 << S_ROWC;
    else if (st[S_ROWC]) st <= 8'b1 << S_ROW;
    else if (row_end) st <= last_round ? 8'b1 << S_IMG : 8'b1 << S_WIN;
    else if (row_go || walk_gap) st <= 8'b1 << S_MIN;
    else if (min_done) st <= 8'b1 << S_HIT;
    else if (st[S_HIT]) st <= 8'b1 << S_WALK;
  end

  always_ff @(posedge clk) begin
    if (rst || img_last) pix <= '0;
    else if (img_hs) pix <= pix + 19'd1;
    if (rst || img_last || call_end) first <= '0;
    else if (row_end) first <= first + 10'(M);
    if (rst || img_last || row_end) wc <= '0;
    else if (win_hs) wc <= wc + 4'd1;
    for (int c = 0; c < M; c++)  // explicit decode of wc (no indexed write)
      if (rst || img_last || row_end) act[c] <= 1'b0;
      else if (win_hs && wc == 4'(c)) act[c] <= 1'b1;
    if (rst) cov <= '0;
    else if (row_go) cov <= cov_n;
    if (row_go || walk_gap) mw <= '0;
    else mw <= mw + 1'b1;
    if (win_last) row <= nrow_lo;
    else if (row_next) row <= row + 10'd1;
    if (st[S_BASE]) row_base <= 19'(row) * 19'(img_width);
    else if (row_next) row_base <= row_base + 19'(img_width);
    if (row_go) col <= '0;
    else if (min_done) col <= jump[9:0];
    else if (issue) col <= col + 10'd1;
    for (int c = 0; c < M; c++)
      if (win_hs && wc == 4'(c)) begin
        u_lo[c] <= win_u0;
        u_hi[c] <= win_u0 + 10'(win_width);
        v_lo[c] <= win_v0;
        v_hi[c] <= w_vhi;
        info_w[c] <= {win_u0, win_v0, win_width, win_height};
      end
    if (win_hs) begin
      row_lo <= nrow_lo;
      row_hi <= nrow_hi;
    end
    for (int c = 0; c < M; c++)
      if (rst) info_full[c] <= 1'b0;
      else if (win_hs && wc == 4'(c)) info_full[c] <= 1'b1;
      else if (info_ready[c]) info_full[c] <= 1'b0;
    // Counters: cleared when a call's image is copied (its rounds start).
    if (rst || img_last) reads_shared <= '0;
    else if (issue) reads_shared <= reads_shared + 32'd1;
    if (rst || img_last) reads_unshared <= '0;
    else if (win_hs) reads_unshared <= reads_unshared + 32'(16'(win_width) * 16'(win_height));
  end

  // Read pipeline: issue → dm_r → dm_q + push.
  always_ff @(posedge clk) begin
    push_r <= rst ? '0 : (issue ? hit : '0);
    push_q <= rst ? '0 : push_r;
  end

  // Per-core FIFOs and credits.
  for (genvar c = 0; c < M; c++) begin : g_core
    logic [$clog2(FD):0] cnt;
    logic empty;
    logic [11:0] head;
    rc_fifo #(.W(12), .DEPTH(FD)) u_fifo (
        .clk, .rst, .push(push_q[c]), .din(dm_q), .pop(pop[c]), .head(head), .empty(empty), .count(cnt));
    assign depth_valid[c] = !empty;
    assign depth_data[12*c+:12] = head;
    assign pop[c] = depth_valid[c] && depth_ready[c];
    wire [CW-1:0] cred_n = cred[c] + CW'(issue && hit[c]) - CW'(pop[c]);
    always_ff @(posedge clk) begin
      cred[c] <= rst ? '0 : cred_n;
      cred_ok[c] <= rst ? 1'b1 : cred_n < CW'(FD);
    end
    assign info_valid[c] = info_full[c];
    assign info_data[36*c+:36] = info_w[c];
`ifndef SYNTHESIS
    always_ff @(posedge clk)
      if (!rst) begin
        assert (cred[c] <= CW'(FD))
        else $error("depth_distributor: core %0d credits %0d exceed the FIFO depth %0d", c, cred[c], FD);
        assert (32'(cnt) <= 32'(cred[c]))
        else $error("depth_distributor: core %0d FIFO holds %0d words but %0d credits are taken", c, cnt, cred[c]);
      end
`endif
  end

`ifndef SYNTHESIS
  // ---------------------------------------------------------------- simulation assertions
  logic        hs_img_wait, hs_win_wait;
  logic [11:0] hs_img;
  logic [35:0] hs_win;
  logic [M-1:0] hs_info_wait, hs_depth_wait;
  logic [M*36-1:0] hs_info;
  logic [M*12-1:0] hs_depth;
  always_ff @(posedge clk) begin
    hs_img_wait <= !rst && img_valid && !img_ready;
    hs_win_wait <= !rst && win_valid && !win_ready;
    hs_info_wait <= rst ? '0 : info_valid & ~info_ready;
    hs_depth_wait <= rst ? '0 : depth_valid & ~depth_ready;
    hs_img <= img_data;
    hs_win <= {win_u0, win_v0, win_width, win_height};
    hs_info <= info_data;
    hs_depth <= depth_data;
    if (!rst) begin
      // Inputs: the source holds valid and its data until ready.
      if (hs_img_wait)
        assert (img_valid && img_data == hs_img)
        else $error("depth_distributor: img_valid dropped or img_data changed before img_ready");
      if (hs_win_wait)
        assert (win_valid && {win_u0, win_v0, win_width, win_height} == hs_win)
        else $error("depth_distributor: win_valid dropped or the window word changed before win_ready");
      // Outputs: this module holds valid and data until ready.
      for (int c = 0; c < M; c++) begin
        if (hs_info_wait[c])
          assert (info_valid[c] && info_data[36*c+:36] == hs_info[36*c+:36])
          else $error("depth_distributor: info_valid[%0d] dropped or its word changed before ready", c);
        if (hs_depth_wait[c])
          assert (depth_valid[c] && depth_data[12*c+:12] == hs_depth[12*c+:12])
          else $error("depth_distributor: depth_valid[%0d] dropped or its pixel changed before ready", c);
      end
      assert ($onehot(st))
      else $error("depth_distributor: state %b is not one-hot", st);
      // Memory addresses inside the image.
      assert (!dm_we || dm_wa < 19'(NPIX))
      else $error("depth_distributor: depth memory write address %0d out of range", dm_wa);
      assert (!issue || dm_ra < 19'(NPIX))
      else $error("depth_distributor: depth memory read address %0d out of range", dm_ra);
      // A window lies inside the image (the driver's WindowIsValid).
      assert (!win_hs || (win_width != 0 && win_height != 0 && 11'(win_u0) + 11'(win_width) <= 11'(img_width) &&
                          11'(win_v0) + 11'(win_height) <= 11'(img_height)))
      else $error("depth_distributor: window (%0d, %0d, %0d x %0d) outside the %0d x %0d image", win_u0, win_v0,
                  win_width, win_height, img_width, img_height);
    end
  end
`endif
endmodule
