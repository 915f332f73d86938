// src/hw/fx_math.h — our own fixed-point math for the hw kernels: sin/cos, square root,
// natural log, reciprocal and division. No vendor math library (hls_math is proprietary, see
// shared/hls/SEMANTICS.md), no float or double anywhere: every function works on the raw
// two's-complement words of ap_[u]fixed (read/written through .range()) with ap_[u]int
// integer datapaths, ROM tables and shift-and-add.
//
// Accuracy (measured by tests/hw/hwrandom_fx_math_test.cc against std:: in double; 1 ulp =
// the output format's LSB):
//   SinCos(angle_t)            ≤ 1 ulp of ap_fixed<18,2> (2^-16), exhaustive over angle_t
//   SinCosTurns<W>             ≤ 1 ulp of ap_fixed<18,2>
//   CosFromSin (eq. 5.3 [HARDWARE.md])       ≤ 1 ulp of the rounded sqrt of 1 − s², where s carries its own
//                              ±0.5 ulp — so up to ~2^-8 absolute near |s| → 1 (ill-conditioned)
//   Sqrt<W,I>                  ≤ 0.5 ulp (exact round-to-nearest of the true root)
//   Log(ap_ufixed<18,0>)       ≤ 0.52 ulp of ap_fixed<18,5> (2^-13), exhaustive over 2^18−1
//   Reciprocal<OW,OI>(x)       ≤ 0.5 ulp (ROM seed + 3 Newton–Raphson steps + one correction)
//   Divide<OW,OI>(n, d)        ≤ 0.5 ulp (restoring division, round to nearest)
// Out-of-range results saturate (Sqrt/Reciprocal/Divide to the format's maximum; Log(0) to the
// most negative value −16; Reciprocal(0) and Divide(n, 0) to the maximum).
//
// These are inline building blocks called inside the pipelined loops of the kernels (they are
// not kernels: no loops that iterate over data, no HW_TRACE). Their latency in a pipeline is
// given by the k*Depth constants of hw/latency.h (kSinCosDepth, kLogDepth, SqrtDepth(N),
// kReciprocalDepth, DivideDepth(N), …); a kernel adds them to its loop's depth estimate.
// ROM contents were generated once by a script (round(f(k)·2^20), listed in docs/HARDWARE.md)
// and are literal constants here.
#pragma once

#include "hw/hw_types.h"
#include "hw/latency.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

// ---- Raw-word access ----
template <int W, int I>
inline ap_uint<W> RawOf(const ap_ufixed<W, I>& x) {
#pragma HLS INLINE
  ap_uint<W> r = x.range(W - 1, 0);
  return r;
}
template <int W, int I>
inline ap_int<W> RawOf(const ap_fixed<W, I>& x) {
#pragma HLS INLINE
  ap_uint<W> u = x.range(W - 1, 0);
  ap_int<W> r = u;  // same W bits, read as two's complement
  return r;
}
template <int W, int I>
inline ap_ufixed<W, I> UFixedFromRaw(const ap_uint<W>& r) {
#pragma HLS INLINE
  ap_ufixed<W, I> x;
  x.range(W - 1, 0) = r;
  return x;
}
template <int W, int I>
inline ap_fixed<W, I> FixedFromRaw(const ap_int<W>& r) {
#pragma HLS INLINE
  ap_fixed<W, I> x;
  ap_uint<W> u = r;
  x.range(W - 1, 0) = u;
  return x;
}

