// src/hw/top.h — the regions and glue of the `hw` engine's top functions (thesis Ch. 7, Fig.
// 1.4, 7.12, 7.17): they only instantiate kernels and the streams/memories between them
// (finn-hlslib style). The tops themselves are declared in tops.h and defined in tops.cc.
//
//   HwInitTop   — the initialisation path (§7.4, Fig. 7.5): CDF → threshold tracker → bound
//                 generator → sampling → sample generation (sample_gen.h InitSamples, itself a
//                 DATAFLOW region), writing the first sample memory.
//   HwWeighTop  — the weighing half of one filter iteration as one DATAFLOW region (§7.5,
//                 Fig. 7.12/7.17): sample-info lookup → full-transformation-matrix chain → FT
//                 distributor; vertex multiplier; depth fragment & sample-info distributor;
//                 M raster cores; weight merger → sorting network (§7.5.4).
//   HwUpdateTop — the other half (§7.5.4, §7.6): resampling with elitism and the threshold
//                 tracker, then diffusion into the other (ping-pong) sample memory.
// The host (src/filter/hw_driver.cc) calls HwWeighTop, reads the best weight (sorter output [0]) to
// decide convergence, and calls HwUpdateTop unless the run stops — the thesis's control loop.
//
// Three tiny glue kernels of ours connect interfaces the kernel engineers defined
// independently (each is a pipelined loop with its own HW_TRACE record):
//   GatherSampleInfo — per particle, its cell's window from the window memory and its cell
//                      (the "sample info" of §7.5.3: the thesis reads box and cell per sample);
//                      ours, optional (WeighConfig::grow_window = 1; 0 = the thesis): the
//                      window grown to contain the projection of the model's bounding box at
//                      the particle's pose (the reference's grow_window, ParticleWindowHw);
//                      it is the one reader of the sample memory in the region and forwards
//                      each sample to the FT chain (a local array);
//   SplitWeights     — the merger's (weight, index) words → the sorter's weight stream (the
//                      sorter numbers arrivals itself, which equals the merger's index);
//   CollectStats     — the merger's forwarded core outputs → a memory the host reads, and
//                      (ours) each particle's mean depth difference Δ = depth_diff_sum /
//                      depth_diff_count → the sample memory's side-band (depth_off_t), which
//                      the diffusion's align-depth move reads at the next update.
//
// Interfaces (Ch. 7 does not list them; as the thesis's §4.4.3, Listing 4.1 [HARDWARE.md] and the second-stage
// code's Init_Crt_Distr: m_axi with depth, offset = slave and a bundle, s_axilite return):
// every memory argument is an AXI4 master (m_axi, offset = slave, one bundle per dataflow
// process that reads or writes it, depth = the compile-time bound for co-simulation); scalars,
// the configuration structs and `return` are AXI4-Lite registers (s_axilite, bundle control).
// Tops are the non-template functions named Hw…Top[N] (scripts/hls names them with set_top):
// HwInitTop, HwWeighTop5, HwWeighTop10 (HwWeighTop<M> for M = 5, 10 raster cores: a template
// cannot be an HLS top) and HwUpdateTop, with the same signatures in C simulation and synthesis
// (tops.h). docs/HARDWARE.md §3 and scripts/hls/README.md list every argument's interface.
//
// Canonical dataflow (each region: HwWeighTop<M>, HwUpdateTop, sample_gen.h's
// InitSamplesRegion): every channel — a stream, a local array, a memory argument — has one
// producer and one consumer; the processes are called unconditionally (the M raster cores by
// a loop over the template parameter M); no scalar statement stands between the processes.
// tests/hw/hwtop_lint_test.cc checks these rules and the INTERFACE pragmas.
//
// C simulation (dataflow.h): in the default sequential mode the processes of a region run in
// statement order over unbounded streams (the vendor's model) and the M raster cores in
// parallel host threads (OpenMP, ignored by HLS; each core owns its streams, memories and
// trace, appended in core order). In bounded mode every stream holds its HW_STREAM depth and
// every process runs concurrently, as synthesis builds them; the results are the same bit for
// bit (tests/hw/hwbounded_test.cc). A core's memories (fragment + z-buffer, ≈ 0.3 MB) and the
// depth distributor's copy of the depth image (≈ 1.2 MB in C) are local arrays of the top in
// synthesis and heap blocks per call in C simulation (too large for a thread's stack;
// estimates run on several threads).
//
// Memories (docs/HARDWARE.md "Memory architecture"): every memory argument is DDR behind an
// m_axi port; a kernel reads or writes it only in bursts (a pipelined loop at addresses
// affine in its counter, at most II accesses per bundle per iteration; the memory lint of
// tests/hw/hwtop_lint_test.cc checks both), and reads what it needs at data-dependent
// addresses from an on-chip copy that a burst fills at the start of each call (burst.h). The
// cycle model charges each burst its DDR latency (latency.h kAxiReadLatency,
// kAxiWriteLatency).
#pragma once

