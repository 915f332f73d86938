// weigh_accel.sv — the weighing pipeline (weigh_pipeline.sv: FT distributor, vertex multiplier,
// depth distributor, M raster cores, weight merger) as an accelerator a processor drives over
// AXI, the way an HLS kernel is driven (docs/HARDWARE.md §16):
//
//   s_axi_ctrl (AXI4-Lite, 32-bit) ── registers (weigh_regs_pkg, from src/hw/rtl/weigh_regs.json)
//   m_axi_gmem (AXI4, 128-bit) ──▶ 6 × axi_burst_reader ──▶ weigh_pipeline ──▶ axi_record_writer ──▶ m_axi_gmem
//   interrupt ◀── GIE ∧ (ISR ≠ 0)
//
// One AXI4 master port, `m_axi_gmem`, with DW = 128 data bits: the width of the XCZU9EG's
// S_AXI_HP ports (PS–PL, 128 bits at up to 333 MHz), so one beat per clock at 200 MHz is 3.2 GB/s,
// above what the pipeline takes (one 2-byte pixel, one 8-byte FT or model word per clock ≤ 1.6
// GB/s summed over the streams at their peaks). The six readers (IMG, WIN, FT, MODEL, PROB, CELL
// buffers; each its own ARID 0 … 5) share the read channels through a round-robin arbiter; each
// requests a burst only with room for it in its beat FIFO, so R (RREADY = 1) never blocks and a
// reader whose stream the pipeline does not take yet cannot hold up the others. Read data is
// routed by RID, so an interconnect may reorder bursts of different IDs. The writer (AWID 6)
// writes one 64-byte record per particle. Addresses are 64 bits; buffer bases are 256-byte
// aligned; bursts are INCR, ≤ 16 beats, never across 4 KB.
//
// Control (Vitis ap_ctrl_hs style): the host writes the parameters and buffer addresses, then
// CTRL.AP_START = 1. The accelerator waits two clocks (the pipeline registers its parameters),
// starts the readers and the writer, and when every record's write response is back and four
// more clocks have passed (the depth distributor's counters settle) it latches CYCLES (clocks
// from the start to here) and the depth distributor's read counters, sets AP_DONE and AP_READY
// (cleared when CTRL is read), clears AP_START, and sets the ISR bits enabled in IER. The
// parameters must not change while a call runs (AP_IDLE = 0).
//
// Bus errors: a read beat with RRESP ≠ OKAY or a write response with BRESP ≠ OKAY sets
// STATUS.RD_ERR or STATUS.WR_ERR (sticky until the host writes 1 to the bit) and records the
// first such response (RD_RESP, RD_ID, WR_RESP). The call is not cut short: the readers count
// the failed beats as data and the writer counts the failed responses, so AP_DONE and the
// interrupt still come and the host reads STATUS after every call.
module weigh_accel
  import weigh_regs_pkg::*;
