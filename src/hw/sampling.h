// src/hw/sampling.h — the bound generator and the sampling stage of the initialisation
// (thesis §7.4 items 3–4, Listings 7.3–7.4; docs/HARDWARE.md §7.1), and the LFSR18 uniform source.
//
// Importance sampling: for a uniform u ∈ (0, 1) pick the first index j with w_n[j] ≥ u
// (§7.4: NewSample_i = w_n_i | w_n_i ≥ U_i ∧ w_n_i < w_n_j for j > i … i.e. the first one).
//
// Bound generator (Listing 7.3 [HARDWARE.md], rewritten): it loads the 2^P threshold words of the tracker
// (threshold_tracker.h), then for each draw u with level k = floor(u·2^P) gives
//   bottom = the index of the first recorded level ≥ k   (0 when k = 0),
//   top    = the index of the first recorded level ≥ k+1 (N − 1 when there is none),
// both found by a 2^P-way parallel compare (UNROLL, a priority encoder). Correctness: the
// answer j has w_n[j] ≥ u ≥ k/2^P, so j ≥ bottom (the first index reaching level k), and
// w_n[top] ≥ (k+1)/2^P > u, so j ≤ top. The thesis's listing scans from its entry 2 (never
// comparing entry 1), and leaves bottom/top unset (the previous draw's) when no entry
// matches; neither is copied.
// `use_tracker = false` gives [0, n − 1] for every draw (the base/GPU version's full scan).
//
// Sampling (Listing 7.4 [HARDWARE.md]): stores the CDF in the sampling memory while it streams in, then
// for each draw scans [bottom, top] one read per cycle and writes the first index whose
// value ≥ u. Counters: `reads` (memory reads done) and `reads_linear` (the reads a scan
// from entry 0 would have done: j + 1) — the thesis's 2520 → 61.5 comparison (Fig. 7.11).
// If no entry of the interval reaches u (impossible for a saturated CDF and u < 1) the top
// index is written, so exactly one index is written per draw (the thesis pads with zeros).
#pragma once

#include <stdint.h>

#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/lfsr.h"
#include "hw/threshold_tracker.h"

namespace posefilter::hw {

// Uniform draws of the sampling and of z: 18 LFSR bits read as ufixed<18,0> ∈ [2^-18, 1).
typedef ap_ufixed<18, 0> unif18_t;

// A draw and its scan interval (Listing 7.3 [HARDWARE.md]'s BOUNDS_RAND word, as a struct).
template <int IB, int CDF_W>
struct SampleBounds {
  ap_uint<IB> bottom, top;
  ap_ufixed<CDF_W, 0> u;
};

// Read counters of the sampling stage (hardware counters, 32 bits).
struct SamplingCounters {
  ap_uint<32> reads;         // CDF memory reads done
  ap_uint<32> reads_linear;  // reads a scan from entry 0 would have needed (Σ (j + 1))
  ap_uint<32> draws;         // indices written
};

// ---- LFSR18 uniform source (§5.1, Listing 5.1 [HARDWARE.md]) ----
// n draws to `out`. leap = false: one shift per draw (the thesis: consecutive draws share 17
// bits, u[t+1] ≈ u[t]/2 + bit/2); leap = true (ours, default of our kernels): kLfsr18Leap
// shifts per draw (lfsr.h), nearly independent consecutive draws. Never 0 (the LFSR state is
// never 0), so u ∈ [2^-18, 1 − 2^-18].
inline void UniformGenerate(Lfsr18& gen, hls::stream<unif18_t>& out, int n, bool leap HW_TRACE_PARAM) {
  int trips = 0;
UNIFORM_GEN:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    ap_uint<18> bits = leap ? gen.Draw() : gen.Next();
    unif18_t u;
    u.range(17, 0) = bits;
    out.write(u);
    ++trips;
  }
  // Depth 1: the (unrolled) register update and the write in one cycle (as LFSR18_GEN).
  HW_TRACE("uniform_gen", "UNIFORM_GEN", trips, 1, kUniformDepth);
}

// ---- Bound generator (Listing 7.3 [HARDWARE.md]) ----
// Pipelines: BOUND_LOAD read+store (1); BOUND_GEN read, 2^P parallel compares and two priority
// encoders (2), write (1). (Depths: latency.h.)