#include "hw/burst.h"
#include "hw/dataflow.h"
#include "hw/diffusion.h"
#include "hw/distributor.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/raster_core.h"
#include "hw/resample.h"
#include "hw/sample_gen.h"
#include "hw/sorter.h"
#include "hw/tops.h"
#include "hw/transform.h"
#include "hw/weight_merger.h"

#ifndef __SYNTHESIS__
#include <memory>
#endif

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {


// The window a particle is weighed in (ours, like the reference's ParticleWindow in
// src/filter/particle_filter.cc): its cell's window grown, axis by axis, to contain the
// projection of the 8 bounding-box corners at the particle's pose, clipped to the image; an
// axis whose grown extent would exceed max(max_window, cell extent) keeps the cell's extent,
// and a corner at W < near keeps the whole cell window. Per corner: (U, V, W) = FT·[c 1]
// (transform.h SampleTransform, raw 2^-32), u = U/W and v = V/W at 2^-8 px (two dividers);
// floor/ceil from the 2^-8 values (≤ 1/256 px from the float projection).
inline Window ParticleWindowHw(const Sample& s, const Window& cell_win, const WeighConfig& cfg, const ft_t pc[kFtElements]) {
#pragma HLS INLINE
  if (cfg.grow_window == 0) return cell_win;
  ft_t ft[kFtElements];
#pragma HLS ARRAY_PARTITION variable = ft complete
  SampleTransform(s, pc, ft);
  const ap_int<56> near_w = ap_int<56>(RawUnsigned(cfg.raster.near_plane)) << 12;  // F20 → F32
  ap_int<40> u_lo = 0, u_hi = 0, v_lo = 0, v_hi = 0;  // pixels at 2^-8
  bool behind = false;
  // The caller's loop is pipelined at II 8: the corners are unrolled and share one projection
  // unit (two dividers, one per image axis), one corner per clock.
#pragma HLS ALLOCATION operation instances = sdiv limit = 2
GROW_CORNERS:
  for (int k = 0; k < 8; ++k) {
#pragma HLS UNROLL
    ap_int<56> h[3];
    for (int r = 0; r < 3; ++r) {
      // ft (2^-22) × corner (2^-10) = 2^-32; translation column << 10.
      h[r] = ap_int<56>(RawSigned(ft[4 * r + 3])) << 10;
      for (int j = 0; j < 3; ++j) h[r] += ap_int<56>(RawSigned(ft[4 * r + j])) * ap_int<56>(RawSigned(cfg.bbox[k][j]));
    }
    if (h[2] < near_w) behind = true;  // a corner behind the near plane
    if (h[2] < near_w) continue;
    const ap_int<40> u = ap_int<40>((h[0] << 8) / h[2]), v = ap_int<40>((h[1] << 8) / h[2]);
    if (k == 0 || u < u_lo) u_lo = u;
    if (k == 0 || u > u_hi) u_hi = u;
    if (k == 0 || v < v_lo) v_lo = v;
    if (k == 0 || v > v_hi) v_hi = v;
  }
  if (behind) return cell_win;
  Window w = cell_win;
  const int lo[2] = {cell_win.u0.to_int(), cell_win.v0.to_int()};
  const int size[2] = {cell_win.width.to_int(), cell_win.height.to_int()};
  const ap_int<40> p_lo[2] = {u_lo, v_lo}, p_hi[2] = {u_hi, v_hi};
  const int limit[2] = {cfg.img_width, cfg.img_height};
GROW_AXES:
  for (int a = 0; a < 2; ++a) {
#pragma HLS UNROLL
    // a = max(0, min(lo, floor(p_lo))), b = min(limit, max(lo + size, ceil(p_hi) + 1)).
    const ap_int<40> fl = p_lo[a] >> 8, ce = (p_hi[a] + 255) >> 8;
    ap_int<40> aa = fl < lo[a] ? fl : ap_int<40>(lo[a]);
    if (aa < 0) aa = 0;
    ap_int<40> bb = ce + 1 > lo[a] + size[a] ? ap_int<40>(ce + 1) : ap_int<40>(lo[a] + size[a]);
    if (bb > limit[a]) bb = limit[a];
    const int cap = cfg.max_window > size[a] ? cfg.max_window : size[a];
    if (bb - aa > cap) continue;  // keep the cell window's extent on this axis
    if (a == 0) {
      w.u0 = aa.to_int();
      w.width = (bb - aa).to_int();
    } else {
      w.v0 = aa.to_int();
      w.height = (bb - aa).to_int();
    }
  }
  return w;
}

// ---- Glue kernels (ours) ----

// Sample info (§7.5.3): the window of each particle's cell and the cell itself; each sample is
// forwarded to samples_fwd (the FT chain's copy) so the sample memory has one reader.
inline void GatherSampleInfo(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                             const Window cell_windows[kNumCells], Window windows[kMaxParticles],
                             cell_index_t cells[kMaxParticles], Sample samples_fwd[kMaxParticles] HW_TRACE_PARAM) {
  ft_t pc[kFtElements];
#pragma HLS ARRAY_PARTITION variable = pc complete
  ProjectionTimesCamera(cfg.cam, pc);
  // The window memory (§7.5.3): the cells' windows, read at each particle's cell, so on chip
  // (kNumCells × 36 bits, BRAM), filled by one burst per call.
  Window window_mem[kNumCells];
  BurstLoad<Window, kNumCells>(cell_windows, window_mem, kNumCells);
  HW_TRACE_MEM("sample_info", "WINDOW_LOAD", kNumCells, 1, kBurstLoadDepth, kAxiReadLatency);
GATHER_INFO:
  for (int p = 0; p < n; ++p) {
#pragma HLS PIPELINE II = 8
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const Sample s = samples[p];
    const cell_index_t c = s.cell;
    windows[p] = ParticleWindowHw(s, window_mem[c.to_int()], cfg, pc);
    cells[p] = c;
    samples_fwd[p] = s;
  }
  // The recorded II and depths are latency.h's. Without growing, II 1 is the loop of a design
  // without the projection unit (the thesis's), which the model's thesis configuration stands
  // for. This top has the unit and is II 8 whatever grow_window says, so with grow_window off it
  // takes up to 7·n clocks (≤ 3.6 k per iteration) more than recorded, hidden behind the
  // raster cores.
  // The samples are one read burst: its latency adds to the loop's depth.
  if (cfg.grow_window)
    HW_TRACE_MEM("sample_info", "GATHER_INFO", uint64_t(n), kGatherInfoGrowII, kGatherInfoGrowDepth + kAxiReadLatency,
                 kAxiReadLatency);
  else HW_TRACE_MEM("sample_info", "GATHER_INFO", uint64_t(n), 1, kGatherInfoDepth + kAxiReadLatency, kAxiReadLatency);
}

// The merger's (weight, relative index) stream → the sorter's weight stream. The merger emits
// particles in order 0 … n−1, the index the sorter assigns to its i-th arrival.
inline void SplitWeights(int n, hls::stream<WeightOut>& in, hls::stream<weight_t>& out HW_TRACE_PARAM) {
SPLIT_WEIGHTS:
  for (int p = 0; p < n; ++p) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    out.write(in.read().weight);
  }
  HW_TRACE("weight_split", "SPLIT_WEIGHTS", uint64_t(n), 1, kSplitWeightsDepth);  // latency.h
}

