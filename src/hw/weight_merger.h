// src/hw/weight_merger.h — the weight merger (thesis §7.5.3 "Weigh/Inlier merger and final
// composition", Listing 7.8 [HARDWARE.md]): reads the raster cores' numerators and denominators in
// particle order (round by round, core by core) and composes the weight of eq. 7.4 [ALGORITHM.md] with ONE
// divider shared by all cores, instead of one per core.
//
//   w = max(0, α·min(1, I/N_raster) + β·min(1, I/N_depth) + γ·ρ − δ·n_edge_continued/n_edge)
//
// (docs/ALGORITHM.md §5; each ratio is 0 when its denominator is 0). N_raster = n_raster −
// n_occluded when occlusion_aware is set (ours, docs/ALGORITHM.md), n_raster otherwise; δ = 0 and
// occlusion_aware = 0 give the thesis's eq. 7.4 [ALGORITHM.md]. Deviations from
// Listing 7.8 [HARDWARE.md]: its weight is (Numerator/Denominator + ρ) >> 2 — one ratio, fixed
// coefficients — while ours has the three terms of eq. 7.4 [ALGORITHM.md] with runtime α, β, γ
// (and δ).
#pragma once

#include "hw/burst.h"
#include "hw/fx_math.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/raster_core.h"

#ifndef __SYNTHESIS__
#include <cmath>
#include <string>
#endif

namespace posefilter::hw {

typedef ap_ufixed<16, 1> coef_t;  // α, β, γ, δ: [0, 2), F15 (ours)
typedef ap_ufixed<18, 1> ratio_t; // a ratio of the divider, [0, 1] after the cap, F17 (ours)

// Runtime parameters of the merger (the host converts the filter's options).
struct WeightParams {
  coef_t alpha, beta, gamma;  // eq. 7.4 [ALGORITHM.md] (defaults 0.2, 0.5, 0.3)
  coef_t delta;               // silhouette edge penalty (default 0.3; 0 = off, the thesis)
  ap_uint<1> occlusion_aware; // 1: N_raster excludes occluded fragments (default; 0 = thesis)
};

// One weighed particle for the sorting network: weight and relative index (Listing 7.8 [HARDWARE.md]).
struct WeightOut {
  weight_t weight;
  particle_index_t index;
};

#ifndef __SYNTHESIS__
inline WeightParams DefaultWeightParams() {
  WeightParams p;
  p.alpha = coef_t(0.2);
  p.beta = coef_t(0.5);
  p.gamma = coef_t(0.3);
  p.delta = coef_t(0.3);
  p.occlusion_aware = 1;
  return p;
}

// Software check for the driver: α, β, γ, δ in [0, 1] and α + β + γ = 1 within the
// coefficients' resolution (3·2^-15). Names the violated constraint in *why.
inline bool WeightParamsAreValid(const WeightParams& p, std::string* why) {
  const double a = p.alpha.to_double(), b = p.beta.to_double(), g = p.gamma.to_double();
  const double d = p.delta.to_double();
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (a > 1 || b > 1 || g > 1) return fail("alpha, beta, gamma must each be in [0, 1]");
  if (d > 1) return fail("delta must be in [0, 1]");
  if (std::fabs(a + b + g - 1) > 3.0 / 32768) return fail("alpha + beta + gamma must equal 1");
  return true;
}
#endif

namespace merger_detail {

// min(1, num/den), 0 for den = 0 — one pass through the shared divider (fx_math Divide,
// restoring, round to nearest, ≤ 2^-18).
inline ratio_t CappedRatio(const inlier_t& num, const count_t& den) {
#pragma HLS INLINE
  if (den == 0) return ratio_t(0);
  const ap_ufixed<32, 32> d = ap_ufixed<32, 32>(den);
  const ratio_t r = Divide<18, 1>(num, d);
  return r > ratio_t(1) ? ratio_t(1) : r;
}

}  // namespace merger_detail

// Merges the outputs of num_particles particles dealt round-robin to num_cores cores
// (particle r·num_cores + c on core c), in particle order. rho of a particle is the stage-1
// probability of its cell: class_prob[cells[particle]]. Every core output is also forwarded
// unchanged, in the same order, on stats_out (the depth alignment and statistics the host
// or the diffusion needs).
inline void MergeWeights(int num_particles, int num_cores, const WeightParams& prm,
                         hls::stream<RasterCoreOutput> core_out[kMaxRasterCores],
                         const cell_index_t cells[kMaxParticles], const prob_t class_prob[kNumCells],
                         hls::stream<WeightOut>& weights, hls::stream<RasterCoreOutput>& stats_out HW_TRACE_PARAM) {
  using namespace merger_detail;
  // ρ is read at each particle's cell: class_prob (DDR) is copied on chip first (kNumCells ×
  // 8 bits, BRAM), one burst per call, while the first round of the cores runs.
  prob_t prob_mem[kNumCells];
  BurstLoad<prob_t, kNumCells>(class_prob, prob_mem, kNumCells);
  HW_TRACE_MEM("weight_merger", "WM_PROB_LOAD", kNumCells, 1, kBurstLoadDepth, kAxiReadLatency);
WM_PARTICLES:
  for (int p = 0; p < num_particles; ++p) {
    // II = 3: the one divider takes I/N_raster, I/N_depth and the edge ratio in turn.
#pragma HLS PIPELINE II = 3
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const int core = p % num_cores;
    const RasterCoreOutput o = core_out[core].read();
    const count_t n_raster = prm.occlusion_aware == 1 ? count_t(o.n_raster - o.n_occluded) : o.n_raster;
    const ratio_t r_raster = CappedRatio(o.inlier_sum, n_raster);
    const ratio_t r_depth = CappedRatio(o.inlier_sum, o.n_depth);
    const ratio_t r_edge = CappedRatio(inlier_t(o.n_edge_continued), o.n_edge);
    const prob_t rho = prob_mem[cells[p].to_int()];
    // Exact sum of products (F32), then max(0, ·) and truncation to weight_t (F17).
    const ap_fixed<40, 4> positive = prm.alpha * r_raster + prm.beta * r_depth + prm.gamma * rho;
    const ap_fixed<40, 4> penalty = prm.delta * r_edge;
    ap_fixed<40, 4> w = positive - penalty;
    if (w < 0) w = 0;
    const ap_fixed<40, 4> w_max = UFixedFromRaw<18, 1>(~ap_uint<18>(0));  // 2 − 2^-17
    if (w > w_max) w = w_max;
    WeightOut out;
    out.weight = weight_t(w);
    out.index = p;
    weights.write(out);
    stats_out.write(o);
  }
  // Depth: stream read (1) + divider (NQ = 50 stages, fx_math DivideDepth) + 3 MACs (3) +
  // clamp and write (2); the loop issues one particle every 3 cycles (latency.h).
  HW_TRACE("weight_merger", "WM_PARTICLES", uint64_t(num_particles), kWmParticlesII, kWmParticlesDepth);
}

}  // namespace posefilter::hw
