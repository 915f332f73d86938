// src/hw/tops.h — the four HLS tops of the hw engine, declared (thesis Ch. 7; defined in
// src/hw/tops.cc, the HLS flow's design source and a translation unit of the library):
//
//   HwInitTop    — initialisation (§7.4, Fig. 7.5): n samples of one class into the sample memory;
//   HwWeighTop5  — weighing and sorting of n particles with 5 raster cores (§7.5, §7.7);
//   HwWeighTop10 — the same with 10 raster cores;
//   HwUpdateTop  — resampling and diffusion into the other sample memory (§7.5.4, §7.6).
//
// The signatures are the synthesized ones in C simulation too: a test bench, the co-simulation
// wrapper and the host driver call the same functions. The C simulation's cycle trace is not an
// argument: a caller that wants the tops' loop records names a trace for its thread with
// ScopedTopTrace (hw_types.h). Every array argument is an m_axi port (DDR), every scalar and
// struct an s_axilite register (docs/HARDWARE.md §3 and scripts/hls/README.md list them).
#pragma once

#include "hw/diffusion.h"
#include "hw/distributor.h"
#include "hw/hw_types.h"
#include "hw/raster_core.h"
#include "hw/resample.h"
#include "hw/sample_gen.h"
#include "hw/transform.h"
#include "hw/weight_merger.h"

namespace posefilter::hw {

// Everything HwWeighTop needs that stays fixed during a run (loaded once by the host).
struct WeighConfig {
  int num_cores;      // host side: M of the HwWeighTop<M> that HwWeighTopCores runs, 1 … 10
                      // (the synthesized tops take M as a template parameter, not this field)
  int num_faces;      // model faces, 1 … kMaxFaces
  int img_width;      // depth image width, pixels (≤ kImageWidth); height·width ≤ the buffer
  CameraParams cam;   // P and C (eq. 6.9 [ALGORITHM.md]), host-quantized
  RasterParams raster;  // z-buffer / inlier mode, thresholds (thr1 annealed per iteration)
  WeightParams weight;  // α β γ δ, occlusion-aware N_raster
  // ours, optional: grow each particle's window to its bounding-box projection (0 = thesis).
  int grow_window = 0;
  int img_height = kImageHeight;  // image height, pixels (≤ kImageHeight)
  int max_window = kMaxWindow;    // growth cap per axis, pixels (≤ kMaxWindow)
  xyz_t bbox[8][3] = {};          // the model's bounding-box corners, object frame, metres
};

// Initialisation (§7.4, Fig. 7.5): n samples (clamped to [0, kMaxParticles]) of the class whose
// post-processed probabilities are prob[·][0] (one class loaded) and whose sum is class_sum,
// placed by the heuristic volumes, into samples; gen (the LFSR states) advances.
void HwInitTop(const prob_t prob[kNumCells][1], class_sum_t class_sum, const HeuristicVolume volumes[kNumCells],
               InitGenerators& gen, const InitOptions& opt, Sample samples[kMaxParticles], int n, InitReport& report);

// Weighing and sorting of n particles with 5 (10) raster cores: the weights sorted descending
// with their relative indices, each particle's core counters (stats) and depth offset (the
// sample memory's side-band), and the depth distributor's read counts. Results do not depend
// on the core count.
void HwWeighTop5(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles], const Window cell_windows[kNumCells],
                 const prob_t class_prob[kNumCells], const depth_t depth[kImageHeight * kImageWidth],
                 const xyz_t vmem[3][kMaxVertices], const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                 particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                 depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts);
void HwWeighTop10(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles], const Window cell_windows[kNumCells],
                  const prob_t class_prob[kNumCells], const depth_t depth[kImageHeight * kImageWidth],
                  const xyz_t vmem[3][kMaxVertices], const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                  particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                  depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts);

// Resampling (elitism, pool, caps, threshold tracker) of the sorted set and diffusion into
// samples_out. w_best = sorted_w[0] (a register the host writes); samples_in and
// samples_in_cells are the same sample memory on two read ports.
void HwUpdateTop(const weight_t sorted_w[kMaxParticles], const particle_index_t sorted_idx[kMaxParticles],
                 weight_t w_best, const Sample samples_in[kMaxParticles], const Sample samples_in_cells[kMaxParticles],
                 const depth_off_t offsets_in[kMaxParticles], const hypothesis_t hypothesis[kNumCells],
                 const ResampleParams& rprm, Lfsr18& resample_rng, const DiffusionParams& dprm,
                 const HeuristicVolume volumes[kNumCells], DiffusionRng& diffusion_rng, Sample samples_out[kMaxParticles],
                 ResampleCounters* counters);

#ifndef __SYNTHESIS__
// Host side (C simulation): the weigh region HwWeighTop<M> for a core count M = cores ∈ [1, 10]
// chosen at run time (each M is its own hardware design), recording into trace (may be null).
void HwWeighTopCores(int cores, int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                     const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
                     const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
                     const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                     particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                     depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts, CycleTrace* trace);
#endif

}  // namespace posefilter::hw