namespace fx_detail {

// sin(k·π/512)·2^20, k = 0 … 256 (quarter wave, 257 points), last entry repeated so the
// interpolation's k+1 read at k = 256 stays in the ROM.
inline constexpr int kSinRom[258] = {
    0, 6434, 12868, 19301, 25733, 32165, 38595, 45024, 51451, 57876,
    64299, 70720, 77138, 83553, 89965, 96374, 102778, 109179, 115576, 121969,
    128357, 134740, 141118, 147491, 153858, 160219, 166575, 172924, 179267, 185602,
    191931, 198253, 204567, 210873, 217172, 223462, 229744, 236018, 242282, 248537,
    254783, 261020, 267246, 273462, 279669, 285864, 292049, 298223, 304386, 310537,
    316676, 322804, 328919, 335022, 341113, 347190, 353255, 359306, 365343, 371367,
    377377, 383373, 389354, 395321, 401273, 407209, 413131, 419036, 424926, 430800,
    436658, 442499, 448324, 454132, 459922, 465696, 471452, 477190, 482910, 488612,
    494295, 499960, 505606, 511233, 516841, 522430, 527998, 533547, 539076, 544584,
    550072, 555539, 560986, 566411, 571815, 577197, 582558, 587896, 593213, 598507,
    603779, 609028, 614254, 619456, 624636, 629792, 634924, 640033, 645117, 650177,
    655213, 660224, 665210, 670171, 675106, 680017, 684901, 689760, 694593, 699400,
    704181, 708935, 713662, 718362, 723036, 727682, 732301, 736892, 741455, 745991,
    750498, 754977, 759428, 763850, 768244, 772608, 776944, 781250, 785526, 789774,
    793991, 798179, 802336, 806463, 810560, 814627, 818662, 822667, 826641, 830584,
    834495, 838376, 842224, 846041, 849826, 853579, 857300, 860988, 864645, 868268,
    871859, 875417, 878942, 882434, 885893, 889319, 892711, 896069, 899394, 902684,
    905941, 909164, 912352, 915506, 918626, 921711, 924761, 927777, 930758, 933703,
    936614, 939489, 942328, 945133, 947901, 950634, 953332, 955993, 958618, 961208,
    963761, 966278, 968758, 971202, 973609, 975980, 978314, 980611, 982871, 985094,
    987281, 989429, 991541, 993616, 995652, 997652, 999614, 1001538, 1003425, 1005273,
    1007084, 1008857, 1010592, 1012289, 1013948, 1015569, 1017151, 1018696, 1020201, 1021669,
    1023098, 1024488, 1025840, 1027153, 1028428, 1029664, 1030861, 1032019, 1033138, 1034219,
    1035261, 1036263, 1037227, 1038151, 1039037, 1039883, 1040690, 1041458, 1042187, 1042877,
    1043527, 1044138, 1044709, 1045242, 1045735, 1046188, 1046603, 1046978, 1047313, 1047609,
    1047865, 1048083, 1048260, 1048398, 1048497, 1048556, 1048576, 1048576,
};
// ln(1 + j/256)·2^20, j = 0 … 256, last entry repeated.
inline constexpr int kLogRom[258] = {
    0, 4088, 8160, 12217, 16257, 20283, 24292, 28287, 32266, 36231,
    40180, 44115, 48035, 51940, 55831, 59707, 63570, 67418, 71251, 75071,
    78877, 82670, 86448, 90214, 93965, 97703, 101428, 105140, 108839, 112525,
    116197, 119857, 123504, 127139, 130761, 134371, 137968, 141553, 145125, 148686,
    152234, 155771, 159296, 162808, 166309, 169799, 173277, 176743, 180198, 183642,
    187074, 190495, 193905, 197304, 200692, 204069, 207435, 210791, 214136, 217470,
    220793, 224106, 227409, 230701, 233983, 237255, 240516, 243768, 247009, 250240,
    253462, 256673, 259875, 263067, 266249, 269422, 272585, 275739, 278883, 282018,
    285143, 288259, 291366, 294464, 297552, 300632, 303703, 306764, 309817, 312860,
    315895, 318922, 321939, 324948, 327948, 330940, 333923, 336898, 339864, 342822,
    345771, 348713, 351646, 354571, 357487, 360396, 363297, 366189, 369074, 371951,
    374820, 377681, 380534, 383380, 386217, 389048, 391870, 394685, 397492, 400292,
    403085, 405870, 408648, 411418, 414181, 416937, 419685, 422427, 425161, 427888,
    430608, 433321, 436027, 438726, 441418, 444104, 446782, 449453, 452118, 454776,
    457427, 460072, 462710, 465341, 467966, 470584, 473196, 475801, 478400, 480992,
    483578, 486157, 488731, 491297, 493858, 496412, 498961, 501503, 504038, 506568,
    509092, 511609, 514121, 516627, 519126, 521620, 524108, 526589, 529065, 531535,
    534000, 536458, 538911, 541358, 543800, 546235, 548665, 551090, 553509, 555922,
    558330, 560732, 563129, 565520, 567906, 570286, 572661, 575031, 577395, 579754,
    582108, 584456, 586800, 589138, 591470, 593798, 596120, 598438, 600750, 603057,
    605359, 607656, 609948, 612235, 614517, 616794, 619066, 621333, 623596, 625853,
    628106, 630353, 632596, 634834, 637068, 639296, 641520, 643740, 645954, 648164,
    650369, 652570, 654766, 656957, 659144, 661326, 663504, 665677, 667846, 670010,
    672170, 674325, 676476, 678623, 680765, 682903, 685036, 687165, 689290, 691410,
    693527, 695639, 697746, 699850, 701949, 704044, 706135, 708222, 710304, 712383,
    714457, 716527, 718593, 720655, 722713, 724767, 726817, 726817,
};
// Reciprocal seed: 2^17 / (1 + (j + 0.5)/64), j = 0 … 63 (1/m at the centre of each of the 64
// mantissa intervals of m ∈ [1, 2); relative error ≤ 2^-7.5).
inline constexpr int kRecipRom[64] = {
    130056, 128070, 126144, 124276, 122461, 120699, 118987, 117323,
    115705, 114131, 112599, 111107, 109655, 108240, 106861, 105517,
    104206, 102928, 101680, 100462, 99273, 98112, 96978, 95870,
    94787, 93727, 92692, 91679, 90688, 89718, 88768, 87839,
    86929, 86037, 85164, 84308, 83469, 82646, 81840, 81049,
    80274, 79513, 78766, 78034, 77314, 76608, 75915, 75234,
    74565, 73908, 73263, 72629, 72005, 71392, 70790, 70198,
    69615, 69042, 68478, 67924, 67378, 66841, 66313, 65793,
};
constexpr int kLn2Q24 = 11629080;        // round(ln 2 · 2^24)
constexpr int kTurnsPerRadQ24 = 2670177; // round(2^24 / (2π) · 2^8): radian·2^-8 → turn·2^-24, ×2^8

// sin of p/2^22 quarter turns (p ∈ [0, 2^22]), result ·2^20 (0 … 2^20): 256-interval ROM with
// linear interpolation; interpolation error ≤ (π/512)²/8 = 4.7e-6 (0.31 ulp of 2^-16).
inline ap_uint<21> QuarterSinQ20(ap_uint<23> p) {
#pragma HLS INLINE
  ap_uint<9> k = p >> 14;
  ap_uint<14> f = p.range(13, 0);
  ap_int<22> a = kSinRom[k.to_int()];
  ap_int<22> b = kSinRom[k.to_int() + 1];
  ap_int<22> diff = b - a;  // 0 … 6434
  ap_int<38> prod = ap_int<38>(diff) * ap_int<38>(f);
  ap_int<24> interp = (prod + ap_int<38>(8192)) >> 14;
  ap_uint<21> v = a + interp;
  return v;
}

// Rounds a ·2^20 value to ·2^-16 raw (round half up).
inline ap_int<18> Q20ToQ16(ap_int<23> v) {
#pragma HLS INLINE
  ap_int<23> r = (v + ap_int<23>(8)) >> 4;
  ap_int<18> out = r;
  return out;
}

// Leading-one position of a W-bit word (0 for x = 0): a priority encoder.
template <int W>
inline int LeadingOne(const ap_uint<W>& x) {
#pragma HLS INLINE
  int pos = 0;
FX_LEADING_ONE:
  for (int i = 0; i < W; ++i) {
#pragma HLS UNROLL
    if (x[i]) pos = i;
  }
  return pos;
}

}  // namespace fx_detail

