// src/hw/box_muller.h — Gaussian noise for the diffusion (§5.2 eq. 5.1–5.2 [ALGORITHM.md],
// eq. 5.3 [HARDWARE.md]; §7.6): the Box–Muller transform on LFSR words, in fixed point
// (fx_math.h: Log, Sqrt, SinCos).
//
//   Z₁ = √(−2 ln U₁)·sin(2πU₂),  Z₂ = √(−2 ln U₁)·cos(2πU₂)            (eq. 5.1 [ALGORITHM.md])
//
// U₁: an LFSR18 word read as ap_ufixed<18,0> ∈ [2^-18, 1 − 2^-18] (never 0: the LFSR has no zero
// state, so the thesis's `if (U != 0)` guard is not needed); U₂: an LFSR15 word read as a
// fraction of a turn, so 2πU₂ needs no multiplier (SinCosTurns). |Z| ≤ √(36·ln 2) = 4.995.
//
// Errata fixed (docs/HARDWARE.md §8):
//  * Listing 5.2 [HARDWARE.md] writes Gauss_fill_h (the sine branch) to BOTH outputs (line 19); here Z₂ is
//    the cosine branch, so a pair is two different, uncorrelated numbers.
//  * eq. 5.3 [HARDWARE.md] as printed, cos = +√(1 − sin²), is never negative: the cosine branch would be a
//    half-normal. With cos_from_sqrt (the thesis's sqrt-recycling path) we give the root the
//    sign of the quadrant of U₂ (cos < 0 for U₂ ∈ (1/4, 3/4)), which costs one XOR. The default
//    path reads cos from the second port of the sine ROM (fx_math SinCosPhase24) — exact to
//    1 ulp where eq. 5.3 [HARDWARE.md] loses precision near |sin| → 1.
#pragma once

#include "hw/fx_math.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/lfsr.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

// ours (not in Table 7.1 [HARDWARE.md]): one N(0, 1) sample, fixed<18,4> (−8 … 8, LSB 2^-14).
typedef ap_fixed<18, 4> gauss_t;

// One Box–Muller pair from two uniform words (U₁ 18 bits, U₂ 15 bits, as described above).
inline void BoxMullerPair(ap_uint<18> u1_bits, ap_uint<15> u2_bits, bool cos_from_sqrt, gauss_t* z1,
                          gauss_t* z2) {
#pragma HLS INLINE
  ap_ufixed<18, 0> u1 = UFixedFromRaw<18, 0>(u1_bits);
  ap_fixed<18, 5> ln_u1 = Log(u1);                     // ∈ [−12.48, 0], LSB 2^-13
  // r² = −2·ln U₁ ∈ [0, 24.96], LSB 2^-13: negate and shift the raw word.
  ap_int<18> ln_raw = RawOf(ln_u1);
  ap_int<20> r2_raw = -(ap_int<20>(ln_raw) << 1);
  ap_ufixed<18, 5> r2 = UFixedFromRaw<18, 5>(ap_uint<18>(r2_raw.range(17, 0)));
  ap_ufixed<18, 5> r = Sqrt<18, 5>(r2);                // ≤ 4.995, LSB 2^-13
  ap_fixed<18, 2> s, c;
  SinCosTurns<15>(UFixedFromRaw<15, 0>(u2_bits), &s, &c);
  if (cos_from_sqrt) {
    // eq. 5.3 [HARDWARE.md] with the quadrant's sign: cos < 0 in quadrants 1 and 2 (top bits 01, 10).
    bool negative = (u2_bits[14] ^ u2_bits[13]) != 0;
    c = CosFromSin(s, negative);
  }
  // Z = r·sin: raw r (2^-13) × raw s (2^-16) = 2^-29; to gauss_t (2^-14) round half up.
  ap_int<19> rr = ap_int<19>(RawOf(r));
  ap_int<38> p1 = ap_int<38>(rr) * ap_int<38>(RawOf(s));
  ap_int<38> p2 = ap_int<38>(rr) * ap_int<38>(RawOf(c));
  ap_int<18> g1 = (p1 + ap_int<38>(1 << 14)) >> 15;
  ap_int<18> g2 = (p2 + ap_int<38>(1 << 14)) >> 15;
  *z1 = FixedFromRaw<18, 4>(g1);
  *z2 = FixedFromRaw<18, 4>(g2);
}

// A free-running Gaussian source (the Box–Muller unit with its two LFSRs, §7.6 Fig. 7.26):
// one pair per call (per clock in hardware). Seeds: zero is replaced by the LFSR defaults.
struct GaussianSource {
  Lfsr18 u1;
  Lfsr15 u2;
  bool cos_from_sqrt = false;

  explicit GaussianSource(unsigned seed18 = kLfsr18DefaultSeed, unsigned seed15 = kLfsr15DefaultSeed,
                          bool use_eq53 = false)
      : u1(seed18), u2(seed15), cos_from_sqrt(use_eq53) {}
  void Pair(gauss_t* z1, gauss_t* z2) {
#pragma HLS INLINE
    ap_uint<18> a = u1.Draw();
    ap_uint<15> b = u2.Draw();
    BoxMullerPair(a, b, cos_from_sqrt, z1, z2);
  }
};

// Listing 5.2 [HARDWARE.md] as a module (corrected): n pairs from streams of U₁ (LFSR18 words) and U₂
// (LFSR15 words) to two Gaussian streams, II = 1.
inline void BoxMuller(hls::stream<ap_uint<18> >& u1_in, hls::stream<ap_uint<15> >& u2_in, hls::stream<gauss_t>& z1_out,
                      hls::stream<gauss_t>& z2_out, int n, bool cos_from_sqrt HW_TRACE_PARAM) {
  int trips = 0;
BOX_MULLER_PAIRS:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 1020
    gauss_t z1, z2;
    BoxMullerPair(u1_in.read(), u2_in.read(), cos_from_sqrt, &z1, &z2);
    z1_out.write(z1);
    z2_out.write(z2);
    ++trips;
  }
  HW_TRACE("box_muller", "BOX_MULLER_PAIRS", trips, 1, kBoxMullerDepth);  // latency.h
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
