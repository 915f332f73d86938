// src/hw/postprocess.h — the stage-1 post-process of the hw engine (thesis §7.3, Fig. 7.3–7.4,
// eq. 7.1–7.2 [ALGORITHM.md]; docs/HARDWARE.md §7.1): raw pyramid values → per-cell class probabilities (prob_t),
// per-cell boxes (bbox_t, Table 7.1 [HARDWARE.md]) and the cells' render windows, plus the per-class probability
// sums the CDF module needs (§7.3: "the new sum of probabilities … is evaluated concurrently").
//
// Semantics mirror the float PostProcessPyramid / DecodeBox (src/prior/pyramid.cc):
//   Prob_j = e^{p_j} / (Σ_i e^{p_i} · (1 + e^c))                           (eq. 7.1–7.2 [ALGORITHM.md])
//   cx = a.cx + tx·a.w, cy = a.cy + ty·a.h, w = a.w·e^tw, h = a.h·e^th, w, h clipped to
//   [1, max_box_px], centre clamped into the image (prior.h "Box decoding").
//
// Fixed-point datapath (all ours where the thesis is silent):
//   * input raw_t = ap_fixed<18,6,AP_RND,AP_SAT>: LSB 2^-12, range [−32, 32); the driver
//     converts the float32 raw values (rounding, saturating). (The thesis's DPU gives 8-bit
//     values, <8,5>; 18 bits keep box decoding within 1 px and logits within 2^-13.)
//   * e^x from a 256-entry ROM over x ∈ [−16, 16) in steps of 1/8 (the thesis's 8-bit ROM
//     input, range e^-16 ≈ 1.12e-7 … e^16 ≈ 8.9e6), entries exp_t = ap_ufixed<48,24>
//     (LSB 2^-24). The ROM is generated at compile time by a constexpr function (MakeExpRom).
//     Ours: the residual r = x − round(8x)/8 (|r| ≤ 1/16) corrects the ROM value by
//     (1 + r + r²/2) (two small multiplies; relative error ≤ |r|³/6 ≈ 2^-14.6, 3.3e-4 in the
//     top 1/16 of the range where the last entry is used with r < 1/8); `exp_interpolate =
//     false` gives the thesis's plain ROM read of the rounded 8-bit argument.
//   * Softmax with the max logit subtracted first (Prob is invariant to it, eq. 7.2 [ALGORITHM.md] holds
//     exactly): every e^{p_j − m} ∈ (0, 1], so Σ ∈ [1, 21] and nothing under- or overflows
//     whatever the logits. The thesis feeds e^{p_j} directly, which needs ≈ 80-bit
//     accumulators to cover e^±16; ours costs one 21-input compare while reading.
//   * ONE reciprocal per cell (Fig. 7.4): of D = Σ_i e^{p_i − m}·(1 + e^c) ∈ [1, 2^28),
//     normalised to a mantissa in [0.5, 1) by a leading-one detector and inverted by
//     fx_math.h Reciprocal (≤ 2^-30); Prob_j = e^{p_j − m}·(1/D), rounded to nearest into
//     prob_t = ap_ufixed<8,0> (saturating at 255/256: a float probability above 1 − 2^-9
//     comes out as 255/256, and one below 2^-9 as 0 — e.g. a uniform prior's 1/6300).
//   * class_sum[j] = Σ_cells Prob_j in class_sum_t = ap_ufixed<21,13> (exact: 6300·255/256
//     < 2^13; thesis §7.4 "ufixed<13+8,8>" is this format, its notation's I and F swapped).
//
// Boxes (Table 7.1 [HARDWARE.md], §7.1): a cell's box is two bbox_t words, each an 18-bit pack of a
// 10-bit centre (pixels, rounded, 0 … 1023) and an 8-bit size (pixels, rounded, 1 … 255):
//   xw = cx << 8 | w,  yh = cy << 8 | h.
// (Table 7.1 [HARDWARE.md]'s third 18-bit word "h_indx + w_indx" is the window origin; ours is Window.)
// Windows (§7.5.3; docs/ALGORITHM.md §5): Window of distributor.h — the box centred, each side
// max(size, min_window_px) clipped to [1, min(max_window_px, image side)], then shifted to
// lie inside the image. min_window_px = 0 is the thesis (our float engine widens small
// boxes to the object's projected diameter — docs/ALGORITHM.md "minimum window size"; here
// one value for all cells, chosen by the driver).
//
// Pyramid geometry: the grids are the thesis's (15×20, 30×40, 60×80 = kNumCells, compile
// time); image size, strides and anchor sizes are runtime parameters (PostProcessParams).
#pragma once

