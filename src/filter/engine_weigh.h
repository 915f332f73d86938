// src/filter/engine_weigh.h — the weighing seam of the float filter (particle_filter.cc):
// what scores one batch of particles. The filter makes each particle's kernel parameters
// (pose, window, level, thresholds), hands the batch of unscored ones to the estimate's
// ParticleWeigher, and turns each kernel result into its weight (eq. 7.4 [ALGORITHM.md]); the
// weigher alone decides where the kernel runs. Every engine row of the registry
// (engine_registry.h) names the weigher its float contexts use:
//   reference  the scalar reference kernel (render/reference.h), one particle per worker;
//   cpu        the SIMD kernel of one instruction set (render/cpu_kernel.h), one particle per worker;
//   gpu        the whole batch in one submission of the Vulkan kernel (render/gpu_kernel.h);
//              batches with ICP sums go to the cpu kernel (the device kernel has none);
//   hw, rtl    the reference kernel (their runs weigh in fixed point behind HwWeighStrategy,
//              hw_weigh.h; a float context of theirs — WeighPoses with their options — weighs
//              with the reference).
// All of them give the same counters for the same parameters (the float engines' results are
// bit-identical).
#pragma once

#include <memory>
#include <vector>

#include "posefilter/render.h"
#include "render/cpu_kernel.h"

namespace posefilter::filter {

struct Context;

// One batch: every particle weighed on one pixel level in one state of the run.
struct WeighBatch {
  int level = 0;                                 // LevelIndex (filter_context.h): per-level device state
  const render::FacePlanes* face_planes = nullptr;  // the level mesh's planes (the cpu kernel's pre-cull)
  bool icp = false;  // the parameters carry scene normals: the kernel also sums the ICP equations
  int threads = 0;   // worker threads (FilterOptions::threads; 0 = all cores)
};

class ParticleWeigher {
 public:
  virtual ~ParticleWeigher() = default;
  // Scores params[i] into (*out)[i] (resized to params.size()); params is not empty. Called by
  // one estimate's serial steps at a time; the weigher owns its worker memory and device state.
  virtual void Score(const WeighBatch& batch, const std::vector<ScoreKernelParams>& params,
                     std::vector<ScoreKernelResult>* out) = 0;
};

// The weighers of the float kernels (engine_weigh.cc), for the registry's rows.
std::unique_ptr<ParticleWeigher> MakeReferenceWeigher(const Context& ctx);
std::unique_ptr<ParticleWeigher> MakeCpuWeigher(const Context& ctx);  // ctx.cpu_target's instruction set
std::unique_ptr<ParticleWeigher> MakeGpuWeigher(const Context& ctx);

}  // namespace posefilter::filter
