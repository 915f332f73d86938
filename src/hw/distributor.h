// src/hw/distributor.h — the FT distributor and the depth fragment & sample-info distributor of
// the render/score pipeline (thesis §7.5.3, Fig. 7.17–7.18, Listing 7.7, Table 7.2 [HARDWARE.md]).
//
// Particles are dealt to the M raster cores in rounds: core c of round r renders particle
// r·M + c (the weight merger reads them back in the same order, Listing 7.8 [HARDWARE.md]). The last round
// may be partial (N not a multiple of M): only its active cores get data.
#pragma once

#include "hw/burst.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/transform.h"

#ifndef __SYNTHESIS__
#include <string>
#endif

namespace posefilter::hw {

// A particle's window in the depth image (pixels): columns [u0, u0 + width), rows
// [v0, v0 + height), inside the image, each side ≤ kMaxWindow (the "sample info" a core gets).
struct Window {
  ap_uint<10> u0, v0;
  ap_uint<8> width, height;
};

// The window of side w × h (≤ kMaxWindow) around a box centre (cu, cv), saturated to the
// image: the centre moves inwards when the window would leave the image (§7.5.3, "Saturate").
inline Window SaturatedWindow(int cu, int cv, int w, int h, int img_width, int img_height) {
#pragma HLS INLINE
  if (w > kMaxWindow) w = kMaxWindow;
  if (h > kMaxWindow) h = kMaxWindow;
  if (w > img_width) w = img_width;
  if (h > img_height) h = img_height;
  int u0 = cu - w / 2, v0 = cv - h / 2;
  if (u0 < 0) u0 = 0;
  if (v0 < 0) v0 = 0;
  if (u0 + w > img_width) u0 = img_width - w;
  if (v0 + h > img_height) v0 = img_height - h;
  Window win;
  win.u0 = u0;
  win.v0 = v0;
  win.width = w;
  win.height = h;
  return win;
}

#ifndef __SYNTHESIS__
// Software check for the driver: the window lies in an img_width × img_height image and
// each side is in [1, kMaxWindow]. Names the violated constraint in *why.
inline bool WindowIsValid(const Window& w, int img_width, int img_height, std::string* why) {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  const int u0 = w.u0.to_int(), v0 = w.v0.to_int(), ww = w.width.to_int(), wh = w.height.to_int();
  if (ww < 1 || ww > kMaxWindow) return fail("window width must be in [1, kMaxWindow]");
  if (wh < 1 || wh > kMaxWindow) return fail("window height must be in [1, kMaxWindow]");
  if (u0 + ww > img_width) return fail("window exceeds the image width (u0 + width > image width)");
  if (v0 + wh > img_height) return fail("window exceeds the image height (v0 + height > image height)");
  return true;
}
#endif

// ---- FT distributor (§7.5.3) ----
// Redirects the chain's elements (12 per particle, particle order) to the core that renders
// the particle: one element per cycle.
inline void DistributeFT(int num_particles, int num_cores, hls::stream<ft_t>& ft_in,
                         hls::stream<ft_t> ft_out[kMaxRasterCores] HW_TRACE_PARAM) {
FTD_ELEMENTS:
  for (int i = 0; i < num_particles * kFtElements; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 12 max = 6120
    const int core = (i / kFtElements) % num_cores;
    ft_out[core].write(ft_in.read());
  }
  // Depth: stream read (1) + demultiplexer (1) + stream write (1) (latency.h).
  HW_TRACE("ft_distributor", "FTD_ELEMENTS", uint64_t(num_particles) * kFtElements, 1, kFtdElementsDepth);
}

// Depth-read counts of one call, for hw-report (Table 7.2 [HARDWARE.md], Fig. 7.19a).
struct DepthDistributionCounts {
  ap_uint<32> reads_shared;    // depth pixels read by this module (each shared pixel once per round)
  ap_uint<32> reads_unshared;  // Σ window areas: what a per-core sequential copy reads (eq. 7.8 [HARDWARE.md])
};

// ---- Depth fragment & sample-info distributor (§7.5.3, Listing 7.7 [HARDWARE.md]) ----
// Per round: the active cores' windows are sorted by row (insertion sort), the rows are cut
// into intervals where the set of windows covering a row does not change, and in each
// interval the covering windows' column ranges are sorted and merged into disjoint column
// intervals. Each pixel of that union is read once and written to every core whose window
// contains it, so every core receives exactly its window's pixels in row-major order, and a
// pixel shared by several windows of the round is read once.
// Outputs per particle: its window on info_out[core], then width·height depth pixels on
// depth_out[core].
// The depth image (img_height rows of img_width pixels, row-major, in DDR) is first copied into
// depth_mem, the thesis's depth BRAM (Fig. 7.19a: kImageHeight × kImageWidth × 12 bits, 114
// RAMB36, owned by the caller like the raster cores' memories), by one burst per call: the
// rows of the windows are not consecutive addresses, so reading them from DDR would pay the
// burst latency once per (row, interval) segment.
inline void DistributeDepth(int num_particles, int num_cores, const Window windows[kMaxParticles],
                            const depth_t depth[kImageHeight * kImageWidth], int img_width, int img_height,
                            depth_t depth_mem[kImageHeight * kImageWidth],
                            hls::stream<Window> info_out[kMaxRasterCores],
                            hls::stream<depth_t> depth_out[kMaxRasterCores],
                            DepthDistributionCounts* counts HW_TRACE_PARAM) {
  BurstLoad<depth_t, kImageHeight * kImageWidth>(depth, depth_mem, img_width * img_height);
  HW_TRACE_MEM("depth_distributor", "DD_DEPTH_LOAD", uint64_t(img_width) * uint64_t(img_height), 1, kBurstLoadDepth,
               kAxiReadLatency);
  uint64_t reads = 0, requested = 0, segments = 0, setup_ops = 0;
DD_ROUNDS:
  for (int first = 0; first < num_particles; first += num_cores) {
#pragma HLS LOOP_TRIPCOUNT min = 51 max = 510
    const int active = num_particles - first < num_cores ? num_particles - first : num_cores;
    // Window bounds of the round's cores, registers (complete partition).
    int u_lo[kMaxRasterCores], u_hi[kMaxRasterCores], v_lo[kMaxRasterCores], v_hi[kMaxRasterCores];
#pragma HLS ARRAY_PARTITION variable = u_lo complete
#pragma HLS ARRAY_PARTITION variable = u_hi complete
#pragma HLS ARRAY_PARTITION variable = v_lo complete
#pragma HLS ARRAY_PARTITION variable = v_hi complete
    // Row breakpoints: every window's first row and one-past-last row, sorted (insertion
    // sort limited to the current size, as Listing 7.7 [HARDWARE.md]'s Limited_Insertion_Sort).
    int breaks[2 * kMaxRasterCores];
    int num_breaks = 0;
  DD_LOAD:
    for (int c = 0; c < active; ++c) {
      const Window w = windows[first + c];
      u_lo[c] = w.u0.to_int();
      u_hi[c] = w.u0.to_int() + w.width.to_int();
      v_lo[c] = w.v0.to_int();
      v_hi[c] = w.v0.to_int() + w.height.to_int();
      requested += uint64_t(w.width.to_int()) * uint64_t(w.height.to_int());
      info_out[c].write(w);
      const int b2[2] = {v_lo[c], v_hi[c]};
      for (int k = 0; k < 2; ++k) {
        int pos = num_breaks++;
        while (pos > 0 && breaks[pos - 1] > b2[k]) {
          breaks[pos] = breaks[pos - 1];
          --pos;
          ++setup_ops;
        }
        breaks[pos] = b2[k];
        ++setup_ops;
      }
    }
  DD_ROW_INTERVALS:
    for (int b = 0; b + 1 < num_breaks; ++b) {
      const int row_begin = breaks[b], row_end = breaks[b + 1];
      if (row_begin == row_end) continue;  // duplicate breakpoint
      // Column intervals of the windows covering these rows, sorted by start, merged.
      int col_lo[kMaxRasterCores], col_hi[kMaxRasterCores];
      int n = 0;
    DD_COL_SORT:
      for (int c = 0; c < active; ++c) {
        if (!(v_lo[c] <= row_begin && row_begin < v_hi[c])) continue;
        int pos = n++;
        while (pos > 0 && col_lo[pos - 1] > u_lo[c]) {
          col_lo[pos] = col_lo[pos - 1];
          col_hi[pos] = col_hi[pos - 1];
          --pos;
          ++setup_ops;
        }
        col_lo[pos] = u_lo[c];
        col_hi[pos] = u_hi[c];
        ++setup_ops;
      }
      int m = 0;  // merged intervals: overlapping or touching ranges join
    DD_COL_MERGE:
      for (int k = 0; k < n; ++k) {
        if (m > 0 && col_lo[k] <= col_hi[m - 1]) {
          if (col_hi[k] > col_hi[m - 1]) col_hi[m - 1] = col_hi[k];
        } else {
          col_lo[m] = col_lo[k];
          col_hi[m] = col_hi[k];
          ++m;
        }
        ++setup_ops;
      }
    DD_ROWS:
      for (int row = row_begin; row < row_end; ++row) {
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 200
      DD_SEGMENTS:
        for (int k = 0; k < m; ++k) {
          ++segments;
        DD_PIXELS:
          for (int col = col_lo[k]; col < col_hi[k]; ++col) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 640
            const depth_t d = depth_mem[row * img_width + col];  // the one read of this pixel
            ++reads;
          DD_CHANNELS:
            for (int c = 0; c < kMaxRasterCores; ++c) {
#pragma HLS UNROLL
              if (c < active && row >= v_lo[c] && row < v_hi[c] && col >= u_lo[c] && col < u_hi[c])
                depth_out[c].write(d);
            }
          }
        }
      }
    }
  }
  counts->reads_shared = reads;
  counts->reads_unshared = requested;
  // Setup: one comparison/shift of the insertion sorts and the merge per cycle.
  HW_TRACE("depth_distributor", "DD_SETUP", setup_ops, 1, kDdSetupDepth);
  // Each (row, column interval) segment restarts the pixel pipeline: address (1) + BRAM
  // read (2) + window compare and stream write (1) = 4 cycles of fill per segment, recorded
  // as DD_SEGMENTS' II (latency.h).
  HW_TRACE("depth_distributor", "DD_SEGMENTS", segments, kDdSegmentOverhead, kDdSegmentsDepth);
  HW_TRACE("depth_distributor", "DD_PIXELS", reads, 1, kDdPixelsDepth);
}

}  // namespace posefilter::hw
