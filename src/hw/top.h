// src/hw/top.h — the top functions of the `hw` engine (thesis Ch. 7, Fig. 1.4, 7.12, 7.17):
// they only instantiate kernels and the streams/memories between them (finn-hlslib style).
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
//   SplitWeights     — the merger's (weight, index) words → the sorter's weight stream (the
//                      sorter numbers arrivals itself, which equals the merger's index);
//   CollectStats     — the merger's forwarded core outputs → a memory the host reads, and
//                      (ours) each particle's mean depth difference Δ = depth_diff_sum /
//                      depth_diff_count → the sample memory's side-band (depth_off_t), which
//                      the diffusion's align-depth move reads at the next update.
//
// Raster cores in C simulation: HLS would run the M core instances concurrently; the C model
// runs them one after another, or in parallel host threads (OpenMP, ignored by HLS) since each
// core owns its streams, memories and trace — results are identical either way. Their loop
// records are appended to the caller's trace in core order afterwards.
#pragma once

#include "hw/diffusion.h"
#include "hw/distributor.h"
#include "hw/hw_types.h"
#include "hw/raster_core.h"
#include "hw/resample.h"
#include "hw/sample_gen.h"
#include "hw/sorter.h"
#include "hw/transform.h"
#include "hw/weight_merger.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

// One raster core's private memories (depth fragment, window z-buffer) and, in C simulation,
// its own cycle trace (so cores can be simulated in parallel). The caller owns an array of
// kMaxRasterCores of them (≈ 0.3 MB each: heap in C simulation).
struct RasterCoreBank {
  RasterCoreMemory mem;
#ifndef __SYNTHESIS__
  CycleTrace trace;
#endif
};

// Everything HwWeighTop needs that stays fixed during a run (loaded once by the host).
struct WeighConfig {
  int num_cores;      // M active raster cores, 1 … kMaxRasterCores
  int num_faces;      // model faces, 1 … kMaxFaces
  int img_width;      // depth image width, pixels (≤ kImageWidth); height·width ≤ the buffer
  CameraParams cam;   // P and C (eq. 6.9), host-quantized
  RasterParams raster;  // z-buffer / inlier mode, thresholds (thr1 annealed per iteration)
  WeightParams weight;  // α β γ δ, occlusion-aware N_raster
  // ours, optional: grow each particle's window to its bounding-box projection (0 = thesis).
  int grow_window = 0;
  int img_height = kImageHeight;  // image height, pixels (≤ kImageHeight)
  int max_window = kMaxWindow;    // growth cap per axis, pixels (≤ kMaxWindow)
  xyz_t bbox[8][3] = {};          // the model's bounding-box corners, object frame, metres
};

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

// Sample info (§7.5.3): the window of each particle's cell and the cell itself.
inline void GatherSampleInfo(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                             const Window cell_windows[kNumCells], Window windows[kMaxParticles],
                             cell_index_t cells[kMaxParticles] HW_TRACE_PARAM) {
  ft_t pc[kFtElements];
#pragma HLS ARRAY_PARTITION variable = pc complete
  ProjectionTimesCamera(cfg.cam, pc);
GATHER_INFO:
  for (int p = 0; p < n; ++p) {
#pragma HLS PIPELINE II = 8
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const cell_index_t c = samples[p].cell;
    windows[p] = ParticleWindowHw(samples[p], cell_windows[c.to_int()], cfg, pc);
    cells[p] = c;
  }
  // Without growing: II 1, depth = sample read (2) + window memory read (2) + write (1).
  // Growing (ours): one projection unit, 8 corners per particle → II 8; depth = sample read
  // (2) + SampleTransform (≈ 18, as the FT chain) + corner MACs (3) + a 2^-8 px divider (≈ 40
  // stages for the 48-bit quotient) + min/max (1) + grow/clip (3) + write (1) = 68.
  if (cfg.grow_window) HW_TRACE("sample_info", "GATHER_INFO", uint64_t(n), 8, 68);
  else HW_TRACE("sample_info", "GATHER_INFO", uint64_t(n), 1, 5);
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
  HW_TRACE("weight_split", "SPLIT_WEIGHTS", uint64_t(n), 1, 1);
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
  // non-zero: 2^17·2^5 / 1 → 24 bits, rounded up to 26) + round/saturate (1) + write (1).
  HW_TRACE("stats", "COLLECT_STATS", uint64_t(n), 1, 29);
}

// ---- Tops ----

// Initialisation (§7.4, Fig. 7.5): n samples of the class whose post-processed probabilities
// are prob[·][0] (one class loaded, NC = 1) and whose sum is class_sum.
inline void HwInitTop(const prob_t prob[kNumCells][1], class_sum_t class_sum, const HeuristicVolume volumes[kNumCells],
                      cdf_t cdf_mem[kNumCells], InitGenerators& gen, const InitOptions& opt,
                      Sample samples[kMaxParticles], int n, InitReport& report HW_TRACE_PARAM) {
  InitSamples<1>(prob, 0, class_sum, volumes, cdf_mem, gen, opt, samples, n, report HW_TRACE_ARG);
}

