// Google Benchmark cases of the score kernel, one call = one particle weighed (render + soft
// inlier + the side sums of ScoreKernelResult): the reference kernel against the cpu engine's
// kernel (every instruction-set variant this machine runs, when src/render/cpu_kernel.h is in
// the tree; with and without the back-face pre-cull), in both z-buffer modes, for tori of 512,
// 2048 and 8192 triangles.
//
// Workload (kernel_setup.h): the 2·n²-triangle torus at 0.8 m in front of a wall; each call
// scores one of 16 poses near the true one inside a 200×200 window, cycling through them.
// Counters: fragments/s (counted fragments, N_raster) and particles/s (kernel calls).
// Run: build with -DPOSEFILTER_BUILD_BENCH=ON, then
//   build/<dir>/bench/posefilter_bench --benchmark_filter=BM_Kernel
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "kernel_setup.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"

#if __has_include("render/cpu_kernel.h")
#include "render/cpu_kernel.h"
#define POSEFILTER_BENCH_HAS_CPU 1
#endif

namespace posefilter {
namespace {

void SetCounters(benchmark::State& state, std::int64_t fragments, const KernelSetup& s, const std::string& engine) {
  state.counters["fragments/s"] = benchmark::Counter(double(fragments), benchmark::Counter::kIsRate);
  state.counters["particles/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(engine + ", " + std::to_string(s.mesh.faces.size()) + " faces, " +
                 (s.params[0].zbuffer ? "z-buffer" : "no z-buffer (thesis)"));
}

// Args: (n: torus subdivisions, zbuffer: 0/1).
void BM_KernelReference(benchmark::State& state) {
  const KernelSetup s(int(state.range(0)), state.range(1) != 0);
  RenderWorkspace ws;
  std::int64_t fragments = 0;
  int i = 0;
  for (auto _ : state) {
    const ScoreKernelResult r = ScoreReference(s.params[i], &ws);
    benchmark::DoNotOptimize(r.inlier_sum);
    fragments += r.n_raster;
    i = (i + 1) % kPoses;
  }
  SetCounters(state, fragments, s, "reference");
}

void MeshSizesAndModes(benchmark::internal::Benchmark* b) {
  for (int n : {16, 32, 64})
    for (int zbuffer : {1, 0}) b->Args({n, zbuffer});
  b->ArgNames({"n", "zbuffer"});
}
BENCHMARK(BM_KernelReference)->Apply(MeshSizesAndModes);

#ifdef POSEFILTER_BENCH_HAS_CPU
// The cpu kernel with one instruction-set variant; registered for each variant this CPU runs.
// Args: (n, zbuffer, precull: 0/1 — the back-face pre-cull from the mesh's face planes, as the
// filter runs it).
void BM_KernelCpu(benchmark::State& state, render::CpuTarget target) {
  const KernelSetup s(int(state.range(0)), state.range(1) != 0);
  const bool precull = state.range(2) != 0;
  const ScoreKernelParams& k0 = s.params[0];
  const render::FacePlanes planes = render::BuildFacePlanes(k0);
  render::CpuWorkspace ws;
  std::int64_t fragments = 0;
  int i = 0;
  for (auto _ : state) {
    const ScoreKernelResult r = render::ScoreCpuWith(target, s.params[i], &ws, precull ? &planes : nullptr);
    benchmark::DoNotOptimize(r.inlier_sum);
    fragments += r.n_raster;
    i = (i + 1) % kPoses;
  }
  SetCounters(state, fragments, s, std::string("cpu/") + render::CpuTargetName(target) + (precull ? ", pre-cull" : ""));
}

void CpuMeshSizesModesAndPreCull(benchmark::internal::Benchmark* b) {
  for (int n : {16, 32, 64})
    for (int zbuffer : {1, 0})
      for (int precull : {1, 0}) b->Args({n, zbuffer, precull});
  b->ArgNames({"n", "zbuffer", "precull"});
}

const int kCpuRegistered = [] {
  for (render::CpuTarget t : render::SupportedCpuTargets()) {
    const std::string name = std::string("BM_KernelCpu/") + render::CpuTargetName(t);
    benchmark::RegisterBenchmark(name.c_str(), BM_KernelCpu, t)->Apply(CpuMeshSizesModesAndPreCull);
  }
  return 0;
}();
#endif

}  // namespace
}  // namespace posefilter