// sin and cos of a phase given in turns: ph/2^24 of a full turn (any 24-bit value). Quadrant
// from the top two bits, quarter-wave ROM + linear interpolation for the rest; cos reads the
// ROM at the mirrored position (second port), so both come out in the same cycle.
inline void SinCosPhase24(ap_uint<24> ph, ap_fixed<18, 2>* s, ap_fixed<18, 2>* c) {
#pragma HLS INLINE
  ap_uint<2> q = ph.range(23, 22);
  ap_uint<23> p = ph.range(21, 0);
  ap_uint<23> pm = ap_uint<23>(1u << 22) - p;  // π/2 − θ
  ap_int<23> sv = fx_detail::QuarterSinQ20(p);
  ap_int<23> cv = fx_detail::QuarterSinQ20(pm);
  ap_int<18> s16 = fx_detail::Q20ToQ16(sv);
  ap_int<18> c16 = fx_detail::Q20ToQ16(cv);
  ap_int<18> so, co;
  // sin(qπ/2 + θ), cos(qπ/2 + θ)
  if (q == 0) {
    so = s16;
    co = c16;
  } else if (q == 1) {
    so = c16;
    co = -s16;
  } else if (q == 2) {
    so = -s16;
    co = -c16;
  } else {
    so = -c16;
    co = s16;
  }
  *s = FixedFromRaw<18, 2>(so);
  *c = FixedFromRaw<18, 2>(co);
}