#include <stdint.h>

#include "hw/distributor.h"
#include "hw/fx_math.h"
#include "hw/hw_types.h"
#include "hw/latency.h"

#ifndef __SYNTHESIS__
#include <cmath>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/prior.h"
#endif

namespace posefilter::hw {

// ---- Types (ours; the thesis's are in hw_types.h) ----
typedef ap_fixed<18, 6, AP_RND, AP_SAT> raw_t;   // raw pyramid value, LSB 2^-12, [−32, 32)
typedef ap_fixed<19, 7> exp_arg_t;               // exponent argument, LSB 2^-12, [−64, 64)
typedef ap_ufixed<48, 24> exp_t;                 // e^x, LSB 2^-24, < 2^24
typedef ap_ufixed<25, 1> exp_unit_t;             // e^{p − max} ∈ (0, 1], LSB 2^-24
typedef ap_ufixed<29, 5> exp_sum_t;              // Σ_j e^{p_j − max} ∈ [1, 21], exact
typedef ap_ufixed<21, 13> class_sum_t;           // Σ_cells prob_t, exact
typedef ap_ufixed<32, 2> recip_mant_t;           // 1/m for a mantissa m ∈ [0.5, 1)

// ---- Pyramid geometry (thesis §7.3, Fig. 7.2a) ----
constexpr int kNumLevels = 3;
#ifndef POSEFILTER_HW_PYRAMID_GRID  // same grid as diffusion.h (one definition per TU)
#define POSEFILTER_HW_PYRAMID_GRID
constexpr int kLevelRows[kNumLevels] = {15, 30, 60};
constexpr int kLevelCols[kNumLevels] = {20, 40, 80};
#endif
static_assert(15 * 20 + 30 * 40 + 60 * 80 == kNumCells, "pyramid grid must give kNumCells");

// ---- The exp ROM (§7.3): kExpRom.v[i] = round(e^{(i − 128)/8} · 2^24), i = 0 … 255 ----
constexpr int kExpRomSize = 256;
struct ExpRomTable {
  uint64_t v[kExpRomSize];
};
// e^x in long double at compile time: Taylor series of x/1024 (|·| ≤ 1/64, 16 terms, error
// far below 2^-64), squared 10 times (relative error grows ≤ 1024·eps ≈ 1e-16).
constexpr long double ConstexprExp(long double x) {
  const long double y = x / 1024.0L;
  long double term = 1.0L, sum = 1.0L;
  for (int k = 1; k <= 16; ++k) {
    term *= y / k;
    sum += term;
  }
  for (int k = 0; k < 10; ++k) sum *= sum;
  return sum;
}
constexpr ExpRomTable MakeExpRom() {
  ExpRomTable t{};
  for (int i = 0; i < kExpRomSize; ++i) {
    const long double e = ConstexprExp((i - 128) / 8.0L) * 16777216.0L;  // · 2^24
    t.v[i] = static_cast<uint64_t>(e + 0.5L);
  }
  return t;
}
inline constexpr ExpRomTable kExpRom = MakeExpRom();

// e^x for x clamped to [−16, 16 − 2^-12] (§7.3 ROM range): ROM entry at round(8x), corrected
// by (1 + r + r²/2), r = x − round(8x)/8, when `interpolate` (ours); the plain ROM read
// otherwise (thesis). Pipeline: clamp/round (1), ROM (1), r² and the poly (2), product (2):
// kExpDepth (latency.h).
inline exp_t ExpRom(exp_arg_t x, bool interpolate) {
#pragma HLS INLINE
  const exp_arg_t lo = -16;
  const exp_arg_t hi(15.999755859375);  // 16 − 2^-12
  exp_arg_t xc = x < lo ? lo : (x > hi ? hi : x);
  ap_fixed<9, 6, AP_RND> xq = xc;        // nearest multiple of 1/8 (ties up), [−16, 16]
  ap_fixed<16, 1> r = xc - xq;           // [−1/16, 1/16), exact
  int idx = (xq * 8).to_int();           // −128 … 128
  if (idx > 127) {                       // x ≥ 15.9375: use the last entry, r ∈ [1/16, 1/8)
    idx = 127;
    r = r + ap_fixed<16, 1>(0.125);
  }
  exp_t e;
  e.range(47, 0) = ap_uint<48>(kExpRom.v[idx + 128]);
  if (!interpolate) return e;
  ap_fixed<32, 2> r2 = r * r;
  ap_fixed<34, 3> poly_s = r2 >> 1;
  poly_s = poly_s + r;
  poly_s = poly_s + ap_fixed<34, 3>(1);
  ap_ufixed<27, 1> poly = poly_s;        // ∈ [0.93, 1.14], LSB 2^-26
  exp_t out = e * poly;                  // truncated to 2^-24
  return out;
}

// 1/x for x > 0 of any width, as a mantissa inverse and a power of two: x = m·2^s with
// m ∈ [0.5, 1) (leading-one detector), so 1/x = inv_m·2^-s, inv_m = 1/m ∈ (1, 2] from
// fx_math.h Reciprocal (≤ 1 ulp = 2^-30). Needed because Reciprocal's 32-bit output cannot hold
// 1/x over the dynamic ranges here (D ∈ [1, 2^28), Σ prob ∈ [2^-8, 6300]) at the precision
// eq. 7.3 [ALGORITHM.md] needs. x = 0 gives inv_m = max, s = 0 (callers avoid it). Latency: kWideRecipDepth
// (latency.h: Reciprocal + leading-one and normalising shift).
template <int W, int I>
inline void WideReciprocal(ap_ufixed<W, I> x, recip_mant_t* inv_m, int* s) {
#pragma HLS INLINE
  ap_uint<W> xr = RawOf(x);
  if (xr == 0) {
    inv_m->range(31, 0) = ~ap_uint<32>(0);
    *s = 0;
    return;
  }
  const int p = fx_detail::LeadingOne<W>(xr);  // x = xr·2^-(W−I), xr ∈ [2^p, 2^(p+1))
  ap_uint<32> mr;
  if (p + 1 >= 32) {
    mr = xr >> (p + 1 - 32);
  } else {
    mr = ap_uint<32>(xr) << (32 - p - 1);
  }
  ap_ufixed<32, 0> m;
  m.range(31, 0) = mr;                           // m = xr·2^-(p+1) ∈ [0.5, 1)
  *inv_m = Reciprocal<32, 2>(m);
  *s = p + 1 - (W - I);
}

// ---- Packed boxes and parameters ----
struct CellBox {
  bbox_t xw;  // centre x (bits 17…8, pixels) | width (bits 7…0, pixels)
  bbox_t yh;  // centre y | height
};
inline bbox_t PackBox(ap_uint<10> centre, ap_uint<8> size) {
#pragma HLS INLINE
  bbox_t b;
  b.range(17, 8) = centre;
  b.range(7, 0) = size;
  return b;
}
inline int BoxCentre(bbox_t b) { return ap_uint<10>(b.range(17, 8)).to_int(); }
inline int BoxSize(bbox_t b) { return ap_uint<8>(b.range(7, 0)).to_int(); }

// Runtime parameters of the post-process (ThesisPostProcessParams() gives the thesis's).
struct PostProcessParams {
  ap_uint<11> image_width, image_height;  // pixels, 1 … 1024 (10-bit centres)
  ap_ufixed<16, 8> stride_x[kNumLevels];  // image_width / cols, pixels (> 0)
  ap_ufixed<16, 8> stride_y[kNumLevels];  // image_height / rows, pixels (> 0)
  ap_ufixed<16, 9> anchor_w[kNumLevels];  // anchor size, pixels, (0, 512)
  ap_ufixed<16, 9> anchor_h[kNumLevels];
  ap_uint<8> max_box_px;                  // box size clip, pixels, 1 … 255 (thesis 200)
  ap_uint<8> max_window_px;               // window side clip, 1 … kMaxWindow (thesis 200)
  ap_uint<8> min_window_px;               // window side floor, pixels (0 = thesis)
  bool exp_interpolate;                   // ROM correction polynomial (ours; false = thesis)
};

// The thesis: 640×480, strides 32/16/8 px, anchors 4 strides (128/64/32 px), 200 px clips.
inline PostProcessParams ThesisPostProcessParams() {
  PostProcessParams p;
  p.image_width = kImageWidth;
  p.image_height = kImageHeight;
  for (int l = 0; l < kNumLevels; ++l) {
    p.stride_x[l] = kImageWidth / kLevelCols[l];
    p.stride_y[l] = kImageHeight / kLevelRows[l];
    p.anchor_w[l] = 4 * kImageWidth / kLevelCols[l];
    p.anchor_h[l] = 4 * kImageHeight / kLevelRows[l];
  }
  p.max_box_px = 200;
  p.max_window_px = kMaxWindow;
  p.min_window_px = 0;
  p.exp_interpolate = true;
  return p;
}

// The post-process kernel (Fig. 7.3). Reads kNumCells·(NC + 5) raw values in the raw pyramid
// layout (prior.h: per cell NC logits, tx, ty, tw, th, c), writes prob[cell][j], boxes[cell],
// windows[cell] and class_sum[j]. NC ≤ kNumClasses (21 in the thesis).
template <int NC>
void PostProcess(hls::stream<raw_t>& raw, const PostProcessParams& prm, prob_t prob[kNumCells][NC],
                 CellBox boxes[kNumCells], Window windows[kNumCells], class_sum_t class_sum[NC]
                     HW_TRACE_PARAM) {
  static_assert(NC >= 1 && NC <= kNumClasses, "PostProcess: 1 ≤ NC ≤ kNumClasses");
  constexpr int kPer = NC + 5;
  const bool interp = prm.exp_interpolate;
  const int img_w = prm.image_width.to_int(), img_h = prm.image_height.to_int();
  // Window side limits: min(max_window_px, image side), at least 1.
  int win_max_w = prm.max_window_px.to_int(), win_max_h = win_max_w;
  if (win_max_w > img_w) win_max_w = img_w;
  if (win_max_h > img_h) win_max_h = img_h;
  if (win_max_w < 1) win_max_w = 1;
  if (win_max_h < 1) win_max_h = 1;
  const int min_win = prm.min_window_px.to_int();
  const int max_box = prm.max_box_px.to_int() < 1 ? 1 : prm.max_box_px.to_int();

PP_CLEAR:
  for (int j = 0; j < NC; ++j) {
#pragma HLS PIPELINE II = 1
    class_sum[j] = 0;
  }
  HW_TRACE("postprocess", "PP_CLEAR", NC, 1, kPpClearDepth);

  uint64_t read_trips = 0, exp_trips = 0, scale_trips = 0, cell_trips = 0;
  int level = 0, row = 0, col = 0;
PP_CELLS:
  for (int cell = 0; cell < kNumCells; ++cell) {
#pragma HLS LOOP_TRIPCOUNT min = 6300 max = 6300
    raw_t v[kPer];
#pragma HLS ARRAY_PARTITION variable = v complete
    raw_t m = 0;
  PP_READ:  // the "splitter" (Fig. 7.3): read the cell's values, track the max logit
    for (int k = 0; k < kPer; ++k) {
#pragma HLS PIPELINE II = 1
      raw_t x = raw.read();
      v[k] = x;
      if (k == 0 || (k < NC && x > m)) m = x;
      ++read_trips;
    }
    exp_unit_t e[NC];
#pragma HLS ARRAY_PARTITION variable = e complete
    exp_sum_t sum = 0;
  PP_EXP:  // ROM exp and accumulator (Fig. 7.4)
    for (int j = 0; j < NC; ++j) {
#pragma HLS PIPELINE II = 1
      exp_arg_t d = v[j] - m;  // ≤ 0
      exp_unit_t ej = ExpRom(d, interp);
      e[j] = ej;
      sum = sum + ej;
      ++exp_trips;
    }
    // eq. 7.1 [ALGORITHM.md]: 1 + e^c; D = Σ·(1 + e^c) ∈ [1, 21·(1 + e^16)) < 2^28.
    exp_t ec = ExpRom(exp_arg_t(v[NC + 4]), interp);
    ap_ufixed<49, 25> onep = ec + ap_ufixed<1, 1>(1);
    ap_ufixed<56, 29> den = sum * onep;
    recip_mant_t inv_m;
    int s = 0;
    WideReciprocal(den, &inv_m, &s);  // 1/D = inv_m·2^-s, s ≥ 1
  PP_SCALE:  // one multiply per class instead of a division (Fig. 7.4)
    for (int j = 0; j < NC; ++j) {
#pragma HLS PIPELINE II = 1
      ap_ufixed<64, 4> t = e[j] * inv_m;  // < 2 · 2^-s·2^s … exact product, then the shift
      t = t >> s;
      ap_ufixed<8, 0, AP_RND, AP_SAT> q = t;
      prob_t pj = q;
      prob[cell][j] = pj;
      class_sum[j] = class_sum[j] + pj;
      ++scale_trips;
    }

    // ---- Box decoding (prior.h DecodeBox), beside the softmax ----
    // Anchor centre: (col + 0.5)·stride − 0.5 (centre of the pixels the cell covers).
    ap_ufixed<9, 8> colh = ap_ufixed<9, 8>(col) + ap_ufixed<1, 0>(0.5);
    ap_ufixed<9, 8> rowh = ap_ufixed<9, 8>(row) + ap_ufixed<1, 0>(0.5);
    ap_fixed<40, 17> acx = colh * prm.stride_x[level] - ap_ufixed<1, 0>(0.5);
    ap_fixed<40, 17> acy = rowh * prm.stride_y[level] - ap_ufixed<1, 0>(0.5);
    ap_fixed<40, 17> cx = acx + v[NC + 0] * prm.anchor_w[level];
    ap_fixed<40, 17> cy = acy + v[NC + 1] * prm.anchor_h[level];
    // Centre clamped into [0, W − 1] × [0, H − 1].
    const ap_fixed<40, 17> zero = 0;
    const ap_fixed<40, 17> cx_max = img_w - 1, cy_max = img_h - 1;
    if (cx < zero) cx = zero;
    if (cx > cx_max) cx = cx_max;
    if (cy < zero) cy = zero;
    if (cy > cy_max) cy = cy_max;
    // Size: anchor·e^t clipped to [1, max_box_px].
    ap_ufixed<64, 33> bw = prm.anchor_w[level] * ExpRom(exp_arg_t(v[NC + 2]), interp);  // exact
    ap_ufixed<64, 33> bh = prm.anchor_h[level] * ExpRom(exp_arg_t(v[NC + 3]), interp);
    const ap_ufixed<64, 33> one = 1, box_max = max_box;
    if (bw < one) bw = one;
    if (bw > box_max) bw = box_max;
    if (bh < one) bh = one;
    if (bh > box_max) bh = box_max;
    ap_ufixed<10, 10, AP_RND, AP_SAT> cxr = cx, cyr = cy;  // rounded centres (≤ 1023)
    ap_ufixed<8, 8, AP_RND, AP_SAT> bwr = bw, bhr = bh;     // rounded sizes (1 … 255)
    CellBox box;
    box.xw = PackBox(ap_uint<10>(cxr.to_int()), ap_uint<8>(bwr.to_int()));
    box.yh = PackBox(ap_uint<10>(cyr.to_int()), ap_uint<8>(bhr.to_int()));
    boxes[cell] = box;

    // ---- Window: side max(size, min_window) clipped, centred on the (unrounded) centre,
    // origin rounded (half up) and saturated into the image.
    int ww = bwr.to_int(), wh = bhr.to_int();
    if (ww < min_win) ww = min_win;
    if (wh < min_win) wh = min_win;
    if (ww > win_max_w) ww = win_max_w;
    if (wh > win_max_h) wh = win_max_h;
    ap_ufixed<9, 8> half_w = ap_ufixed<9, 8>(ww) >> 1;
    ap_ufixed<9, 8> half_h = ap_ufixed<9, 8>(wh) >> 1;
    ap_fixed<12, 12, AP_RND, AP_SAT> u0i = cx - half_w;  // one rounding, half up
    ap_fixed<12, 12, AP_RND, AP_SAT> v0i = cy - half_h;
    int u0 = u0i.to_int(), v0 = v0i.to_int();
    if (u0 < 0) u0 = 0;
    if (v0 < 0) v0 = 0;
    if (u0 > img_w - ww) u0 = img_w - ww;
    if (v0 > img_h - wh) v0 = img_h - wh;
    Window win;
    win.u0 = u0;
    win.v0 = v0;
    win.width = ww;
    win.height = wh;
    windows[cell] = win;

    // Next cell's (level, row, col).
    ++cell_trips;
    if (++col == kLevelCols[level]) {
      col = 0;
      if (++row == kLevelRows[level]) {
        row = 0;
        ++level;
      }
    }
  }
  // Pipeline depths (estimates for the cycle model): latency.h, "Post-process".
  HW_TRACE("postprocess", "PP_READ", read_trips, 1, kPpReadDepth);
  HW_TRACE("postprocess", "PP_EXP", exp_trips, 1, kPpExpDepth);
  HW_TRACE("postprocess", "PP_SCALE", scale_trips, 1, kPpScaleDepth);
  // The cell loop's own cost: per cell, the three inner pipelines' fill (their depths) and
  // the reciprocal/loop overhead — recorded as the outer loop's II (kPpCellII).
  HW_TRACE("postprocess", "PP_CELLS", cell_trips, kPpCellII, kPpCellsDepth);
}

#ifndef __SYNTHESIS__
// ---- Host side (driver and tests): parameters from a float layout, value conversion ----

// The kernel's parameters for a float PyramidLayout. Throws posefilter::Error (naming the
// violated constraint) unless the layout has the thesis's three grids (15×20, 30×40, 60×80),
// ≤ kNumClasses classes, an image of 1 … 1024 pixels per side, anchors in (0, 512) px;
// max_box_px in [1, 255], max_window_px in [1, kMaxWindow], min_window_px in [0, 255].
inline PostProcessParams PostProcessParamsFor(const PyramidLayout& layout, double max_box_px,
                                              int max_window_px = kMaxWindow,
                                              int min_window_px = 0, bool exp_interpolate = true) {
  std::string why;
  if (!layout.IsValid(&why)) throw Error("hw post-process: invalid pyramid layout: " + why);
  if (int(layout.levels.size()) != kNumLevels) {
    throw Error("hw post-process: the hw engine needs the thesis pyramid (3 levels), got " +
                std::to_string(layout.levels.size()) + " levels");
  }
  for (int l = 0; l < kNumLevels; ++l) {
    const PyramidLevel& lv = layout.levels[l];
    if (lv.rows != kLevelRows[l] || lv.cols != kLevelCols[l]) {
      throw Error("hw post-process: level " + std::to_string(l) + " is " + std::to_string(lv.rows) +
                  "×" + std::to_string(lv.cols) + ", the hw engine needs " +
                  std::to_string(kLevelRows[l]) + "×" + std::to_string(kLevelCols[l]));
    }
    if (!(lv.anchor_w < 512 && lv.anchor_h < 512)) {
      throw Error("hw post-process: level " + std::to_string(l) + " anchor must be < 512 px");
    }
  }
  if (layout.num_classes > kNumClasses) {
    throw Error("hw post-process: num_classes " + std::to_string(layout.num_classes) +
                " exceeds kNumClasses = " + std::to_string(kNumClasses));
  }
  if (layout.image_width > 1024 || layout.image_height > 1024) {
    throw Error("hw post-process: image " + std::to_string(layout.image_width) + "×" +
                std::to_string(layout.image_height) + " exceeds 1024 px per side (10-bit box centres)");
  }
  if (!(max_box_px >= 1 && max_box_px <= 255)) {
    throw Error("hw post-process: max_box_px must be in [1, 255] (8-bit box sizes)");
  }
  if (max_window_px < 1 || max_window_px > kMaxWindow) {
    throw Error("hw post-process: max_window_px must be in [1, kMaxWindow = 200]");
  }
  if (min_window_px < 0 || min_window_px > 255) {
    throw Error("hw post-process: min_window_px must be in [0, 255]");
  }
  PostProcessParams p;
  p.image_width = layout.image_width;
  p.image_height = layout.image_height;
  for (int l = 0; l < kNumLevels; ++l) {
    p.stride_x[l] = ap_ufixed<16, 8>(layout.StrideX(l));
    p.stride_y[l] = ap_ufixed<16, 8>(layout.StrideY(l));
    p.anchor_w[l] = ap_ufixed<16, 9>(layout.levels[l].anchor_w);
    p.anchor_h[l] = ap_ufixed<16, 9>(layout.levels[l].anchor_h);
  }
  p.max_box_px = int(std::lround(max_box_px));
  p.max_window_px = max_window_px;
  p.min_window_px = min_window_px;
  p.exp_interpolate = exp_interpolate;
  return p;
}

// float32 raw pyramid → the kernel's input stream (round to 2^-12, saturate at ±32). Throws
// Error on a wrong size or a non-finite value (naming the index).
inline void RawPyramidToStream(const std::vector<float>& raw, int num_classes, hls::stream<raw_t>& out) {
  const size_t expected = size_t(kNumCells) * size_t(num_classes + 5);
  if (raw.size() != expected) {
    throw Error("hw post-process: raw pyramid holds " + std::to_string(raw.size()) +
                " values, expected " + std::to_string(expected));
  }
  for (size_t i = 0; i < raw.size(); ++i) {
    if (!std::isfinite(raw[i])) {
      throw Error("hw post-process: raw pyramid value " + std::to_string(i) + " (cell " +
                  std::to_string(i / size_t(num_classes + 5)) + ") is not finite");
    }
    out.write(raw_t(double(raw[i])));
  }
}
#endif

}  // namespace posefilter::hw