#(
    parameter int M = 5  // raster cores, 1 … 10
) (
    input  logic          ap_clk,
    input  logic          ap_rst_n,
    // AXI4-Lite slave: registers.
    input  logic          s_axi_ctrl_awvalid,
    output logic          s_axi_ctrl_awready,
    input  logic [7:0]    s_axi_ctrl_awaddr,
    input  logic          s_axi_ctrl_wvalid,
    output logic          s_axi_ctrl_wready,
    input  logic [31:0]   s_axi_ctrl_wdata,
    input  logic [3:0]    s_axi_ctrl_wstrb,
    output logic          s_axi_ctrl_bvalid,
    input  logic          s_axi_ctrl_bready,
    output logic [1:0]    s_axi_ctrl_bresp,
    input  logic          s_axi_ctrl_arvalid,
    output logic          s_axi_ctrl_arready,
    input  logic [7:0]    s_axi_ctrl_araddr,
    output logic          s_axi_ctrl_rvalid,
    input  logic          s_axi_ctrl_rready,
    output logic [31:0]   s_axi_ctrl_rdata,
    output logic [1:0]    s_axi_ctrl_rresp,
    // AXI4 master: DDR.
    output logic          m_axi_gmem_awvalid,
    input  logic          m_axi_gmem_awready,
    output logic [63:0]   m_axi_gmem_awaddr,
    output logic [7:0]    m_axi_gmem_awlen,
    output logic [2:0]    m_axi_gmem_awsize,
    output logic [1:0]    m_axi_gmem_awburst,
    output logic [2:0]    m_axi_gmem_awid,
    output logic          m_axi_gmem_awlock,
    output logic [3:0]    m_axi_gmem_awcache,
    output logic [2:0]    m_axi_gmem_awprot,
    output logic [3:0]    m_axi_gmem_awqos,
    output logic          m_axi_gmem_wvalid,
    input  logic          m_axi_gmem_wready,
    output logic [127:0]  m_axi_gmem_wdata,
    output logic [15:0]   m_axi_gmem_wstrb,
    output logic          m_axi_gmem_wlast,
    input  logic          m_axi_gmem_bvalid,
    output logic          m_axi_gmem_bready,
    input  logic [1:0]    m_axi_gmem_bresp,
    input  logic [2:0]    m_axi_gmem_bid,
    output logic          m_axi_gmem_arvalid,
    input  logic          m_axi_gmem_arready,
    output logic [63:0]   m_axi_gmem_araddr,
    output logic [7:0]    m_axi_gmem_arlen,
    output logic [2:0]    m_axi_gmem_arsize,
    output logic [1:0]    m_axi_gmem_arburst,
    output logic [2:0]    m_axi_gmem_arid,
    output logic          m_axi_gmem_arlock,
    output logic [3:0]    m_axi_gmem_arcache,
    output logic [2:0]    m_axi_gmem_arprot,
    output logic [3:0]    m_axi_gmem_arqos,
    input  logic          m_axi_gmem_rvalid,
    output logic          m_axi_gmem_rready,
    input  logic [127:0]  m_axi_gmem_rdata,
    input  logic [1:0]    m_axi_gmem_rresp,
    input  logic          m_axi_gmem_rlast,
    input  logic [2:0]    m_axi_gmem_rid,
    // Level interrupt: GIE ∧ (ISR ≠ 0).
    output logic          interrupt
);
  localparam int NR = 6;  // readers: 0 IMG, 1 WIN, 2 FT, 3 MODEL, 4 PROB, 5 CELL
  localparam int R_IMG = 0, R_WIN = 1, R_FT = 2, R_MODEL = 3, R_PROB = 4, R_CELL = 5;
  localparam int WRITER_ID = 6;
  wire clk = ap_clk;
  wire rst = !ap_rst_n;

  // ---- Registers ----
  logic        ap_start, ap_done, ap_ready, gie;
  logic [1:0]  ier, isr;
  logic [9:0]  r_num_particles, r_img_width, r_img_height;
  logic [11:0] r_num_faces;
  logic [1:0]  r_raster_flags;
  logic [23:0] r_thr1, r_hard_thr, r_align_band, r_edge_band, r_near_plane;
  logic [19:0] r_inv_thr1;
  logic [31:0] r_weight_ab, r_weight_gd;
  logic        r_occl;
  logic [63:0] r_addr[7];  // IMG, WIN, FT, MODEL, PROB, CELL, OUT
  logic [63:0] r_cycles;
  logic [31:0] r_dd_shared, r_dd_unshared;
  // STATUS: sticky bus-error bits (W1C) and the first failed response of each direction.
  logic        st_rd_err, st_wr_err;
  logic [1:0]  st_rd_resp, st_wr_resp;  // AXI RESP: 1 EXOKAY, 2 SLVERR, 3 DECERR
  logic [2:0]  st_rd_id;                // RID: the reader (0 IMG … 5 CELL)

  // Control states (one-hot): IDLE → SETUP (2 clocks) → RUN → DRAIN (4 clocks) → IDLE.
  localparam int S_IDLE = 0, S_SETUP = 1, S_RUN = 2, S_DRAIN = 3;
  logic [3:0]  st;
  logic [2:0]  wait_cnt;
  logic [63:0] cycles;
  wire         idle = st[S_IDLE];
  wire         go = st[S_SETUP] && wait_cnt == 3'd1;  // the readers' and the writer's start
  logic [NR-1:0] rd_done;
  logic          wr_done, wr_err;
  logic [31:0]   dd_shared, dd_unshared;
  wire           finish = st[S_DRAIN] && wait_cnt == 3'd3;

  // Failed responses on m_axi_gmem (RREADY and BREADY are always 1: a valid beat is taken).
  wire rd_fail = m_axi_gmem_rvalid && m_axi_gmem_rresp != 2'b00;
  wire wr_fail = m_axi_gmem_bvalid && m_axi_gmem_bresp != 2'b00;

  // ---- AXI4-Lite: one write (AW and W together) and one read at a time ----
  wire aw_hs = s_axi_ctrl_awvalid && s_axi_ctrl_wvalid && !s_axi_ctrl_bvalid;
  assign s_axi_ctrl_awready = aw_hs;
  assign s_axi_ctrl_wready  = aw_hs;
  assign s_axi_ctrl_bresp   = 2'b00;
  assign s_axi_ctrl_rresp   = 2'b00;
  assign s_axi_ctrl_arready = !s_axi_ctrl_rvalid;
  wire ar_hs = s_axi_ctrl_arvalid && s_axi_ctrl_arready;
  wire [31:0] wmask = {{8{s_axi_ctrl_wstrb[3]}}, {8{s_axi_ctrl_wstrb[2]}}, {8{s_axi_ctrl_wstrb[1]}}, {8{s_axi_ctrl_wstrb[0]}}};

  function automatic logic [31:0] merge(input logic [31:0] old, input logic [31:0] wd, input logic [31:0] mask);
    return (old & ~mask) | (wd & mask);
  endfunction

  logic [31:0] rd_word;
  always_comb begin
    rd_word = '0;
    unique case (s_axi_ctrl_araddr & 8'hFC)
      REG_CTRL:              rd_word = 32'({ap_ready, idle, ap_done, ap_start});
      REG_GIE:               rd_word = 32'(gie);
      REG_IER:               rd_word = 32'(ier);
      REG_ISR:               rd_word = 32'(isr);
      REG_ID:                rd_word = ID_EXPECTED;
      REG_CORES:             rd_word = 32'(M);
      REG_STATUS: begin
        rd_word[STATUS_RD_ERR_LSB] = st_rd_err;
        rd_word[STATUS_WR_ERR_LSB] = st_wr_err;
        rd_word[STATUS_RD_RESP_LSB+:STATUS_RD_RESP_W] = st_rd_resp;
        rd_word[STATUS_WR_RESP_LSB+:STATUS_WR_RESP_W] = st_wr_resp;
        rd_word[STATUS_RD_ID_LSB+:STATUS_RD_ID_W] = st_rd_id;
      end
      REG_NUM_PARTICLES:     rd_word = 32'(r_num_particles);
      REG_NUM_FACES:         rd_word = 32'(r_num_faces);
      REG_IMG_WIDTH:         rd_word = 32'(r_img_width);
      REG_IMG_HEIGHT:        rd_word = 32'(r_img_height);
      REG_RASTER_FLAGS:      rd_word = 32'(r_raster_flags);
      REG_THR1:              rd_word = 32'(r_thr1);
      REG_INV_THR1:          rd_word = 32'(r_inv_thr1);
      REG_HARD_THR:          rd_word = 32'(r_hard_thr);
      REG_ALIGN_BAND:        rd_word = 32'(r_align_band);
      REG_EDGE_BAND:         rd_word = 32'(r_edge_band);
      REG_NEAR_PLANE:        rd_word = 32'(r_near_plane);
      REG_WEIGHT_AB:         rd_word = r_weight_ab;
      REG_WEIGHT_GD:         rd_word = r_weight_gd;
      REG_WEIGHT_FLAGS:      rd_word = 32'(r_occl);
      REG_IMG_ADDR_LO:       rd_word = r_addr[0][31:0];
      REG_IMG_ADDR_HI:       rd_word = r_addr[0][63:32];
      REG_WIN_ADDR_LO:       rd_word = r_addr[1][31:0];
      REG_WIN_ADDR_HI:       rd_word = r_addr[1][63:32];
      REG_FT_ADDR_LO:        rd_word = r_addr[2][31:0];
      REG_FT_ADDR_HI:        rd_word = r_addr[2][63:32];
      REG_MODEL_ADDR_LO:     rd_word = r_addr[3][31:0];
      REG_MODEL_ADDR_HI:     rd_word = r_addr[3][63:32];
      REG_PROB_ADDR_LO:      rd_word = r_addr[4][31:0];
      REG_PROB_ADDR_HI:      rd_word = r_addr[4][63:32];
      REG_CELL_ADDR_LO:      rd_word = r_addr[5][31:0];
      REG_CELL_ADDR_HI:      rd_word = r_addr[5][63:32];
      REG_OUT_ADDR_LO:       rd_word = r_addr[6][31:0];
      REG_OUT_ADDR_HI:       rd_word = r_addr[6][63:32];
      REG_CYCLES_LO:         rd_word = r_cycles[31:0];
      REG_CYCLES_HI:         rd_word = r_cycles[63:32];
      REG_DD_READS_SHARED:   rd_word = r_dd_shared;
      REG_DD_READS_UNSHARED: rd_word = r_dd_unshared;
      default:               rd_word = '0;
    endcase
  end

  wire [7:0]  wa = s_axi_ctrl_awaddr & 8'hFC;
  wire [31:0] wd = s_axi_ctrl_wdata;
  always_ff @(posedge clk) begin
    if (rst) begin
      s_axi_ctrl_bvalid <= 1'b0;
      s_axi_ctrl_rvalid <= 1'b0;
      s_axi_ctrl_rdata <= '0;
      ap_start <= 1'b0;
      ap_done <= 1'b0;
      ap_ready <= 1'b0;
      gie <= 1'b0;
      ier <= '0;
      isr <= '0;
      st_rd_err <= 1'b0;
      st_wr_err <= 1'b0;
      st_rd_resp <= '0;
      st_wr_resp <= '0;
      st_rd_id <= '0;
      r_num_particles <= '0;
      r_num_faces <= '0;
      r_img_width <= '0;
      r_img_height <= '0;
      r_raster_flags <= '0;
      r_thr1 <= '0;
      r_inv_thr1 <= '0;
      r_hard_thr <= '0;
      r_align_band <= '0;
      r_edge_band <= '0;
      r_near_plane <= '0;
      r_weight_ab <= '0;
      r_weight_gd <= '0;
      r_occl <= 1'b0;
      for (int i = 0; i < 7; i++) r_addr[i] <= '0;
      r_cycles <= '0;
      r_dd_shared <= '0;
      r_dd_unshared <= '0;
    end else begin
      // Write channel.
      if (aw_hs) s_axi_ctrl_bvalid <= 1'b1;
      else if (s_axi_ctrl_bready) s_axi_ctrl_bvalid <= 1'b0;
      if (aw_hs) begin
        unique case (wa)
          REG_CTRL:          if (s_axi_ctrl_wstrb[0] && wd[CTRL_AP_START_LSB] && idle) ap_start <= 1'b1;
          REG_GIE:           if (s_axi_ctrl_wstrb[0]) gie <= wd[GIE_ENABLE_LSB];
          REG_IER:           if (s_axi_ctrl_wstrb[0]) ier <= wd[1:0];
          REG_ISR:           ;  // below, with the hardware's set
          REG_STATUS:        ;  // below, with the bus's set
          REG_NUM_PARTICLES: r_num_particles <= 10'(merge(32'(r_num_particles), wd, wmask));
          REG_NUM_FACES:     r_num_faces <= 12'(merge(32'(r_num_faces), wd, wmask));
          REG_IMG_WIDTH:     r_img_width <= 10'(merge(32'(r_img_width), wd, wmask));
          REG_IMG_HEIGHT:    r_img_height <= 10'(merge(32'(r_img_height), wd, wmask));
          REG_RASTER_FLAGS:  r_raster_flags <= 2'(merge(32'(r_raster_flags), wd, wmask));
          REG_THR1:          r_thr1 <= 24'(merge(32'(r_thr1), wd, wmask));
          REG_INV_THR1:      r_inv_thr1 <= 20'(merge(32'(r_inv_thr1), wd, wmask));
          REG_HARD_THR:      r_hard_thr <= 24'(merge(32'(r_hard_thr), wd, wmask));
          REG_ALIGN_BAND:    r_align_band <= 24'(merge(32'(r_align_band), wd, wmask));
          REG_EDGE_BAND:     r_edge_band <= 24'(merge(32'(r_edge_band), wd, wmask));
          REG_NEAR_PLANE:    r_near_plane <= 24'(merge(32'(r_near_plane), wd, wmask));
          REG_WEIGHT_AB:     r_weight_ab <= merge(r_weight_ab, wd, wmask);
          REG_WEIGHT_GD:     r_weight_gd <= merge(r_weight_gd, wd, wmask);
          REG_WEIGHT_FLAGS:  if (s_axi_ctrl_wstrb[0]) r_occl <= wd[0];
          REG_IMG_ADDR_LO:   r_addr[0][31:0] <= merge(r_addr[0][31:0], wd, wmask);
          REG_IMG_ADDR_HI:   r_addr[0][63:32] <= merge(r_addr[0][63:32], wd, wmask);
          REG_WIN_ADDR_LO:   r_addr[1][31:0] <= merge(r_addr[1][31:0], wd, wmask);
          REG_WIN_ADDR_HI:   r_addr[1][63:32] <= merge(r_addr[1][63:32], wd, wmask);
          REG_FT_ADDR_LO:    r_addr[2][31:0] <= merge(r_addr[2][31:0], wd, wmask);
          REG_FT_ADDR_HI:    r_addr[2][63:32] <= merge(r_addr[2][63:32], wd, wmask);
          REG_MODEL_ADDR_LO: r_addr[3][31:0] <= merge(r_addr[3][31:0], wd, wmask);
          REG_MODEL_ADDR_HI: r_addr[3][63:32] <= merge(r_addr[3][63:32], wd, wmask);
          REG_PROB_ADDR_LO:  r_addr[4][31:0] <= merge(r_addr[4][31:0], wd, wmask);
          REG_PROB_ADDR_HI:  r_addr[4][63:32] <= merge(r_addr[4][63:32], wd, wmask);
          REG_CELL_ADDR_LO:  r_addr[5][31:0] <= merge(r_addr[5][31:0], wd, wmask);
          REG_CELL_ADDR_HI:  r_addr[5][63:32] <= merge(r_addr[5][63:32], wd, wmask);
          REG_OUT_ADDR_LO:   r_addr[6][31:0] <= merge(r_addr[6][31:0], wd, wmask);
          REG_OUT_ADDR_HI:   r_addr[6][63:32] <= merge(r_addr[6][63:32], wd, wmask);
          default: ;  // read-only or unmapped: ignored
        endcase
      end
      // Read channel; reading CTRL clears AP_DONE and AP_READY (below).
      if (ar_hs) begin
        s_axi_ctrl_rvalid <= 1'b1;
        s_axi_ctrl_rdata <= rd_word;
      end else if (s_axi_ctrl_rready) begin
        s_axi_ctrl_rvalid <= 1'b0;
      end
      // Done: latched figures and the status bits (a CTRL read in the same clock sees the old
      // value and does not clear the new done).
      if (finish) begin
        ap_start <= 1'b0;
        ap_done <= 1'b1;
        ap_ready <= 1'b1;
        r_cycles <= cycles;
        r_dd_shared <= dd_shared;
        r_dd_unshared <= dd_unshared;
      end else if (ar_hs && (s_axi_ctrl_araddr & 8'hFC) == REG_CTRL) begin
        ap_done <= 1'b0;
        ap_ready <= 1'b0;
      end
      // ISR: set by the events IER enables, each bit toggled by a written 1.
      for (int b = 0; b < 2; b++) begin
        automatic logic ev = finish && ier[b];
        automatic logic tog = aw_hs && wa == REG_ISR && s_axi_ctrl_wstrb[0] && wd[b];
        if (ev) isr[b] <= 1'b1;
        else if (tog) isr[b] <= !isr[b];
      end
      // STATUS: a failed response sets its bit (and, when the bit was clear, records the
      // response); a written 1 clears the bit and what it recorded, unless a failed response
      // comes in the same clock.
      if (rd_fail) begin
        st_rd_err <= 1'b1;
        if (!st_rd_err) begin
          st_rd_resp <= m_axi_gmem_rresp;
          st_rd_id <= m_axi_gmem_rid;
        end
      end else if (aw_hs && wa == REG_STATUS && s_axi_ctrl_wstrb[0] && wd[STATUS_RD_ERR_LSB]) begin
        st_rd_err <= 1'b0;
        st_rd_resp <= '0;
        st_rd_id <= '0;
      end
      if (wr_fail) begin
        st_wr_err <= 1'b1;
        if (!st_wr_err) st_wr_resp <= m_axi_gmem_bresp;
      end else if (aw_hs && wa == REG_STATUS && s_axi_ctrl_wstrb[0] && wd[STATUS_WR_ERR_LSB]) begin
        st_wr_err <= 1'b0;
        st_wr_resp <= '0;
      end
    end
  end
  assign interrupt = gie && isr != 2'b00;

  // ---- Control ----
  always_ff @(posedge clk) begin
    if (rst) begin
      st <= 4'b0001;
      wait_cnt <= '0;
      cycles <= '0;
    end else begin
      if (!idle) cycles <= cycles + 64'd1;
      unique case (1'b1)
        st[S_IDLE]:
          if (ap_start && !finish) begin
            st <= 4'b0010;
            wait_cnt <= '0;
            cycles <= 64'd1;
          end
        st[S_SETUP]: begin
          wait_cnt <= wait_cnt + 3'd1;
          if (go) st <= 4'b0100;
        end
        st[S_RUN]:
          if (wr_done && &rd_done) begin
            st <= 4'b1000;
            wait_cnt <= '0;
          end
        st[S_DRAIN]: begin
          wait_cnt <= wait_cnt + 3'd1;
          if (finish) st <= 4'b0001;
        end
        default: ;
      endcase
    end
  end

  // ---- Readers and the AR arbiter ----
  logic [NR-1:0]   ar_req, ar_grant, r_hit;
  logic [63:0]     rq_addr[NR];
  logic [7:0]      rq_len[NR];
  logic [19:0]     rd_count[NR];
  logic [2:0]      rr;  // the reader served last
  assign rd_count[R_IMG]   = 20'(r_img_width) * 20'(r_img_height);
  assign rd_count[R_WIN]   = 20'(r_num_particles);
  assign rd_count[R_FT]    = 20'(r_num_particles) * 20'd12;
  assign rd_count[R_MODEL] = 20'd1024 + 20'(r_num_faces);
  assign rd_count[R_PROB]  = 20'd6300;
  assign rd_count[R_CELL]  = 20'(r_num_particles);

  // Round robin: the first requester after rr, when the AR register is free or being taken.
  logic       ar_free;
  logic [2:0] pick;
  logic       pick_ok;
  assign ar_free = !m_axi_gmem_arvalid || m_axi_gmem_arready;
  always_comb begin
    pick = '0;
    pick_ok = 1'b0;
    for (int k = 1; k <= NR; k++) begin
      automatic int i = (int'(rr) + k) % NR;
      if (!pick_ok && ar_req[i]) begin
        pick = 3'(i);
        pick_ok = 1'b1;
      end
    end
    ar_grant = '0;
    if (ar_free && pick_ok) ar_grant[pick] = 1'b1;
  end
  always_ff @(posedge clk) begin
    if (rst) begin
      m_axi_gmem_arvalid <= 1'b0;
      m_axi_gmem_araddr <= '0;
      m_axi_gmem_arlen <= '0;
      m_axi_gmem_arid <= '0;
      rr <= 3'(NR - 1);
    end else if (ar_free) begin
      m_axi_gmem_arvalid <= pick_ok;
      if (pick_ok) begin
        m_axi_gmem_araddr <= rq_addr[pick];
        m_axi_gmem_arlen <= rq_len[pick];
        m_axi_gmem_arid <= pick;
        rr <= pick;
      end
    end
  end
  assign m_axi_gmem_arsize  = 3'd4;     // 16 bytes per beat
  assign m_axi_gmem_arburst = 2'b01;    // INCR
  assign m_axi_gmem_arlock  = 1'b0;
  assign m_axi_gmem_arcache = 4'b0011;  // normal, bufferable (as Vitis m_axi)
  assign m_axi_gmem_arprot  = 3'b000;
  assign m_axi_gmem_arqos   = 4'd0;
  assign m_axi_gmem_rready  = 1'b1;     // every reader reserved room for its bursts
  for (genvar i = 0; i < NR; i++) begin : g_hit
    assign r_hit[i] = m_axi_gmem_rvalid && m_axi_gmem_rid == 3'(i);
  end

  // Pipeline streams.
  logic        img_valid, img_ready, win_valid, win_ready, ft_valid, ft_ready;
  logic        model_valid, model_ready, prob_valid, prob_ready, cell_valid, cell_ready;
  logic [15:0] img_word, cell_word;
  logic [47:0] win_word;
  logic [63:0] ft_word, model_word;
  logic [7:0]  prob_word;

  axi_burst_reader #(.EB(BUF_IMG_BYTES)) u_rd_img (
      .clk, .rst, .start(go), .base(r_addr[0]), .count(rd_count[R_IMG]), .done(rd_done[R_IMG]),
      .ar_req(ar_req[R_IMG]), .ar_addr(rq_addr[R_IMG]), .ar_len(rq_len[R_IMG]), .ar_grant(ar_grant[R_IMG]),
      .r_valid(r_hit[R_IMG]), .r_data(m_axi_gmem_rdata),
      .out_valid(img_valid), .out_ready(img_ready), .out_data(img_word));
  axi_burst_reader #(.EB(BUF_WIN_BYTES)) u_rd_win (
      .clk, .rst, .start(go), .base(r_addr[1]), .count(rd_count[R_WIN]), .done(rd_done[R_WIN]),
      .ar_req(ar_req[R_WIN]), .ar_addr(rq_addr[R_WIN]), .ar_len(rq_len[R_WIN]), .ar_grant(ar_grant[R_WIN]),
      .r_valid(r_hit[R_WIN]), .r_data(m_axi_gmem_rdata),
      .out_valid(win_valid), .out_ready(win_ready), .out_data(win_word));
  axi_burst_reader #(.EB(BUF_FT_BYTES)) u_rd_ft (
      .clk, .rst, .start(go), .base(r_addr[2]), .count(rd_count[R_FT]), .done(rd_done[R_FT]),
      .ar_req(ar_req[R_FT]), .ar_addr(rq_addr[R_FT]), .ar_len(rq_len[R_FT]), .ar_grant(ar_grant[R_FT]),
      .r_valid(r_hit[R_FT]), .r_data(m_axi_gmem_rdata),
      .out_valid(ft_valid), .out_ready(ft_ready), .out_data(ft_word));
  axi_burst_reader #(.EB(BUF_MODEL_BYTES)) u_rd_model (
      .clk, .rst, .start(go), .base(r_addr[3]), .count(rd_count[R_MODEL]), .done(rd_done[R_MODEL]),
      .ar_req(ar_req[R_MODEL]), .ar_addr(rq_addr[R_MODEL]), .ar_len(rq_len[R_MODEL]), .ar_grant(ar_grant[R_MODEL]),
      .r_valid(r_hit[R_MODEL]), .r_data(m_axi_gmem_rdata),
      .out_valid(model_valid), .out_ready(model_ready), .out_data(model_word));
  axi_burst_reader #(.EB(BUF_PROB_BYTES)) u_rd_prob (
      .clk, .rst, .start(go), .base(r_addr[4]), .count(rd_count[R_PROB]), .done(rd_done[R_PROB]),
      .ar_req(ar_req[R_PROB]), .ar_addr(rq_addr[R_PROB]), .ar_len(rq_len[R_PROB]), .ar_grant(ar_grant[R_PROB]),
      .r_valid(r_hit[R_PROB]), .r_data(m_axi_gmem_rdata),
      .out_valid(prob_valid), .out_ready(prob_ready), .out_data(prob_word));
  axi_burst_reader #(.EB(BUF_CELL_BYTES)) u_rd_cell (
      .clk, .rst, .start(go), .base(r_addr[5]), .count(rd_count[R_CELL]), .done(rd_done[R_CELL]),
      .ar_req(ar_req[R_CELL]), .ar_addr(rq_addr[R_CELL]), .ar_len(rq_len[R_CELL]), .ar_grant(ar_grant[R_CELL]),
      .r_valid(r_hit[R_CELL]), .r_data(m_axi_gmem_rdata),
      .out_valid(cell_valid), .out_ready(cell_ready), .out_data(cell_word));

  // ---- The pipeline ----
  logic         out_valid, out_ready;
  logic [17:0]  out_weight;
  logic [9:0]   out_index;
  logic [313:0] s;  // RasterCoreOutput (weight_merger.sv's layout)

  weigh_pipeline #(.M(M)) u_pipe (
      .clk, .rst, .num_particles(r_num_particles), .num_faces(r_num_faces), .img_width(r_img_width),
      .img_height(r_img_height), .prm_zbuffer(r_raster_flags[RASTER_FLAGS_ZBUFFER_LSB]),
      .prm_hard(r_raster_flags[RASTER_FLAGS_HARD_LSB]), .prm_thr1(r_thr1), .prm_inv_thr1(r_inv_thr1),
      .prm_hard_thr(r_hard_thr), .prm_align_band(r_align_band), .prm_edge_band(r_edge_band),
      .prm_near_plane(r_near_plane),
      .prm_alpha(r_weight_ab[WEIGHT_AB_ALPHA_LSB+:16]), .prm_beta(r_weight_ab[WEIGHT_AB_BETA_LSB+:16]),
      .prm_gamma(r_weight_gd[WEIGHT_GD_GAMMA_LSB+:16]), .prm_delta(r_weight_gd[WEIGHT_GD_DELTA_LSB+:16]),
      .prm_occlusion_aware(r_occl),
      .img_valid, .img_ready, .img_data(img_word[11:0]),
      .win_valid, .win_ready, .win_u0(win_word[9:0]), .win_v0(win_word[25:16]), .win_width(win_word[39:32]),
      .win_height(win_word[47:40]),
      .ft_valid, .ft_ready, .ft_data(ft_word[35:0]),
      .model_valid, .model_ready, .model_data(model_word[38:0]),
      .prob_valid, .prob_ready, .prob_data(prob_word),
      .cell_valid, .cell_ready, .cell_data(cell_word[12:0]),
      .out_valid, .out_ready, .out_weight, .out_index, .out_stats(s),
      .dd_reads_shared(dd_shared), .dd_reads_unshared(dd_unshared));

  // ---- The output record (64 bytes, little endian; docs/HARDWARE.md §16): RasterCoreOutput
  // as axi_pack.h lays it out (bytes 0–47), the weight (48–51), the index (52–53), zeros. ----
  logic [511:0] rec;
  always_comb begin
    rec = '0;
    rec[0+:64]    = 64'(s[313:272]);                 // inlier_sum (42 bits, unsigned)
    rec[64+:32]   = s[271:240];                      // n_raster
    rec[96+:32]   = s[239:208];                      // n_occluded
    rec[128+:32]  = s[207:176];                      // n_depth
    rec[192+:64]  = {{8{s[175]}}, s[175:120]};       // depth_diff_sum (56 bits, signed)
    rec[256+:32]  = s[119:88];                       // depth_diff_count
    rec[288+:32]  = s[87:56];                        // n_edge
    rec[320+:32]  = s[55:24];                        // n_edge_continued
    rec[352+:16]  = 16'(s[23:12]);                   // faces_front
    rec[368+:16]  = 16'(s[11:0]);                    // faces_total
    rec[384+:32]  = 32'(out_weight);                 // weight_t raw F17
    rec[416+:16]  = 16'(out_index);                  // particle index
  end

  axi_record_writer #(.ID(WRITER_ID)) u_wr (
      .clk, .rst, .start(go), .base(r_addr[6]), .count(r_num_particles), .done(wr_done), .bresp_err(wr_err),
      .rec_valid(out_valid), .rec_ready(out_ready), .rec_data(rec),
      .awvalid(m_axi_gmem_awvalid), .awready(m_axi_gmem_awready), .awaddr(m_axi_gmem_awaddr),
      .awlen(m_axi_gmem_awlen), .awid(m_axi_gmem_awid),
      .wvalid(m_axi_gmem_wvalid), .wready(m_axi_gmem_wready), .wdata(m_axi_gmem_wdata), .wlast(m_axi_gmem_wlast),
      .bvalid(m_axi_gmem_bvalid), .bresp(m_axi_gmem_bresp));
  assign m_axi_gmem_awsize  = 3'd4;
  assign m_axi_gmem_awburst = 2'b01;
  assign m_axi_gmem_awlock  = 1'b0;
  assign m_axi_gmem_awcache = 4'b0011;
  assign m_axi_gmem_awprot  = 3'b000;
  assign m_axi_gmem_awqos   = 4'd0;
  assign m_axi_gmem_wstrb   = '1;
  assign m_axi_gmem_bready  = 1'b1;