// sin/cos of 2π·u, u a fraction of a turn in [0, 1) with W ≤ 24 bits (Box–Muller's 2πU₂
// without a multiplier: the LFSR word is the phase).
template <int W>
inline void SinCosTurns(ap_ufixed<W, 0> u, ap_fixed<18, 2>* s, ap_fixed<18, 2>* c) {
#pragma HLS INLINE
  static_assert(W >= 2 && W <= 24, "SinCosTurns: 2 ≤ W ≤ 24 phase bits");
  ap_uint<24> ph = ap_uint<24>(RawOf(u)) << (24 - W);
  SinCosPhase24(ph, s, c);
}

// sin/cos of an angle in radians, any value of angle_t (−8 … 8): a·(1/2π) → turns (one
// multiply, two's-complement wrap = mod 2π), then SinCosPhase24.
inline void SinCos(angle_t a, ap_fixed<18, 2>* s, ap_fixed<18, 2>* c) {
#pragma HLS INLINE
  ap_int<12> ar = RawOf(a);  // a·2^8
  ap_int<36> prod = ap_int<36>(ar) * ap_int<36>(fx_detail::kTurnsPerRadQ24);  // turns·2^32
  ap_int<28> ph_full = prod >> 8;                                              // turns·2^24
  ap_uint<24> ph = ph_full.range(23, 0);
  SinCosPhase24(ph, s, c);
}

// Square root of a raw N-bit integer, rounded to nearest: digit-by-digit (restoring) method,
// one result bit per stage (UNROLL: SqrtDepth(N) pipeline stages, II = 1).
template <int N>
inline ap_uint<(N + 1) / 2 + 1> IsqrtRound(const ap_uint<N>& v) {
#pragma HLS INLINE
  constexpr int NE = N + (N & 1);  // even number of radicand bits
  ap_uint<NE + 2> num = v;
  ap_uint<NE + 2> res = 0;
  ap_uint<NE + 2> bit = ap_uint<NE + 2>(1) << (NE - 2);
FX_SQRT_DIGITS:
  for (int i = 0; i < NE / 2; ++i) {
#pragma HLS UNROLL
    ap_uint<NE + 2> trial = res + bit;
    if (num >= trial) {
      num = num - trial;
      res = (res >> 1) + bit;
    } else {
      res = res >> 1;
    }
    bit = bit >> 2;
  }
  // res = floor(sqrt(v)), num = v − res². Round up when v ≥ res² + res + 1 (i.e. v is past
  // (res + 0.5)² = res² + res + 0.25).
  if (num > res) res = res + 1;
  ap_uint<(N + 1) / 2 + 1> out = res;
  return out;
}

// √x in the same format, rounded to nearest (≤ 0.5 ulp); saturates at the format's maximum
// (only reachable when I = 0 and x rounds up to 1). 0 ≤ I ≤ W.
template <int W, int I>
inline ap_ufixed<W, I> Sqrt(ap_ufixed<W, I> x) {
#pragma HLS INLINE
  static_assert(I >= 0 && I <= W, "Sqrt: 0 <= I <= W");
  constexpr int F = W - I;
  // y·2^F = sqrt(X·2^-F)·2^F = sqrt(X·2^F): integer root of the raw word shifted by F.
  ap_uint<W + F> v = ap_uint<W + F>(RawOf(x)) << F;
  ap_uint<(W + F + 1) / 2 + 1> y = IsqrtRound<W + F>(v);
  const ap_uint<(W + F + 1) / 2 + 2> max_raw = (ap_uint<(W + F + 1) / 2 + 2>(1) << W) - 1;
  ap_uint<W> out = (ap_uint<(W + F + 1) / 2 + 2>(y) > max_raw) ? ap_uint<W>(max_raw) : ap_uint<W>(y);
  return UFixedFromRaw<W, I>(out);
}