// Mean depth difference of one particle, Δ = Σ(z_s − z_r) / count (0 when count = 0), in
// depth_off_t: the F20 sum divided by the count (truncated toward 0), rounded half up to F15
// and saturated to ±4 m.
inline depth_off_t MeanDepthOffset(const RasterCoreOutput& o) {
#pragma HLS INLINE
  if (o.depth_diff_count == 0) return depth_off_t(0);
  const ap_int<64> q20 = ap_int<64>(RawOf(o.depth_diff_sum)) / ap_int<64>(o.depth_diff_count);
  ap_int<64> q15 = (q20 + 16) >> 5;
  if (q15 > ap_int<64>(131071)) q15 = 131071;
  if (q15 < ap_int<64>(-131072)) q15 = -131072;
  return FixedFromRaw<18, 3>(ap_int<18>(q15));
}

// The merger's forwarded core outputs (particle order) → a memory for the host, and the
// per-particle depth offsets → the sample memory's side-band.
inline void CollectStats(int n, hls::stream<RasterCoreOutput>& in, RasterCoreOutput stats[kMaxParticles],
                         depth_off_t offsets[kMaxParticles] HW_TRACE_PARAM) {
COLLECT_STATS:
  for (int p = 0; p < n; ++p) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const RasterCoreOutput o = in.read();
    stats[p] = o;
    offsets[p] = MeanDepthOffset(o);
  }
  // Depth: read (1) + a pipelined 56/32-bit divider (≈ one stage per quotient bit that can be
  // non-zero: 2^17·2^5 / 1 → 24 bits, rounded up to 26) + round/saturate (1) + write (1) = 29
  // (latency.h).
  // stats and offsets are two write bursts on their own bundles: + the write latency.
  HW_TRACE_MEM("stats", "COLLECT_STATS", uint64_t(n), 1, kCollectStatsDepth + kAxiWriteLatency, kAxiWriteLatency);
}