// Weighing and sorting of n particles (one DATAFLOW region). Outputs: the weights sorted
// descending with their relative indices, each particle's core counters (stats, particle
// order), each particle's depth offset (the sample memory's side-band, particle order) and the
// depth distributor's read counts.
inline void HwWeighTop(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                       const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
                       const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
                       const face_t tri_mem[kMaxFaces], RasterCoreBank banks[kMaxRasterCores],
                       weight_t sorted_w[kMaxParticles], particle_index_t sorted_idx[kMaxParticles],
                       RasterCoreOutput stats[kMaxParticles], depth_off_t offsets[kMaxParticles],
                       DepthDistributionCounts* dd_counts HW_TRACE_PARAM) {
#pragma HLS DATAFLOW
  const int M = cfg.num_cores;
  Window windows[kMaxParticles];
  cell_index_t cells[kMaxParticles];
  hls::stream<ft_t> ft_chain("ft_chain");
  hls::stream<ft_t> ft_core[kMaxRasterCores];
  hls::stream<Vertex> vert_core[kMaxRasterCores];
  hls::stream<Window> info_core[kMaxRasterCores];
  hls::stream<depth_t> depth_core[kMaxRasterCores];
  hls::stream<RasterCoreOutput> out_core[kMaxRasterCores];
  hls::stream<WeightOut> merged("merged");
  hls::stream<RasterCoreOutput> merged_stats("merged_stats");
  hls::stream<weight_t> to_sorter("to_sorter");
#pragma HLS STREAM variable = ft_core depth = 24
#pragma HLS STREAM variable = vert_core depth = 8
#pragma HLS STREAM variable = depth_core depth = 8

  GatherSampleInfo(n, cfg, samples, cell_windows, windows, cells HW_TRACE_ARG);
  FullTransformChain(n, samples, cfg.cam, ft_chain HW_TRACE_ARG);
  DistributeFT(n, M, ft_chain, ft_core HW_TRACE_ARG);
  VertexMultiplier(n, M, cfg.num_faces, vmem, tri_mem, vert_core HW_TRACE_ARG);
  DistributeDepth(n, M, windows, depth, cfg.img_width, info_core, depth_core, dd_counts HW_TRACE_ARG);
RASTER_CORES:
#ifndef __SYNTHESIS__
#pragma omp parallel for schedule(dynamic, 1)
#endif
  for (int c = 0; c < kMaxRasterCores; ++c) {
#pragma HLS UNROLL
    if (c < M) {
#ifndef __SYNTHESIS__
      banks[c].trace.Clear();
#endif
      RasterCore((n - c + M - 1) / M, cfg.num_faces, cfg.raster, info_core[c], depth_core[c], ft_core[c], vert_core[c],
                 out_core[c], banks[c].mem
#ifndef __SYNTHESIS__
                 , trace ? &banks[c].trace : nullptr
#endif
      );
    }
  }
#ifndef __SYNTHESIS__
  if (trace) {  // the cores' records, in core order (C-simulation bookkeeping)
    for (int c = 0; c < M; ++c)
      for (int r = 0; r < banks[c].trace.count; ++r) {
        const LoopRecord& rec = banks[c].trace.records[r];
        trace->Add(rec.module, rec.loop, rec.trips, rec.ii, rec.depth);
      }
  }
#endif
  MergeWeights(n, M, cfg.weight, out_core, cells, class_prob, merged, merged_stats HW_TRACE_ARG);
  SplitWeights(n, merged, to_sorter HW_TRACE_ARG);
  CollectStats(n, merged_stats, stats, offsets HW_TRACE_ARG);
  SortWeights(to_sorter, n, sorted_w, sorted_idx HW_TRACE_ARG);
}

// Resampling (elitism, pool, threshold tracker) and diffusion into samples_out; the best
// weight that sets the diffusion spread is the sorter's first output (§7.6).
inline void HwUpdateTop(const weight_t sorted_w[kMaxParticles], const particle_index_t sorted_idx[kMaxParticles],
                        const Sample samples_in[kMaxParticles], const depth_off_t offsets_in[kMaxParticles],
                        const hypothesis_t hypothesis[kNumCells],
                        const ResampleParams& rprm, Lfsr18& resample_rng, const DiffusionParams& dprm,
                        const HeuristicVolume volumes[kNumCells], DiffusionRng& diffusion_rng,
                        Sample samples_out[kMaxParticles], ResampleCounters* counters HW_TRACE_PARAM) {
#pragma HLS DATAFLOW
  particle_index_t selected[kMaxParticles];
  Resample(sorted_w, sorted_idx, samples_in, hypothesis, rprm, resample_rng, selected, counters, nullptr HW_TRACE_ARG);
  Diffuse(samples_in, offsets_in, selected, rprm.num_particles, rprm.num_elite, sorted_w[0], dprm, volumes, diffusion_rng,
          samples_out HW_TRACE_ARG);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