// cos from sin by eq. 5.3 [HARDWARE.md], cos = ±√(1 − sin²), sign given by the caller (the quadrant: the
// thesis's listing always takes +, which folds the cosine branch of Box–Muller onto
// positive values — fixed here, see box_muller.h). 1 − s² is formed with 32 fraction bits so
// only s's own rounding limits the result.
inline ap_fixed<18, 2> CosFromSin(ap_fixed<18, 2> s, bool negative) {
#pragma HLS INLINE
  ap_int<18> sr = RawOf(s);               // s·2^16
  ap_int<36> sq = ap_int<36>(sr) * ap_int<36>(sr);  // s²·2^32
  ap_int<37> d = ap_int<37>(1) << 32;
  d = d - sq;
  if (d < 0) d = 0;
  ap_uint<34> du = d.range(33, 0);
  ap_uint<18> c = IsqrtRound<34>(du);     // √(d·2^-32)·2^16
  ap_int<19> cs = negative ? ap_int<19>(-ap_int<19>(c)) : ap_int<19>(c);
  ap_int<18> out = cs;
  return FixedFromRaw<18, 2>(out);
}

// Natural log of x ∈ (0, 1): x = m·2^-k with m ∈ [1, 2) by leading-one normalisation,
// ln x = ln m − k·ln 2, ln m from a 256-interval ROM with linear interpolation (error
// ≤ (1/256)²/8 = 1.9e-6, 0.016 ulp of 2^-13). Result rounded to 2^-13. Log(0) = −16 (saturated;
// callers feed LFSR words, which are never 0).
inline ap_fixed<18, 5> Log(ap_ufixed<18, 0> x) {
#pragma HLS INLINE
  ap_uint<18> xr = RawOf(x);
  if (xr == 0) {
    ap_int<18> most_negative = ap_int<18>(-131072);
    return FixedFromRaw<18, 5>(most_negative);
  }
  int p = fx_detail::LeadingOne<18>(xr);    // x = 2^(p−18)·(xr/2^p)
  ap_uint<18> m = xr << (17 - p);           // bit 17 set: m = 1.f, 17 fraction bits
  ap_uint<8> j = m.range(16, 9);
  ap_uint<9> f = m.range(8, 0);
  ap_int<22> a = fx_detail::kLogRom[j.to_int()];
  ap_int<22> b = fx_detail::kLogRom[j.to_int() + 1];
  ap_int<34> prod = ap_int<34>(b - a) * ap_int<34>(f);
  ap_int<26> ln_m = a + ((prod + ap_int<34>(256)) >> 9);   // ·2^20
  // ln x = ln m − k·ln 2 at 2^-24 (k·ln 2 exact to 18·2^-25), then rounded to 2^-13.
  ap_int<34> k = 18 - p;                                    // 1 … 18
  ap_int<34> v = (ap_int<34>(ln_m) << 4) - k * ap_int<34>(fx_detail::kLn2Q24);
  ap_int<34> r = (v + ap_int<34>(1 << 10)) >> 11;           // ·2^13, round half up
  ap_int<18> out = r;
  return FixedFromRaw<18, 5>(out);
}