// Reads 2^P threshold words, then n_draws draws from rand_in; writes n_draws bounds. n is the
// CDF length (top = n − 1 above the last level).
template <int N, int P, int IB, int CDF_W>
void BoundGenerate(hls::stream<ap_uint<P + IB> >& thr_in, hls::stream<ap_ufixed<CDF_W, 0> >& rand_in,
                   hls::stream<SampleBounds<IB, CDF_W> >& out, int n, int n_draws, bool use_tracker
                       HW_TRACE_PARAM) {
  constexpr int kThr = 1 << P;
  if (n > N) n = N;
  if (n < 1) n = 1;
  ap_uint<P + IB> thr[kThr];
#pragma HLS ARRAY_PARTITION variable = thr complete
BOUND_LOAD:
  for (int t = 0; t < kThr; ++t) {
#pragma HLS PIPELINE II = 1
    thr[t] = thr_in.read();
  }
  HW_TRACE("bound_gen", "BOUND_LOAD", kThr, 1, kBoundLoadDepth);

  int trips = 0;
BOUND_GEN:
  for (int d = 0; d < n_draws; ++d) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    ap_ufixed<CDF_W, 0> u = rand_in.read();
    ap_uint<P> k = u.range(CDF_W - 1, CDF_W - P);  // floor(u·2^P)
    ap_uint<IB> bottom = 0;
    ap_uint<IB> top = n - 1;
    if (use_tracker) {
      bool found_b = false, found_t = false;
    BOUND_SEARCH:
      for (int t = 0; t < kThr; ++t) {
#pragma HLS UNROLL
        const ap_uint<P> level = ThrLevel<P, IB>(thr[t]);
        const bool valid = (level != 0);
        if (valid && !found_b && k != 0 && level >= k) {
          bottom = ThrIndex<P, IB>(thr[t]);
          found_b = true;
        }
        if (valid && !found_t && level > k) {
          top = ThrIndex<P, IB>(thr[t]);
          found_t = true;
        }
      }
    }
    SampleBounds<IB, CDF_W> b;
    b.bottom = bottom;
    b.top = top;
    b.u = u;
    out.write(b);
    ++trips;
  }
  HW_TRACE("bound_gen", "BOUND_GEN", trips, 1, kBoundGenDepth);
}

// ---- Sampling (Listing 7.4 [HARDWARE.md]) ----
// Pipelines: SAMPLE_STORE read+store (1). SAMPLE_SCAN: memory read (1), compare (1), index
// write (1): depth 3. Each draw re-enters SAMPLE_SCAN: the draw loop (SAMPLE_DRAWS) costs
// the scan's fill (3) + reading the bounds and writing the index (2) per draw. (Depths and
// the per-draw overhead: latency.h.)

// Stores n CDF values from cdf_in into cdf_mem (the sampling memory), then for each of n_draws
// bounds writes the sampled index to idx_out. Counters are reset at the start.
template <int N, int IB, int CDF_W>
void SampleIndices(hls::stream<ap_ufixed<CDF_W, 0> >& cdf_in, hls::stream<SampleBounds<IB, CDF_W> >& bounds,
                   ap_ufixed<CDF_W, 0> cdf_mem[N], hls::stream<ap_uint<IB> >& idx_out, int n, int n_draws,
                   SamplingCounters& counters HW_TRACE_PARAM) {
  if (n > N) n = N;
  if (n < 1) n = 1;
  int stores = 0;
SAMPLE_STORE:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = N
    cdf_mem[i] = cdf_in.read();
    ++stores;
  }
  HW_TRACE("sampling", "SAMPLE_STORE", stores, 1, kSampleStoreDepth);

  ap_uint<32> reads = 0, reads_linear = 0, draws = 0;
  uint64_t scan_trips = 0;
SAMPLE_DRAWS:
  for (int d = 0; d < n_draws; ++d) {
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    SampleBounds<IB, CDF_W> b = bounds.read();
    int bottom = b.bottom.to_int(), top = b.top.to_int();
    if (top > n - 1) top = n - 1;
    int pick = top;
  SAMPLE_SCAN:
    for (int idx = bottom; idx <= top; ++idx) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 6300 avg = 16
      ++reads;
      ++scan_trips;
      if (cdf_mem[idx] >= b.u) {
        pick = idx;
        break;
      }
    }
    idx_out.write(ap_uint<IB>(pick));
    reads_linear += ap_uint<32>(pick + 1);
    ++draws;
  }
  HW_TRACE("sampling", "SAMPLE_SCAN", scan_trips, 1, kSampleScanTraceDepth);  // fill counted in SAMPLE_DRAWS' II
  HW_TRACE("sampling", "SAMPLE_DRAWS", uint64_t(n_draws < 0 ? 0 : n_draws), kSampleDrawOverhead, kSampleDrawsDepth);
  counters.reads = reads;
  counters.reads_linear = reads_linear;
  counters.draws = draws;
}

}  // namespace posefilter::hw
