// src/hw/lfsr.h — the thesis's linear feedback shift registers (§5.1, Listing 5.1 and 7.6 [HARDWARE.md]).
//
// Two Fibonacci LFSRs, as the thesis builds them: the register shifts right by one each step
// and the XOR of the taps enters at the top bit (register numbering of Fig. 5.1: cell 1 is the
// input = bit W−1, cell W the output = bit 0; tap k is bit W−k).
//   LFSR18: p(x) = 1 + x^11 + x^18, taps 18 and 11 → bits 0 and 7; period 2^18 − 1 = 262143.
//   LFSR15: taps 15 and 14 → bits 0 and 1; period 2^15 − 1 = 32767.
// The all-zero state is the XOR LFSR's lock-up state: a zero seed is replaced by a default seed
// (§5.1, Listing 5.1 [HARDWARE.md] line 3). The defaults are ours (the thesis does not print seed_default).
//
// Next() is one shift per call (the thesis's one step per clock: consecutive outputs share
// W−1 bits, i.e. u[n+1] ≈ u[n]/2 + bit/2). Leap<K>() advances K steps in one call — in
// hardware the K-fold unrolled feedback is a small XOR network, still one output per clock
// (II = 1) — so consecutive outputs are (nearly) independent; K must be coprime with the
// period for the full period to survive (period/gcd(K, period)). Our kernels that need
// uncorrelated consecutive draws (Box–Muller, diffusion, resampling) use Leap with
// kLfsr18Leap / kLfsr15Leap; modules that copy the thesis 1:1 use Next().
//
// One plain struct template, two instances: no heap, no static state (each module owns its
// generators, seeds are runtime inputs).
#pragma once

#include "hw/hw_types.h"
#include "hw/latency.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

// Default seeds when a zero seed is given (ours; any non-zero value is valid).
constexpr unsigned kLfsr18DefaultSeed = 0x2A5F3;  // 18 bits
constexpr unsigned kLfsr15DefaultSeed = 0x5A5A;   // 15 bits
// Leap lengths coprime with the periods (262143 = 3^3·7·19·73, 32767 = 7·31·151): 17 new bits
// of 18 per LFSR18 output, 16 steps (all 15 bits new) per LFSR15 output.
constexpr int kLfsr18Leap = 17;
constexpr int kLfsr15Leap = 16;
constexpr unsigned kLfsr18Period = 262143;
constexpr unsigned kLfsr15Period = 32767;

// A W-bit Fibonacci LFSR with taps at bits 0 and kTap (Listing 5.1 [HARDWARE.md] lines 9–13 for W = 18,
// Listing 7.6 [HARDWARE.md] lines 5–9 for W = 15): each step shifts right and the XOR of the two taps enters
// at bit W−1. kSeed replaces a zero seed; kLeap is the step count of Draw().
template <int W, int kTap, unsigned kSeed, int kLeap>
struct FibonacciLfsr {
  ap_uint<W> state;

  explicit FibonacciLfsr(unsigned seed = kSeed) { Seed(seed); }
  // Loads a seed (low W bits); zero is replaced by kSeed (Listing 5.1 [HARDWARE.md] line 3).
  void Seed(unsigned seed) {
    ap_uint<W> s = seed & ((1u << W) - 1u);
    state = (s == 0) ? ap_uint<W>(kSeed) : s;
  }
  // One shift: new bit = bit 0 ^ bit kTap enters at bit W−1.
  void Step() {
#pragma HLS INLINE
    ap_uint<1> out = state[0];
    ap_uint<1> tap = state[kTap];
    ap_uint<1> fb = out ^ tap;
    state = state >> 1;
    state[W - 1] = fb;
  }
  // One step, then the new state (the thesis's output).
  ap_uint<W> Next() {
#pragma HLS INLINE
    Step();
    return state;
  }
  // K steps in one call (unrolled XOR network in hardware), then the new state.
  template <int K>
  ap_uint<W> Leap() {
#pragma HLS INLINE
  LFSR_LEAP:
    for (int k = 0; k < K; ++k) {
#pragma HLS UNROLL
      Step();
    }
    return state;
  }
  // The default leap (kLeap steps): the draw our kernels use.
  ap_uint<W> Draw() { return Leap<kLeap>(); }
};

// 18-bit LFSR, p(x) = 1 + x^11 + x^18 (§5.1, Fig. 5.2, Listing 5.1 [HARDWARE.md]): taps 18 and 11 = bits 0, 7.
using Lfsr18 = FibonacciLfsr<18, 7, kLfsr18DefaultSeed, kLfsr18Leap>;
// 15-bit LFSR, taps 15 and 14 = bits 0, 1 (Listing 7.6 [HARDWARE.md] lines 5–9).
using Lfsr15 = FibonacciLfsr<15, 1, kLfsr15DefaultSeed, kLfsr15Leap>;

// Listing 5.1 [HARDWARE.md] as a module: n successive LFSR18 states (one step each) written to a stream,
// II = 1. The generator keeps its state across calls (the caller owns it).
inline void Lfsr18Generate(Lfsr18& gen, hls::stream<ap_uint<18> >& out, int n HW_TRACE_PARAM) {
  int trips = 0;
LFSR18_GEN:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    out.write(gen.Next());
    ++trips;
  }
  // Depth 1: the register update and the stream write happen in the same cycle (latency.h).
  HW_TRACE("lfsr18", "LFSR18_GEN", trips, 1, kLfsr18GenDepth);
}

// Listing 7.6 [HARDWARE.md] style angle source: n uniform angles in [−π, π) from an LFSR15 (its 15 bits read
// as fixed<15,1> ∈ [−1, 1) and multiplied by π, quantized to angle_t by truncation).
// ours vs thesis: the thesis multiplies by angle_t(π) = 3.140625 in angle_t precision; we use
// π with 16 fraction bits (0x3243F / 2^16) before the truncation, so ±π is reached evenly.
inline angle_t LfsrToAngle(ap_uint<15> bits) {
#pragma HLS INLINE
  // Raw: bits as signed 15-bit r ∈ [−2^14, 2^14), value r·2^-14; × π·2^16 → 2^-30 units.
  ap_int<15> r = bits;
  ap_int<34> prod = ap_int<34>(r) * ap_int<34>(0x3243F);  // π·2^16 = 205887.4 → 205887
  // To angle_t raw (2^-8): shift by 22, floor.
  ap_int<12> a = prod >> 22;
  angle_t out;
  out.range(11, 0) = a.range(11, 0);
  return out;
}

inline void AngleGenerate(Lfsr15& gen, hls::stream<angle_t>& out, int n HW_TRACE_PARAM) {
  int trips = 0;
ANGLE_GEN:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    out.write(LfsrToAngle(gen.Next()));
    ++trips;
  }
  // Depth 3: LFSR step, one DSP multiply (2 stages for 15×18 bits), the write (latency.h).
  HW_TRACE("angle_gen", "ANGLE_GEN", trips, 1, kAngleGenDepth);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