// ---- The weigh region (the tops HwWeighTop5 and HwWeighTop10 in tops.cc) ----

// Weighing and sorting of n particles with M raster cores (1 … kMaxRasterCores), one DATAFLOW
// region. Outputs: the weights sorted descending with their relative indices, each particle's
// core counters (stats, particle order), each particle's depth offset (the sample memory's
// side-band, particle order) and the depth distributor's read counts. Particle p is rendered
// by core p mod M; results do not depend on M. Not a top itself (a template): the tops are
// HwWeighTop5 and HwWeighTop10 (tops.h, tops.cc).
template <int M>
void HwWeighTop(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles], const Window cell_windows[kNumCells],
                const prob_t class_prob[kNumCells], const depth_t depth[kImageHeight * kImageWidth],
                const xyz_t vmem[3][kMaxVertices], const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts HW_TRACE_PARAM) {
  static_assert(M >= 1 && M <= kMaxRasterCores, "HwWeighTop: M must be in [1, kMaxRasterCores]");
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, trace);
#ifdef __SYNTHESIS__
  RasterCoreMemory core_mem[M];  // per core: depth fragment + window z-buffer (BRAM)
#pragma HLS ARRAY_PARTITION variable = core_mem complete dim = 1
  depth_t depth_mem[kImageHeight * kImageWidth];  // the depth BRAM of DistributeDepth
