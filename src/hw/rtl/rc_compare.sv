// rc_compare.sv — CompareFragment of raster_core.h (§7.5.1 soft inlier, erratum fixed:
// continuous ramp χ = 2 − d/thr1 on thr1 < d < 2·thr1; GRIP's hard inlier; occlusion and
// depth-alignment counters), two register stages, II = 1.
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
  // Stage 1: difference, magnitude, ramp product.
  logic        s1_v;
  logic [25:0] s1_d;
  logic [24:0] s1_ad;
  logic [44:0] s1_prod;  // |d|·inv_thr1, F28
  logic signed [25:0] dd;
  logic [24:0] add;
  assign dd  = $signed({2'b00, zs}) - $signed({2'b00, zr});
  assign add = dd[25] ? 25'(-dd) : 25'(dd);
  always_ff @(posedge clk) begin
    s1_v    <= rst ? 1'b0 : (in_valid && zs != '0);
    s1_d    <= dd;
    s1_ad   <= add;
    s1_prod <= 45'(add) * 45'(inv_thr1);
  end

  // Stage 2: χ and flags.
  logic signed [47:0] ramp, rr;
  logic [10:0] chi_c;
  assign ramp = (48'sd2 <<< 28) - $signed({3'b000, s1_prod});
  assign rr   = (ramp + (48'sd1 <<< 17)) >>> 18;
  always_comb begin
    if (hard) chi_c = ({1'b0, hard_thr} >= s1_ad) ? 11'd1024 : 11'd0;
    else if (s1_ad <= {1'b0, thr1}) chi_c = 11'd1024;
    else if ({1'b0, s1_ad} >= {1'b0, thr1, 1'b0}) chi_c = 11'd0;
    else if (rr < 0) chi_c = 11'd0;
    else if (rr > 1024) chi_c = 11'd1024;
    else chi_c = rr[10:0];
  end
  always_ff @(posedge clk) begin
    out_valid <= rst ? 1'b0 : s1_v;
    chi       <= chi_c;
    occluded  <= (chi_c == 0) && s1_d[25];
    in_band   <= s1_ad <= {1'b0, align_band};
    d         <= s1_d;
  end
endmodule
