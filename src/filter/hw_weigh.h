// src/filter/hw_weigh.h — the seam between the hw engine's runner (hw_driver.cc) and the
// weighing it runs each iteration. By default the runner calls the C model's weigh region
// (HwWeighTopCores, src/hw/tops.h); an HwWeighStrategy replaces that call with the same inputs
// and outputs — the rtl engine (rtl_engine.cc) weighs through the Verilated accelerator.
#pragma once

#include <memory>

#include "filter/engine.h"
#include "hw/host/verilator_transport.h"
#include "hw/tops.h"

namespace posefilter::filter {

class HwWeighStrategy {
 public:
  virtual ~HwWeighStrategy() = default;
  // HwWeighTopCores(cores, n, cfg, …, dd_counts, trace) with the same meaning: the weights
  // sorted descending with their indices, each particle's core counters and depth offset, the
  // depth distributor's counts. `trace` (may be null) as HwWeighTopCores records it.
  virtual void Weigh(int cores, int n, const hw::WeighConfig& cfg, const hw::Sample samples[hw::kMaxParticles],
                     const hw::Window cell_windows[hw::kNumCells], const hw::prob_t class_prob[hw::kNumCells],
                     const hw::depth_t depth[hw::kImageHeight * hw::kImageWidth],
                     const hw::xyz_t vmem[3][hw::kMaxVertices], const hw::face_t tri_mem[hw::kMaxFaces],
                     hw::weight_t sorted_w[hw::kMaxParticles], hw::particle_index_t sorted_idx[hw::kMaxParticles],
                     hw::RasterCoreOutput stats[hw::kMaxParticles], hw::depth_off_t offsets[hw::kMaxParticles],
                     hw::DepthDistributionCounts* dd_counts, hw::CycleTrace* trace) = 0;
  // At the end of each run: adds the strategy's counters of that run to *stats and resets them.
  virtual void EndRun(FilterStats* stats) { (void)stats; }
};

// The hw engine (MakeHwEngine) with its weighing done by `weigh` (not null).
std::unique_ptr<EngineRuns> MakeHwEngineWith(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                             const FilterOptions& options, std::unique_ptr<HwWeighStrategy> weigh);

// The rtl engine's weighing alone (rtl_engine.cc), on a simulated bus with the given options:
// for tests that compare each of its weighings with the C model's. Throws Error when the build
// has no Verilated RTL.
std::unique_ptr<HwWeighStrategy> MakeRtlWeigh(const hw::host::VerilatorTransportOptions& topt);

}  // namespace posefilter::filter
