// rc_compare.sv — CompareFragment of raster_core.h (§7.5.1 soft inlier, erratum fixed:
// continuous ramp χ = 2 − d/thr1 on thr1 < d < 2·thr1; GRIP's hard inlier; occlusion and
// depth-alignment counters), three register stages, II = 1.
//
// Formats: z_r, z_s in F20 metres (ap_uint<24>); d = z_s − z_r ap_int<26> F20; |d| ap_uint<25>;
// thr1, hard_thr, align_band ufixed<24,4> raw F20; 1/thr1 ufixed<20,12> raw F8, so |d|·(1/thr1)
// is F28 and the ramp (2 − |d|/thr1) is F28, rounded to χ in F10 by (ramp + 2^17) >> 18 and
// clamped to [0, 1024]. z_s = 0 (missing depth) counts nothing (zs_nz = 0).
module rc_compare (
    input  logic        clk,
    input  logic        rst,
    input  logic        hard,        // 1: χ = [|d| ≤ hard_thr]
    input  logic [23:0] thr1,        // F20
    input  logic [19:0] inv_thr1,    // F8
    input  logic [23:0] hard_thr,    // F20
    input  logic [23:0] align_band,  // F20
    input  logic        in_valid,
    input  logic [23:0] zr,          // F20
    input  logic [23:0] zs,          // F20
    output logic        out_valid,   // a fragment with valid scene depth (z_s ≠ 0)
    output logic [10:0] chi,         // F10
    output logic        occluded,    // χ = 0 and z_s < z_r
    output logic        in_band,     // |d| ≤ align_band
    output logic [25:0] d            // z_s − z_r, F20
);
  // Stage 1: difference and magnitude (|d| from the two differences side by side).
  logic        s1_v;
  logic [25:0] s1_d;
  logic [24:0] s1_ad;
  logic signed [25:0] dd;
  logic [24:0] add;
  assign dd  = $signed({2'b00, zs}) - $signed({2'b00, zr});
  assign add = dd[25] ? 25'({1'b0, zr} - {1'b0, zs}) : 25'(dd);
  always_ff @(posedge clk) begin
    s1_v  <= rst ? 1'b0 : (in_valid && zs != '0);
    s1_d  <= dd;
    s1_ad <= add;
  end

  // Stage 2: the ramp product |d|·inv_thr1 (25 × 20 bits: two DSP48E2 and their sum, from
  // registered operands) and the threshold comparisons of |d|.
  logic        s2_v, s2_le_hard, s2_le_thr1, s2_ge_2thr1;
  logic [25:0] s2_d;
  logic [24:0] s2_ad;
  logic [44:0] s2_prod;  // |d|·inv_thr1, F28 (stage 2's register)
  always_ff @(posedge clk) begin
    s2_v        <= rst ? 1'b0 : s1_v;
    s2_d        <= s1_d;
    s2_ad       <= s1_ad;
    s2_prod     <= 45'(s1_ad) * 45'(inv_thr1);
    s2_le_hard  <= {1'b0, hard_thr} >= s1_ad;
    s2_le_thr1  <= s1_ad <= {1'b0, thr1};
    s2_ge_2thr1 <= {1'b0, s1_ad} >= {1'b0, thr1, 1'b0};
  end

  // Stage 3: χ and flags. The rounded ramp is rr = floor((2^29 − prod + 2^17) / 2^18)
  // = floor(c / 2^18) with c = K − prod, K = 2^29 + 2^17. Its two clamps are comparisons of prod
  // with constants, written on prod's bits (no carry chain):
  //   rr < 0     ⇔ prod > 2^29 + 2^17
  //   rr > 1024  ⇔ c ≥ 1025·2^18 ⇔ prod ≤ 2^28 − 2^17 (bits 17–27 ones)
  // and between them rr = c[28:18], so c is needed modulo 2^29 only (one 29-bit subtraction).
  // χ = 0, for the occluded flag, is formed beside χ rather than tested behind its multiplexers:
  // on the ramp, χ = 0 ⇔ rr < 1 ⇔ c < 2^18 ⇔ prod > 2^29 − 2^17 (bits 17–28 ones), which also
  // covers rr < 0, and rr > 1024 (prod ≤ 2^28 − 2^17) never meets it.
  logic [10:0] chi_c;
  logic [28:0] c29;
  logic        rr_neg, rr_big, rr_zero, chi_zero;
  assign c29    = 29'((30'd1 << 29) + (30'd1 << 17) - 30'(s2_prod[28:0]));
  assign rr_neg = s2_prod[44:30] != '0 ||
                  (s2_prod[29] && (s2_prod[28:18] != '0 || (s2_prod[17] && s2_prod[16:0] != '0)));
  assign rr_big = s2_prod[44:28] == '0 && !(s2_prod[27:17] == '1 && s2_prod[16:0] != '0);
  assign rr_zero = s2_prod[44:29] != '0 || (s2_prod[28:17] == '1 && s2_prod[16:0] != '0);
  assign chi_zero = hard ? !s2_le_hard : !s2_le_thr1 && (s2_ge_2thr1 || rr_zero);
  always_comb begin
    if (hard) chi_c = s2_le_hard ? 11'd1024 : 11'd0;
    else if (s2_le_thr1) chi_c = 11'd1024;
    else if (s2_ge_2thr1) chi_c = 11'd0;
    else if (rr_neg) chi_c = 11'd0;
    else if (rr_big) chi_c = 11'd1024;
    else chi_c = c29[28:18];
  end
  always_ff @(posedge clk) begin
    out_valid <= rst ? 1'b0 : s2_v;
    chi       <= chi_c;
    occluded  <= chi_zero && s2_d[25];
    in_band   <= s2_ad <= {1'b0, align_band};
    d         <= s2_d;
  end
endmodule
