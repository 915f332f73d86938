// Google Benchmark cases of the reference score kernel (render + soft inlier of one particle)
// on the ~2000-triangle torus at 0.8 m in a 200×200 window, in both z-buffer modes.
#include <benchmark/benchmark.h>

#include "kernel_setup.h"
#include "posefilter/render.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

// A larger torus than kernel_setup.h's (R 8 cm, r 3 cm), scored 3 mm off its true pose: a mix
// of inliers and ramp values.
struct Setup {
  Mesh mesh = MakeTorus(0.08, 0.03, 32, 32);
  Camera camera;
  DepthImage depth = DepthBeforeWall(mesh, BenchTruthPose(), camera);
  ScoreKernelParams k;
  Setup() {
    Eigen::Isometry3d scored = BenchTruthPose();
    scored.translation().z() += 0.003;
    k = BenchParams(mesh, scored, camera, depth, true);
  }
};

void BM_ScoreReference(benchmark::State& state) {
  Setup s;
  s.k.zbuffer = state.range(0) != 0;
  RenderWorkspace ws;
  std::int64_t fragments = 0;
  for (auto _ : state) {
    const ScoreKernelResult r = ScoreReference(s.k, &ws);
    benchmark::DoNotOptimize(r.inlier_sum);
    fragments += r.n_raster;
  }
  state.counters["fragments/s"] = benchmark::Counter(double(fragments), benchmark::Counter::kIsRate);
  state.SetLabel(s.k.zbuffer ? "z-buffer" : "no z-buffer (thesis)");
}
BENCHMARK(BM_ScoreReference)->Arg(1)->Arg(0);

}  // namespace
}  // namespace posefilter