// 1/x in ap_ufixed<OW, OI> (x in ap_ufixed<W, I>, W ≤ 32, OW ≤ 32), rounded to nearest
// (≤ 0.5 ulp): leading-one normalisation x = m·2^(p−F), a 64-entry ROM seed y₀ ≈ 1/m
// (relative error ≤ 2^-7.5), three Newton–Raphson steps y ← y·(2 − m·y) at 44 fraction bits
// (2^-15 → 2^-30 → 2^-43), the shift by F − p into the output format, then one correction
// step with the exact residual 2·R·X − 2^(F+FO+1) (one multiply and a compare) that moves R
// by ±1 to the round-to-nearest quotient. x = 0 or 1/x beyond the format saturate to the
// maximum. Used for the post-process/CDF normalisation (one reciprocal replaces N
// divisions, §7.3–7.4).
template <int OW, int OI, int W, int I>
inline ap_ufixed<OW, OI> Reciprocal(ap_ufixed<W, I> x) {
#pragma HLS INLINE
  static_assert(W <= 32 && OW <= 32, "Reciprocal: at most 32-bit input and output");
  constexpr int F = W - I;
  constexpr int FO = OW - OI;
  constexpr int S = F + FO;  // raw out = 2^S / X
  static_assert(S >= 0 && S <= 64, "Reciprocal: 0 <= F + FO <= 64");
  const ap_uint<OW> max_raw = ~ap_uint<OW>(0);
  ap_uint<W> xr = RawOf(x);
  if (xr == 0) return UFixedFromRaw<OW, OI>(max_raw);
  int p = fx_detail::LeadingOne<W>(xr);
  ap_uint<32> m = ap_uint<32>(xr) << (31 - p);                         // m·2^31, top bit set
  ap_uint<6> j = m.range(30, 25);
  ap_uint<46> y = ap_uint<46>(fx_detail::kRecipRom[j.to_int()]) << 27;  // 1/m · 2^44
  const ap_uint<47> two_q44 = ap_uint<47>(1) << 45;
FX_RECIP_NR:
  for (int it = 0; it < 3; ++it) {
#pragma HLS UNROLL
    ap_uint<78> my = m * y;                            // m·y · 2^75
    ap_uint<47> myq = my >> 31;                         // m·y · 2^44 (≈ 1)
    ap_uint<47> e = two_q44 - myq;                      // (2 − m·y)·2^44
    ap_uint<93> ye = y * e;
    y = ye >> 44;
  }
  // 1/x = y·2^-44 · 2^(F−p); raw out R = y · 2^(S − p − 44), rounded.
  const int sh = S - p - 44;
  ap_uint<72> r;
  if (sh >= 0) {
    r = ap_uint<72>(y) << sh;
  } else {
    const int rs = -sh;
    r = rs > 70 ? ap_uint<72>(0) : ap_uint<72>((ap_uint<120>(y) + (ap_uint<120>(1) << (rs - 1))) >> rs);
  }
  // Correction: want T − ½ ≤ R < T + ½ with T = 2^S / X, i.e. −X ≤ 2·R·X − 2^(S+1) < X.
  ap_int<112> resid = (ap_int<112>(r * xr) << 1) - (ap_int<112>(1) << (S + 1));
  if (resid >= ap_int<112>(xr)) {
    r = r - 1;
  } else if (resid < -ap_int<112>(xr)) {
    r = r + 1;
  }
  if (r > ap_uint<72>(max_raw)) return UFixedFromRaw<OW, OI>(max_raw);
  ap_uint<OW> out = r;
  return UFixedFromRaw<OW, OI>(out);
}

// n/d in ap_ufixed<OW, OI>, rounded to nearest (≤ 0.5 ulp): restoring long division, one
// quotient bit per stage (DivideDepth(NW + S + 1) stages, II = 1), S = FO − FN + FD ≥ 0.
// d = 0 or an out-of-range quotient saturates to the maximum. The weight merger's one divider
// (I / N_raster, I / N_depth — pass integer counts as ap_ufixed<W, W>).
template <int OW, int OI, int NW, int NI, int DW, int DI>
inline ap_ufixed<OW, OI> Divide(ap_ufixed<NW, NI> n, ap_ufixed<DW, DI> d) {
#pragma HLS INLINE
  constexpr int FN = NW - NI, FD = DW - DI, FO = OW - OI;
  constexpr int S = FO - FN + FD;
  static_assert(S >= 0, "Divide: output needs at least the dividend's fraction bits minus the divisor's");
  constexpr int NQ = NW + S + 1;  // quotient bits of (n << (S + 1)) / d
  static_assert(NQ <= 96, "Divide: quotient wider than 96 bits");
  const ap_uint<OW> max_raw = ~ap_uint<OW>(0);
  ap_uint<DW> dr = RawOf(d);
  if (dr == 0) return UFixedFromRaw<OW, OI>(max_raw);
  ap_uint<NQ> num = ap_uint<NQ>(RawOf(n)) << (S + 1);
  ap_uint<DW + 1> rem = 0;
  ap_uint<NQ> q = 0;
FX_DIV_BITS:
  for (int i = NQ - 1; i >= 0; --i) {
#pragma HLS UNROLL
    rem = (rem << 1) | ap_uint<DW + 1>(num[i] ? 1 : 0);
    if (rem >= ap_uint<DW + 1>(dr)) {
      rem = rem - ap_uint<DW + 1>(dr);
      q[i] = 1;
    }
  }
  ap_uint<NQ + 1> qr = (ap_uint<NQ + 1>(q) + 1) >> 1;  // round half up
  if (qr > ap_uint<NQ + 1>(max_raw)) return UFixedFromRaw<OW, OI>(max_raw);
  ap_uint<OW> out = qr;
  return UFixedFromRaw<OW, OI>(out);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
