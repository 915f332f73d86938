// src/hw/burst.h — on-chip copies of DDR arrays (docs/HARDWARE.md "Memory architecture").
//
// A top's memory arguments are m_axi ports into DDR. A pipelined loop may read or write such a
// port only at addresses that are an affine function of its counter (one burst; the memory
// lint of tools/hls_lint/ checks it); a kernel that reads at data-dependent
// addresses (a cell's window, a vertex of a face, a resampled particle) first copies the array
// into on-chip RAM with BurstLoad and reads the copy. The caller records the copy's cycles,
// HW_TRACE_MEM(module, label, count, 1, kBurstLoadDepth, kAxiReadLatency), under its own
// module; latency.h gives the figures.
#pragma once

#include "hw/latency.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

// dst[0 … count) = src[0 … count), one word per clock (count ≤ N): one read burst.
template <typename T, int N>
void BurstLoad(const T src[N], T dst[N], int count) {
BURST_LOAD:
  for (int i = 0; i < count; ++i) {
#pragma HLS PIPELINE II = 1
    dst[i] = src[i];
  }
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