#else
  std::unique_ptr<RasterCoreMemory[]> core_mem_heap(new RasterCoreMemory[M]);
  RasterCoreMemory* const core_mem = core_mem_heap.get();
  std::unique_ptr<depth_t[]> depth_mem_heap(new depth_t[kImageHeight * kImageWidth]);
  depth_t* const depth_mem = depth_mem_heap.get();
#endif
  // Ping-pong buffers of GatherSampleInfo: its readers start when it has returned.
  Window windows[kMaxParticles];
  cell_index_t cells[kMaxParticles];
  // The FT chain's copy of the samples (GatherSampleInfo forwards them). A ping-pong array, not
  // a FIFO: the cores wait for the windows, which GatherSampleInfo completes only after its last
  // particle, so a short FIFO here would fill and stall the region.
  Sample samples_ft[kMaxParticles];
  hls::stream<ft_t> ft_chain;
  hls::stream<ft_t> ft_core[M];
  hls::stream<Vertex> vert_core[M];
  hls::stream<Window> info_core[M];
  hls::stream<depth_t> depth_core[M];
  hls::stream<RasterCoreOutput> out_core[M];
  hls::stream<WeightOut> merged;
  hls::stream<RasterCoreOutput> merged_stats;
  hls::stream<weight_t> to_sorter;
  HW_STREAM(ft_chain, 2);
  HW_STREAM(ft_core, 24);
  // 2048 vertices per core (block RAM; vertex_multiplier.sv's FD): the multiplier writes each
  // vertex to all cores of a round at once, and this depth lets each core read them at its own
  // rate, as the cycle model's rounds assume (docs/HARDWARE.md §12).
  HW_STREAM(vert_core, 2048);
  HW_STREAM(info_core, 2);
  HW_STREAM(depth_core, 8);
  HW_STREAM(out_core, 2);
  HW_STREAM(merged, 2);
  HW_STREAM(merged_stats, 2);
  HW_STREAM(to_sorter, 2);

  HW_PROCESS(df, GatherSampleInfo(n, cfg, samples, cell_windows, windows, cells, samples_ft HW_TRACE_ARG));
  HW_PROCESS_AFTER(df, "GatherSampleInfo", FullTransformChain(n, samples_ft, cfg.cam, ft_chain HW_TRACE_ARG));
  HW_PROCESS(df, DistributeFT(n, M, ft_chain, ft_core HW_TRACE_ARG));
  HW_PROCESS(df, VertexMultiplier(n, M, cfg.num_faces, vmem, tri_mem, vert_core HW_TRACE_ARG));
  HW_PROCESS_AFTER(df, "GatherSampleInfo",
                   DistributeDepth(n, M, windows, depth, cfg.img_width, cfg.img_height, depth_mem, info_core,
                                   depth_core, dd_counts HW_TRACE_ARG));
RASTER_CORES:
  HW_PROCESS_UNROLL(df, c, M,
                    RasterCore((n - c + M - 1) / M, cfg.num_faces, cfg.raster, info_core[c], depth_core[c], ft_core[c],
                               vert_core[c], out_core[c], core_mem[c] HW_TRACE_ARG));
  HW_PROCESS_AFTER(df, "GatherSampleInfo",
                   MergeWeights(n, M, cfg.weight, out_core, cells, class_prob, merged, merged_stats HW_TRACE_ARG));
  HW_PROCESS(df, SplitWeights(n, merged, to_sorter HW_TRACE_ARG));
  HW_PROCESS(df, CollectStats(n, merged_stats, stats, offsets HW_TRACE_ARG));
  HW_PROCESS(df, SortWeights(to_sorter, n, sorted_w, sorted_idx HW_TRACE_ARG));
  HW_DATAFLOW_END(df);
}


}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
