// src/hw/cdf.h — cumulative sum and normalisation of the initialisation (thesis §7.4 item 1,
// eq. 7.3 [ALGORITHM.md], Fig. 7.6–7.7; docs/HARDWARE.md §7.1): one class's probabilities over the kNumCells
// cells → the normalised CDF
//   w_n[i] = (Σ_{q ≤ i} w_q) / (Σ_k w_k),  i = 0 … kNumCells − 1,              (eq. 7.3 [ALGORITHM.md])
// streamed out in cdf_t = ap_ufixed<18,0> (truncated), the last value saturated to
// 1 − 2^-18 (the thesis's fix for the finite-precision reciprocal, §7.4 item 1).
//
// Datapath: the full-precision running sum cum_i of prob_t (ufixed<8,0>) values is exact in
// class_sum_t = ap_ufixed<21,13> (6300·255/256 < 2^13). The normalisation coefficient 1/Σ is
// one reciprocal (WideReciprocal: mantissa inverse ≤ 2^-30 relative, and a power-of-two
// shift), so w_n[i] = cum_i·(1/Σ) is off the exact ratio by < 2^-18 (truncation) + 2^-29
// (reciprocal), i.e. within 2^-17 of the double CDF (tests/hw/hwsample_cdf_test.cc). cum_i
// is monotone and 1/Σ constant, so the output is monotone.
//
// Σ comes from the post-process (its class_sum, §7.3 "evaluated concurrently"), as in the
// thesis's final version (its earlier variant read the probability memory twice). Zero mass
// (Σ = 0: e.g. a uniform prior whose 1/6300 rounds to 0 in prob_t) would divide by zero; ours:
// every cell then counts 1 (a uniform CDF) and `uniform_fallback` is raised for the driver.
#pragma once

#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/postprocess.h"

namespace posefilter::hw {

// The one-class CDF (eq. 7.3 [ALGORITHM.md]) of prob[·][cls], Σ = class_sum (the post-process's class sum of
// `cls`). Writes kNumCells values to `out`. cls must be in [0, NC).
template <int NC>
void CdfNormalise(const prob_t prob[kNumCells][NC], int cls, class_sum_t class_sum,
                  hls::stream<cdf_t>& out, bool& uniform_fallback HW_TRACE_PARAM) {
#ifndef __SYNTHESIS__
  if (cls < 0 || cls >= NC) cls = 0;  // software guard; the driver validates the class
#endif
  const bool empty = (class_sum == 0);
  uniform_fallback = empty;
  const class_sum_t total = empty ? class_sum_t(kNumCells) : class_sum;
  recip_mant_t inv_m;
  int s = 0;
  WideReciprocal(total, &inv_m, &s);  // 1/Σ = inv_m·2^-s, s ∈ [−7, 13]
  HW_TRACE("cdf", "CDF_RECIP", 1, 1, kWideRecipDepth);

  class_sum_t cum = 0;
  cdf_t sat;
  sat.range(17, 0) = ~ap_uint<18>(0);  // 1 − 2^-18
  int trips = 0;
CDF_NORM:
  for (int i = 0; i < kNumCells; ++i) {
#pragma HLS PIPELINE II = 1
    if (empty) {
      cum = cum + ap_ufixed<1, 1>(1);
    } else {
      cum = cum + prob[i][cls];
    }
    ap_ufixed<72, 20> t = cum * inv_m;  // exact (<53,15>), room for the shifts
    if (s >= 0) {
      t = t >> s;
    } else {
      t = t << (-s);
    }
    ap_ufixed<18, 0, AP_TRN, AP_SAT> q = t;  // truncated, < 1
    cdf_t c = q;
    if (i == kNumCells - 1) c = sat;         // last value saturated (§7.4)
    out.write(c);
    ++trips;
  }
  // prob is read in order from DDR (one burst): its latency adds to the depth (latency.h).
  HW_TRACE_MEM("cdf", "CDF_NORM", trips, 1, kCdfNormDepth + kAxiReadLatency, kAxiReadLatency);
}

}  // namespace posefilter::hw
