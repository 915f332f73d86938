// src/filter/engine_weigh.cc — the float kernels' weighers (engine_weigh.h): reference, cpu
// (one instruction set) and gpu.
#include "filter/engine_weigh.h"

#include <array>
#include <memory>
#include <vector>

#include "core/threads.h"
#include "filter/filter_context.h"
#include "render/gpu_kernel.h"

namespace posefilter::filter {
namespace {

// One particle per worker, each worker with its own workspace (kept from batch to batch so its
// buffers are allocated and touched once); `score` runs the kernel of one particle.
class PerParticleWeigher : public ParticleWeigher {
 protected:
  template <typename ScoreOne>
  void ScoreEach(const WeighBatch& batch, const std::vector<ScoreKernelParams>& params,
                 std::vector<ScoreKernelResult>* out, const ScoreOne& score) {
    const int threads = WorkerThreads(batch.threads);
    if (int(workspaces_.size()) < threads) workspaces_.resize(std::size_t(threads));
    out->resize(params.size());
    ParallelFor(threads, int(params.size()), 4, [&](int worker, int i) {
      (*out)[std::size_t(i)] = score(params[std::size_t(i)], &workspaces_[std::size_t(worker)]);
    });
  }

 private:
  std::vector<render::CpuWorkspace> workspaces_;
};

class ReferenceWeigher final : public PerParticleWeigher {
 public:
  void Score(const WeighBatch& batch, const std::vector<ScoreKernelParams>& params,
             std::vector<ScoreKernelResult>* out) override {
    ScoreEach(batch, params, out, [](const ScoreKernelParams& k, render::CpuWorkspace* ws) {
      return ScoreReference(k, &ws->reference);
    });
  }
};

class CpuWeigher final : public PerParticleWeigher {
 public:
  explicit CpuWeigher(render::CpuTarget target) : target_(target) {}
  void Score(const WeighBatch& batch, const std::vector<ScoreKernelParams>& params,
             std::vector<ScoreKernelResult>* out) override {
    ScoreEach(batch, params, out, [&](const ScoreKernelParams& k, render::CpuWorkspace* ws) {
      return render::ScoreCpuWith(target_, k, ws, batch.face_planes);
    });
  }

 private:
  render::CpuTarget target_;
};

// The whole batch in one submission; per level the level's model and scene on the device (made
// by the first batch on the level). ICP batches go to the cpu kernel.
class GpuWeigher final : public ParticleWeigher {
 public:
  explicit GpuWeigher(render::CpuTarget icp_target) : icp_(icp_target) {}
  void Score(const WeighBatch& batch, const std::vector<ScoreKernelParams>& params,
             std::vector<ScoreKernelResult>* out) override {
    if (batch.icp) return icp_.Score(batch, params, out);
    std::shared_ptr<render::GpuKernel>& gpu = levels_[std::size_t(batch.level)];
    if (!gpu) gpu = std::make_shared<render::GpuKernel>(params[0]);
    gpu->Score(params, out);
  }

 private:
  CpuWeigher icp_;
  std::array<std::shared_ptr<render::GpuKernel>, 2> levels_{};
};

}  // namespace

std::unique_ptr<ParticleWeigher> MakeReferenceWeigher(const Context&) { return std::make_unique<ReferenceWeigher>(); }

std::unique_ptr<ParticleWeigher> MakeCpuWeigher(const Context& ctx) { return std::make_unique<CpuWeigher>(ctx.cpu_target); }

std::unique_ptr<ParticleWeigher> MakeGpuWeigher(const Context& ctx) { return std::make_unique<GpuWeigher>(ctx.cpu_target); }

}  // namespace posefilter::filter