`ifndef SYNTHESIS
  // Simulation checks (Verilator --assert): the AXI handshakes this top drives, its states and
  // the host's use of the registers.
  logic hs_ar_wait, hs_lr_wait, hs_lb_wait;
  logic hs_wr_fail;  // a failed write response seen since this call's start (STATUS.WR_ERR's source)
  logic [74:0] hs_ar;
  logic [31:0] hs_lr;
  always_ff @(posedge clk) begin
    hs_ar_wait <= !rst && m_axi_gmem_arvalid && !m_axi_gmem_arready;
    hs_ar <= {m_axi_gmem_araddr, m_axi_gmem_arlen, m_axi_gmem_arid};
    hs_lr_wait <= !rst && s_axi_ctrl_rvalid && !s_axi_ctrl_rready;
    hs_lr <= s_axi_ctrl_rdata;
    hs_lb_wait <= !rst && s_axi_ctrl_bvalid && !s_axi_ctrl_bready;
    hs_wr_fail <= !rst && !go && (hs_wr_fail || wr_fail);
    if (!rst) begin
      if (hs_ar_wait)
        assert (m_axi_gmem_arvalid && {m_axi_gmem_araddr, m_axi_gmem_arlen, m_axi_gmem_arid} == hs_ar)
        else $error("weigh_accel: m_axi_gmem arvalid dropped or AR changed before arready");
      if (hs_lr_wait)
        assert (s_axi_ctrl_rvalid && s_axi_ctrl_rdata == hs_lr)
        else $error("weigh_accel: s_axi_ctrl rvalid dropped or rdata changed before rready");
      if (hs_lb_wait)
        assert (s_axi_ctrl_bvalid)
        else $error("weigh_accel: s_axi_ctrl bvalid dropped before bready");
      assert ($onehot(st))
      else $error("weigh_accel: state %b is not one-hot", st);
      assert ($onehot0(ar_grant))
      else $error("weigh_accel: AR grants %b not one-hot", ar_grant);
      assert (!(m_axi_gmem_rvalid && m_axi_gmem_rid >= 3'(NR)))
      else $error("weigh_accel: read data with RID %0d, no reader has it", m_axi_gmem_rid);
      assert (!(finish && wr_err != hs_wr_fail))
      else $error("weigh_accel: the writer's failed-response flag %0d disagrees with the B channel's %0d",
                  wr_err, hs_wr_fail);
      assert (!(aw_hs && !idle && wa >= REG_NUM_PARTICLES && wa <= REG_OUT_ADDR_HI))
      else $error("weigh_accel: register 0x%02h written while a call runs", wa);
      assert (!(go && (r_num_particles == 0 || r_num_particles > 10'd510)))
      else $error("weigh_accel: NUM_PARTICLES %0d outside 1 … 510", r_num_particles);
      assert (!(go && (r_num_faces == 0 || r_num_faces > 12'd2048)))
      else $error("weigh_accel: NUM_FACES %0d outside 1 … 2048", r_num_faces);
    end
  end
`endif
endmodule
