// src/render/gpu_kernel.h — the `gpu` engine's score kernel (internal API): Vulkan compute
// shaders that weigh whole particle sets on a GPU (or on Mesa's lavapipe without one).
//
// GpuKernel::Score computes for each particle what ScoreReference computes
// (include/posefilter/render.h; the rasterization rules there are binding), except the ICP
// normal equations (params with scene_normals are refused: the filter weighs those on the cpu
// kernel). Counts (n_raster, n_occluded, n_edge, n_edge_continued, depth_diff_count,
// faces_front, faces_total) and inlier_sum are bit-identical to the reference;
// depth_diff_sum is summed in fixed point of 2^-32 m, so it differs from the reference's
// double sum by less than depth_diff_count · 2^-32 m.
// Three compute passes per batch of particles (src/render/gpu/shaders/):
//   1. vertex: transform, project and snap every vertex for every particle (exact float:
//      no contraction, divisions correctly rounded through double);
//   2. raster: one invocation per (face, particle): culling, int64 Pineda edge functions,
//      perspective-correct 1/z; z-buffer mode keeps the largest 1/z per window pixel
//      (atomicMax), thesis mode compares every fragment at once;
//   3. score (z-buffer mode): one invocation per window pixel: compare, silhouette edge test.
// Sums are int64 fixed point, reduced per workgroup, so results do not depend on the order
// the device runs invocations in (same seed, same poses).
// Data: the model and the scene depth go up once per kernel (one per pixel level of an
// estimate); per batch only the poses and windows go up and the sums come down.
// docs/PERFORMANCE.md ("The gpu engine") has the design notes and measured figures.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "posefilter/render.h"

namespace posefilter::render {

// Whether this build has the gpu engine (CMake option POSEFILTER_VULKAN).
bool GpuBuilt();
// Whether this build has the gpu engine (POSEFILTER_VULKAN) and a Vulkan device it can use;
// else *why (may be null) says what is missing. Makes the device on first use.
bool GpuAvailable(std::string* why);
// The device the gpu engine uses, as "name (type)", e.g. "llvmpipe (LLVM 15.0.6, 256 bits)
// (cpu)"; throws Error when none (GpuAvailable's reason).
std::string GpuDeviceName();

// Errors the Vulkan validation layer reported so far on the gpu engine's device, and the
// first one's text (POSEFILTER_VULKAN_VALIDATION=1 enables the layer; else 0 and "").
int GpuValidationErrors();
std::string GpuFirstValidationError();

class GpuKernel {
 public:
  // Uploads the model (like.vertices, faces) and scene depth (like.depth) that every later
  // Score call's parameters point at. Throws posefilter::Error without a device, when the
  // model or image does not fit the device's buffers, or on a null pointer with a non-empty
  // size.
  explicit GpuKernel(const ScoreKernelParams& like);
  ~GpuKernel();
  GpuKernel(const GpuKernel&) = delete;
  GpuKernel& operator=(const GpuKernel&) = delete;

  // Scores every params[i] into (*out)[i] (resized). All must point at the uploaded arrays
  // and share the intrinsics, near plane, inlier, z-buffer and band settings (one batch is
  // one level and one iteration of the filter); none may carry scene_normals; every window
  // must lie inside the image. Throws Error otherwise, and on a device loss or a batch that
  // does not finish within `timeout_s` (never hangs).
  void Score(const std::vector<ScoreKernelParams>& params, std::vector<ScoreKernelResult>* out,
             double timeout_s = 60.0);


 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

namespace gpu_testing {
// Tests: the next batch submission reports a device loss (lost = true) or a timeout instead
// of running. A no-op in builds without the gpu engine.
void InjectFault(bool lost);
}  // namespace gpu_testing

}  // namespace posefilter::render
