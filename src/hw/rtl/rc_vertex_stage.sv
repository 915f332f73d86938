// rc_vertex_stage.sv — the vertex stage of a raster core (raster_core.sv, state FACES): the
// particle's FT matrix, then one vertex per clock, continuously across faces, through the
// transform, the near test, the 1/W divider and the two snapping dividers, and per face the face
// setup (2·Area, culling, clipped bounding box, edge setup) into one triangle FIFO entry
// (rc_pkg::tri_t). Stages V0–V4, VI and F0–F5: src/hw/rtl/README.md, "Microarchitecture"; number
// formats: the header of raster_core.sv.
//
// The stage never stalls: the core accepts a face's first vertex only when the triangle FIFO
// has room for it and for every face already in this pipeline (credits; `face_v` returns one),
// and the window and the near plane are stable while the core is in FACES.
module rc_vertex_stage (
    input  logic        clk,
    input  logic        rst,
    // FT matrix, row-major 3×4 (ft_t raw, F22): element ft_idx ← ft_data when ft_we.
    input  logic        ft_we,
    input  logic [3:0]  ft_idx,
    input  logic [35:0] ft_data,
    // The current window (absolute pixel coordinates of its corner, its size) and the near
    // plane (F20 m).
    input  logic [9:0]  u0,
    input  logic [9:0]  v0,
    input  logic [7:0]  ww,
    input  logic [7:0]  wh,
    input  logic [23:0] prm_near_plane,
    // The vertex accepted this clock (xyz_t raw, F10 m) and its corner 0–2 in its face.
    input  logic        vert_hs,
    input  logic [1:0]  vk,
    input  logic [12:0] vert_x,
    input  logic [12:0] vert_y,
    input  logic [12:0] vert_z,
    // face_v: a face leaves the stage (its credit returns); tri_push: that face is front-facing
    // with a non-empty box, and tri_entry is its FIFO entry.
    output logic        face_v,
    output logic        tri_push,
    output logic [rc_pkg::TRI_W-1:0] tri_entry,
    // A face passed the near/guard test and culling this clock (even with an empty box).
    output logic        face_front,
    // Some vertex or face is in the stage.
    output logic        busy
);
  localparam int GUARD = 1 << 21;  // kGuardBandSubpixels: |x|, |y| of a snapped vertex (F8)

  // FT registers, loaded in the core's FT state.
  logic [35:0] ft[12];
  always_ff @(posedge clk)
    if (ft_we) ft[ft_idx] <= ft_data;

  // V0: the accepted vertex.
  logic        v0_v;
  logic [1:0]  v0_k;
  logic signed [12:0] v0_p[3];
  always_ff @(posedge clk) begin
    v0_v <= rst ? 1'b0 : vert_hs;
    v0_k <= vk;
    v0_p[0] <= vert_x;
    v0_p[1] <= vert_y;
    v0_p[2] <= vert_z;
  end

  // V1: the nine products FT[r][j]·p[j] (36 × 13 → 49 bits, exact).
  logic        v1_v;
  logic [1:0]  v1_k;
  logic signed [48:0] v1_m[3][3];
  always_ff @(posedge clk) begin
    v1_v <= rst ? 1'b0 : v0_v;
    v1_k <= v0_k;
    for (int r = 0; r < 3; r++)
      for (int j = 0; j < 3; j++) v1_m[r][j] <= $signed(ft[4*r+j]) * v0_p[j];
  end

  // V2: U, V, W = (FT[r][3] << 10) + Σ products, ap_int<52> F32.
  logic        v2_v;
  logic [1:0]  v2_k;
  logic signed [51:0] v2_h[3];
  always_ff @(posedge clk) begin
    v2_v <= rst ? 1'b0 : v1_v;
    v2_k <= v1_k;
    for (int r = 0; r < 3; r++)
      v2_h[r] <= (52'($signed(ft[4*r+3])) <<< 10) + 52'(v1_m[r][0]) + 52'(v1_m[r][1]) + 52'(v1_m[r][2]);
  end

  // V3: divider operands. near: W < near·2^12 (F20 → F32) skips the face. 1/W: floor(2^58/W)
  // (F26). SnapRatio: floor((|U|·2^9 + W) / (2W)) = round-half-away(256·U/W) in magnitude.
  // The dividers see W as 51-bit unsigned: a vertex with W ≤ 0 fails the near test (near ≥ 0)
  // or, for W = 0, overflows, and the values of a failed vertex are never used; with W > 0,
  // W < 2^51 (ap_int<52>). For W > 0 the snap is computed as floor(n/W) with
  // n = floor((|U|·2^9 + W) / 2) = |U|·2^8 + floor(W/2) (nested floors), and only with
  // 21 quotient bits: the guard band (|x|, |y| < 2^21) rejects every larger quotient, which is
  // exactly the divider's overflow flag. |U|·2^8 + floor(W/2) is one subtraction, without a
  // separate negation: h − y − c with h = floor(W/2), y = U·2^8 and c = 0 when U < 0,
  // y = ~(U·2^8) and c = 1 when U ≥ 0 (−~a − 1 = a); the carry-in rides in an extra low bit.
  logic        v3_v, v3_near_ok, v3_negx, v3_negy;
  logic [1:0]  v3_k;
  logic [50:0] v3_w;
  logic [60:0] v3_nx, v3_ny;
  wire signed [51:0] near_w = 52'({prm_near_plane, 12'b0});
  function automatic logic [60:0] snap_num(input logic signed [51:0] u, input logic [49:0] h);
    logic [60:0] us, y;
    logic [61:0] t;
    us = 61'($signed(u)) << 8;
    y  = u[51] ? us : ~us;
    t  = {11'b0, h, 1'b0} - {y, !u[51]};
    snap_num = t[61:1];
  endfunction
  always_ff @(posedge clk) begin
    v3_v       <= rst ? 1'b0 : v2_v;
    v3_k       <= v2_k;
    v3_near_ok <= !(v2_h[2] < near_w);
    v3_negx    <= v2_h[0][51];
    v3_negy    <= v2_h[1][51];
    v3_w       <= v2_h[2][50:0];
    v3_nx      <= snap_num(v2_h[0], v2_h[2][50:1]);
    v3_ny      <= snap_num(v2_h[1], v2_h[2][50:1]);
  end

  // Dividers: 1/W (32 stages) and the two snapping dividers (21 stages + 9 padding). The
  // snapped x, y leave two clocks before 1/W: the face setup's x/y stages (F0–F3) run two clocks
  // ahead of the 1/W words, which join them in F4 (the FIFO entry).
  logic [31:0] q_iz;
  logic [20:0] q_x, q_y;
  logic        ov_iz, ov_x, ov_y;
  rc_div #(.QW(32), .NW(60), .DW(51), .PAD(0)) u_div_iz (
      .clk, .n(60'h1 << 58), .d(v3_w), .q(q_iz), .ovf(ov_iz));
  rc_div #(.QW(21), .NW(61), .DW(51), .PAD(9)) u_div_x (
      .clk, .n(v3_nx), .d(v3_w), .q(q_x), .ovf(ov_x));
  rc_div #(.QW(21), .NW(61), .DW(51), .PAD(9)) u_div_y (
      .clk, .n(v3_ny), .d(v3_w), .q(q_y), .ovf(ov_y));
  logic       vd_v, vd_near_ok, vd_negx, vd_negy, vd_any;
  logic [1:0] vd_k;
  rc_delay #(.W(5), .L(30)) u_vdel (
      .clk, .rst, .vin(v3_v), .din({v3_k, v3_near_ok, v3_negx, v3_negy}),
      .vout(vd_v), .dout({vd_k, vd_near_ok, vd_negx, vd_negy}), .vpre(), .dpre(), .any(vd_any));

  // V4: the snapped vertex (ScreenVertex) x, y F8 and its ok flag (near test, no snapping
  // overflow: |x|, |y| < GUARD), two clocks ahead of its 1/W.
  logic        v4_v, v4_ok;
  logic [1:0]  v4_k;
  logic signed [22:0] v4_x, v4_y;
  always_ff @(posedge clk) begin
    v4_v  <= rst ? 1'b0 : vd_v;
    v4_k  <= vd_k;
    v4_ok <= vd_near_ok && !ov_x && !ov_y;
    v4_x  <= vd_negx ? -$signed({1'b0, q_x}) : $signed({1'b0, q_x});
    v4_y  <= vd_negy ? -$signed({1'b0, q_y}) : $signed({1'b0, q_y});
  end
  // VI: the vertex's 1/W (F26) and its ok flag (no overflow), as the 1/W divider delivers them,
  // two clocks after V4 (vz: V4's valid and corner one clock later).
  logic        vz_v, vi_v, vi_ok;
  logic [1:0]  vz_k, vi_k;
  logic [31:0] vi_iz;
  always_ff @(posedge clk) begin
    vz_v  <= rst ? 1'b0 : v4_v;
    vz_k  <= v4_k;
    vi_v  <= rst ? 1'b0 : vz_v;
    vi_k  <= vz_k;
    vi_ok <= !ov_iz;
    vi_iz <= q_iz;
  end

  // Face assembly: corners 0 and 1 wait in registers for corner 2 (x, y from V4; 1/W from VI).
  logic signed [22:0] fa_x[2], fa_y[2];
  logic [31:0] fa_iz[2];
  logic        fa_ok[2], fa_izok[2];
  always_ff @(posedge clk) begin
    if (v4_v && v4_k != 2) begin
      fa_x[v4_k[0]]  <= v4_x;
      fa_y[v4_k[0]]  <= v4_y;
      fa_ok[v4_k[0]] <= v4_ok;
    end
    if (vi_v && vi_k != 2) begin
      fa_iz[vi_k[0]]   <= vi_iz;
      fa_izok[vi_k[0]] <= vi_ok;
    end
  end

  // F0: the edge differences and the corners' order for the box.
  // Edge k runs from Va = V[k+1] to Vb = V[k+2]: A_k = Vb.y − Va.y, B_k = Va.x − Vb.x
  // (ap_int<24>). The area's differences are edges: V2x − V0x = B_1, V1y − V0y = A_2,
  // V2y − V0y = −A_1, V1x − V0x = −B_2, so 2·Area = B_1·A_2 − A_1·B_2. The signs of the same
  // differences order the corners for the box (their sign bits, no comparators):
  // x0 < x1 ⇔ B_2 < 0, x1 < x2 ⇔ B_0 < 0, x2 < x0 ⇔ B_1 < 0;
  // y0 > y1 ⇔ A_2 < 0, y1 > y2 ⇔ A_0 < 0, y2 > y0 ⇔ A_1 < 0.
  logic        f0_v, f0_ok;
  logic signed [22:0] f0_x[3], f0_y[3];
  logic signed [23:0] f0_a[3], f0_b[3];
  logic signed [22:0] f0_minx, f0_maxx, f0_miny, f0_maxy;
  logic signed [22:0] cx[3], cy[3];
  assign cx[0] = fa_x[0];
  assign cx[1] = fa_x[1];
  assign cx[2] = v4_x;
  assign cy[0] = fa_y[0];
  assign cy[1] = fa_y[1];
  assign cy[2] = v4_y;
  logic signed [23:0] ea[3], eb[3];
  for (genvar k = 0; k < 3; k++) begin : g_ab
    assign ea[k] = 24'(cy[(k + 2) % 3]) - 24'(cy[(k + 1) % 3]);
    assign eb[k] = 24'(cx[(k + 1) % 3]) - 24'(cx[(k + 2) % 3]);
  end
  // The first and the last of three values in a strict order given by the pairwise flags
  // p01 = (a before b), p12 = (b before c), p20 = (c before a); ties pick an equal value.
  // With "<" flags: first = min, last = max; with ">" flags: first = max, last = min.
  function automatic logic signed [22:0] first3(input logic signed [22:0] a, b, c,
                                                input logic p01, p12, p20);
    first3 = p01 ? (p20 ? c : a) : (p12 ? b : c);
  endfunction
  function automatic logic signed [22:0] last3(input logic signed [22:0] a, b, c,
                                               input logic p01, p12, p20);
    last3 = p01 ? (p12 ? c : b) : (p20 ? a : c);
  endfunction
  wire xlt01 = eb[2][23], xlt12 = eb[0][23], xlt20 = eb[1][23];
  wire ygt01 = ea[2][23], ygt12 = ea[0][23], ygt20 = ea[1][23];
  always_ff @(posedge clk) begin
    f0_v  <= rst ? 1'b0 : (v4_v && v4_k == 2);
    f0_ok <= fa_ok[0] && fa_ok[1] && v4_ok;
    for (int k = 0; k < 3; k++) begin
      f0_x[k] <= cx[k];
      f0_y[k] <= cy[k];
      f0_a[k] <= ea[k];
      f0_b[k] <= eb[k];
    end
    f0_minx <= first3(cx[0], cx[1], cx[2], xlt01, xlt12, xlt20);
    f0_maxx <= last3(cx[0], cx[1], cx[2], xlt01, xlt12, xlt20);
    f0_maxy <= first3(cy[0], cy[1], cy[2], ygt01, ygt12, ygt20);
    f0_miny <= last3(cy[0], cy[1], cy[2], ygt01, ygt12, ygt20);
  end

  // F1: 2·Area products (eq. 6.12 [ALGORITHM.md]: (V2x−V0x)(V1y−V0y) − (V2y−V0y)(V1x−V0x)),
  // 24 × 24 bits from registered operands.
  logic        f1_v, f1_ok;
  logic signed [22:0] f1_x[3], f1_y[3];
  logic signed [47:0] f1_p1, f1_p2;
  logic signed [22:0] f1_minx, f1_maxx, f1_miny, f1_maxy;
  logic signed [23:0] f1_a[3], f1_b[3];
  always_ff @(posedge clk) begin
    f1_v  <= rst ? 1'b0 : f0_v;
    f1_ok <= f0_ok;
    for (int k = 0; k < 3; k++) begin
      f1_x[k] <= f0_x[k];
      f1_y[k] <= f0_y[k];
      f1_a[k] <= f0_a[k];
      f1_b[k] <= f0_b[k];
    end
    f1_p1 <= 48'(f0_b[1]) * 48'(f0_a[2]);  // (V2x − V0x)(V1y − V0y)
    f1_p2 <= 48'(f0_a[1]) * 48'(f0_b[2]);  // (V2y − V0y)(V1x − V0x) = (−A_1)(−B_2)
    f1_minx <= f0_minx;
    f1_maxx <= f0_maxx;
    f1_miny <= f0_miny;
    f1_maxy <= f0_maxy;
  end

  // F2: 2·Area, culling (2·Area ≤ 0, §6.2), box in pixels (ceil of min, floor of max) clipped
  // to the window (absolute pixel coordinates, signed 16 bits). The face's three 1/W (F26) and
  // their ok flag join here from VI and travel beside the x/y stages to the FIFO entry.
  logic        f2_v, f2_ok, f2_izok, f2_nonempty;
  logic signed [22:0] f2_x[3], f2_y[3];
  logic signed [23:0] f2_a[3], f2_b[3];
  logic [31:0] f2_iz[3];
  logic signed [49:0] f2_area2;
  logic signed [15:0] f2_ulo, f2_uhi, f2_vlo, f2_vhi;
  logic signed [15:0] ulo_c, uhi_c, vlo_c, vhi_c;
  logic signed [49:0] area2_c;
  wire signed [23:0] nminx = -(24'(f1_minx)), nminy = -(24'(f1_miny));
  always_comb begin
    ulo_c = -(16'(nminx >>> 8));
    vlo_c = -(16'(nminy >>> 8));
    uhi_c = 16'(f1_maxx >>> 8);
    vhi_c = 16'(f1_maxy >>> 8);
    if (ulo_c < $signed({6'b0, u0})) ulo_c = $signed({6'b0, u0});
    if (vlo_c < $signed({6'b0, v0})) vlo_c = $signed({6'b0, v0});
    if (uhi_c > $signed({6'b0, u0}) + $signed({8'b0, ww}) - 16'sd1) uhi_c = $signed({6'b0, u0}) + $signed({8'b0, ww}) - 16'sd1;
    if (vhi_c > $signed({6'b0, v0}) + $signed({8'b0, wh}) - 16'sd1) vhi_c = $signed({6'b0, v0}) + $signed({8'b0, wh}) - 16'sd1;
    area2_c = 50'(f1_p1) - 50'(f1_p2);
  end
  always_ff @(posedge clk) begin
    f2_v        <= rst ? 1'b0 : f1_v;
    f2_ok       <= f1_ok;
    f2_izok     <= fa_izok[0] && fa_izok[1] && vi_ok;
    f2_nonempty <= ulo_c <= uhi_c && vlo_c <= vhi_c;
    for (int k = 0; k < 3; k++) f2_x[k] <= f1_x[k];
    for (int k = 0; k < 3; k++) f2_y[k] <= f1_y[k];
    for (int k = 0; k < 3; k++) f2_a[k] <= f1_a[k];
    for (int k = 0; k < 3; k++) f2_b[k] <= f1_b[k];
    f2_iz[0] <= fa_iz[0];
    f2_iz[1] <= fa_iz[1];
    f2_iz[2] <= vi_iz;
    f2_area2 <= area2_c;
    f2_ulo <= ulo_c;
    f2_uhi <= uhi_c;
    f2_vlo <= vlo_c;
    f2_vhi <= vhi_c;
  end
  // Front-facing (not culled): ok (x, y and 1/W) and 2·Area > 0, from the registered 2·Area's
  // sign and a zero test (no comparator behind the subtraction).
  wire f2_front = f2_ok && f2_izok && !f2_area2[49] && f2_area2 != '0;

  // F3–F5: edge setup (eq. 6.13–6.18 [ALGORITHM.md]). Edge k opposite corner k, from Va = V[k+1]
  // to Vb = V[k+2]: A = Vb.y − Va.y, B = Va.x − Vb.x (formed in F0); E_k at the first pixel
  // A·(u_lo·256 − Va.x) + B·(v_lo·256 − Va.y) (operands ap_int<24>): F3 the offsets, F4 the
  // products, F5 their sum; owned edge: A > 0 or A = 0 and B > 0 (min_e = 0, else 1);
  // sh = max(BitLength(2·Area) − 24, 0).
  logic        f3_v, f3_push;
  logic signed [23:0] f3_a[3], f3_b[3], f3_dx[3], f3_dy[3];
  logic [2:0]  f3_mine;
  logic [4:0]  f3_sh;
  logic [31:0] f3_iz[3];
  logic [7:0]  f3_xlo, f3_xhi, f3_ylo, f3_yhi;
  logic [15:0] f3_addr0;
  // sh = max(BitLength(2·Area) − 24, 0): for the highest set bit i ≥ 24 of 2·Area (bits 0–48),
  // sh = i − 23. A flat one-hot AND-OR (no priority chain): bit i is the highest when no bit
  // above it is set.
  logic [4:0]  sh_c;
  always_comb begin
    sh_c = '0;
    for (int i = 24; i < 49; i++)
      if (f2_area2[i] && (f2_area2[48:0] >> (i + 1)) == '0) sh_c = sh_c | 5'(i - 23);
  end
  for (genvar k = 0; k < 3; k++) begin : g_edge
    localparam int A_ = (k + 1) % 3;
    wire signed [23:0] ak = f2_a[k];
    wire signed [23:0] bk = f2_b[k];
    always_ff @(posedge clk) begin
      f3_a[k]  <= ak;
      f3_b[k]  <= bk;
      f3_dx[k] <= 24'({f2_ulo, 8'b0}) - 24'(f2_x[A_]);
      f3_dy[k] <= 24'({f2_vlo, 8'b0}) - 24'(f2_y[A_]);
      // A > 0 or (A = 0 and B > 0), from signs and zero tests.
      f3_mine[k] <= !((!ak[23] && ak != '0) || (ak == '0 && !bk[23] && bk != '0));
    end
  end
  always_ff @(posedge clk) begin
    f3_v    <= rst ? 1'b0 : f2_v;
    f3_push <= f2_front && f2_nonempty;  // front-facing, non-empty box
    f3_sh  <= sh_c;
    for (int k = 0; k < 3; k++) f3_iz[k] <= f2_iz[k];
    f3_xlo <= 8'(f2_ulo - $signed({6'b0, u0}));
    f3_xhi <= 8'(f2_uhi - $signed({6'b0, u0}));
    f3_ylo <= 8'(f2_vlo - $signed({6'b0, v0}));
    f3_yhi <= 8'(f2_vhi - $signed({6'b0, v0}));
    f3_addr0 <= 16'(f2_vlo - $signed({6'b0, v0})) * 16'(rc_pkg::KW) + 16'(f2_ulo - $signed({6'b0, u0}));
  end

  // F4: the products A·dx and B·dy (24 × 24 bits from registered operands).
  logic        f4_v, f4_push;
  logic signed [47:0] f4_pa[3], f4_pb[3];
  logic signed [23:0] f4_a[3], f4_b[3];
  logic [2:0]  f4_mine;
  logic [4:0]  f4_sh;
  logic [31:0] f4_iz[3];
  logic [7:0]  f4_xlo, f4_xhi, f4_ylo, f4_yhi;
  logic [15:0] f4_addr0;
  always_ff @(posedge clk) begin
    f4_v    <= rst ? 1'b0 : f3_v;
    f4_push <= f3_push;
    for (int k = 0; k < 3; k++) begin
      f4_pa[k] <= f3_a[k] * f3_dx[k];
      f4_pb[k] <= f3_b[k] * f3_dy[k];
      f4_a[k]  <= f3_a[k];
      f4_b[k]  <= f3_b[k];
      f4_iz[k] <= f3_iz[k];
    end
    f4_mine  <= f3_mine;
    f4_sh    <= f3_sh;
    f4_xlo   <= f3_xlo;
    f4_xhi   <= f3_xhi;
    f4_ylo   <= f3_ylo;
    f4_yhi   <= f3_yhi;
    f4_addr0 <= f3_addr0;
  end

  // F5: E_k at the first pixel (ap_int<50>), the FIFO entry.
  logic f5_v, f5_push;
  rc_pkg::tri_t f5_t;
  always_ff @(posedge clk) begin
    f5_v    <= rst ? 1'b0 : f4_v;
    f5_push <= f4_push;
    f5_t.xlo <= f4_xlo;
    f5_t.xhi <= f4_xhi;
    f5_t.ylo <= f4_ylo;
    f5_t.yhi <= f4_yhi;
    f5_t.addr0 <= f4_addr0;
    for (int k = 0; k < 3; k++) begin
      f5_t.e[k]  <= 50'(f4_pa[k]) + 50'(f4_pb[k]);
      f5_t.a[k]  <= f4_a[k];
      f5_t.b[k]  <= f4_b[k];
      f5_t.iz[k] <= f4_iz[k];
    end
    f5_t.mine <= f4_mine;
    f5_t.sh   <= f4_sh;
  end
  assign face_v    = f5_v;
  assign tri_push  = f5_v && f5_push;
  assign tri_entry = f5_t;
  // faces_front: faces that passed the near/guard test and culling (even with an empty box).
  assign face_front = f2_v && f2_front;
  assign busy = v0_v || v1_v || v2_v || v3_v || vd_any || v4_v || vz_v || vi_v || f0_v || f1_v ||
                f2_v || f3_v || f4_v || f5_v;
endmodule
