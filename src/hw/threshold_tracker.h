// src/hw/threshold_tracker.h — the threshold tracker (thesis §7.4 item 2, Fig. 7.8–7.9,
// Listing 7.2; docs/HARDWARE.md §7.1).
//
// Importance sampling picks the first CDF entry ≥ a uniform draw u; scanning from entry 0
// costs up to N reads per draw. While the CDF streams past (it is copied through unchanged
// to the sampling memory), the tracker records, for each of the 2^P threshold levels
// k/2^P (k = 1 … 2^P − 1), the FIRST index whose CDF value reaches it: whenever the top P
// bits of the CDF value (= floor(w_n·2^P)) rise above the last recorded level, it emits
// (level, index) packed as ThrInfo = level << IB | index. Levels that a single step jumps
// over are not recorded (the thesis's adaptive thresholds: "the step … is kept constant,
// unless the difference between two adjacent values exceeds the fixed distance"). The list
// is padded with zero words to exactly 2^P entries (a data-driven module needs a fixed count,
// §7.4; level 0 is never emitted, so 0 marks "unused").
//
// The bound generator (sampling.h) turns the list into a [bottom, top] index interval per draw.
//
// Generic (template) so the resampling stage (§7.5.4, N = 510 weights, 10-bit indices) can
// reuse it: N entries, P threshold bits, IB index bits, CDF_W bits of the CDF word
// (ap_ufixed<CDF_W, 0>).
//
// Thesis code kept: `curr − past ≥ 1` on ap_uint is a signed difference (SEMANTICS.md), i.e.
// curr > past — written as such here.
#pragma once

#include "hw/hw_types.h"
#include "hw/latency.h"

namespace posefilter::hw {

// Thesis: 2^5 = 32 thresholds (SIZE_ARR_THR), 13-bit cell index → 18-bit THR_INFO words.
constexpr int kThrBits = 5;

template <int P, int IB>
struct ThrInfo {
  typedef ap_uint<P + IB> type;  // level (P bits) << IB | first index reaching it (IB bits)
};
template <int P, int IB>
inline ap_uint<P> ThrLevel(const ap_uint<P + IB>& w) {
#pragma HLS INLINE
  ap_uint<P> l = w.range(P + IB - 1, IB);
  return l;
}
template <int P, int IB>
inline ap_uint<IB> ThrIndex(const ap_uint<P + IB>& w) {
#pragma HLS INLINE
  ap_uint<IB> i = w.range(IB - 1, 0);
  return i;
}

// Listing 7.2 [HARDWARE.md] (corrected): copies `n` CDF values from cdf_in to cdf_out and writes exactly
// 2^P threshold words to thr_out. n ≤ N (runtime length: the resampling CDF is shorter
// when fewer particles are resampled).
template <int N, int P, int IB, int CDF_W>
void ThresholdTracker(hls::stream<ap_ufixed<CDF_W, 0> >& cdf_in, hls::stream<ap_ufixed<CDF_W, 0> >& cdf_out,
                      hls::stream<ap_uint<P + IB> >& thr_out, int n HW_TRACE_PARAM) {
  static_assert(P >= 1 && P <= CDF_W, "ThresholdTracker: 1 ≤ P ≤ CDF word bits");
  static_assert((1 << IB) >= N, "ThresholdTracker: IB bits must index N entries");
  if (n > N) n = N;
  ap_uint<P> past = 0;
  int sent = 0, trips = 0;
THR_TRACK:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = N
    ap_ufixed<CDF_W, 0> v = cdf_in.read();
    cdf_out.write(v);
    ap_uint<P> curr = v.range(CDF_W - 1, CDF_W - P);  // floor(v·2^P)
    if (curr > past) {
      ap_uint<P + IB> w;
      w.range(P + IB - 1, IB) = curr;
      w.range(IB - 1, 0) = ap_uint<IB>(i);
      thr_out.write(w);
      past = curr;
      ++sent;
    }
    ++trips;
  }
  HW_TRACE("threshold_tracker", "THR_TRACK", trips, 1, kThrTrackDepth);  // depths: latency.h
  int pads = 0;
THR_PAD:
  for (; sent < (1 << P); ++sent) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 32 avg = 16
    thr_out.write(0);
    ++pads;
  }
  HW_TRACE("threshold_tracker", "THR_PAD", pads, 1, kThrPadDepth);
}

}  // namespace posefilter::hw
