// Google Benchmark cases of the reference score kernel (render + soft inlier of one particle)
// on the ~2000-triangle torus at 0.8 m in a 200×200 window, in both z-buffer modes.
#include <benchmark/benchmark.h>

#include "posefilter/render.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

struct Setup {
  Mesh mesh = MakeTorus(0.08, 0.03, 32, 32);
  Camera camera;
  DepthImage depth;
  ScoreKernelParams k;
  Setup() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.01, -0.02, 0.8);
    depth = DepthImage(camera.width, camera.height, 0.f);
    RenderDepth(mesh, T, camera, &depth);
    for (float& z : depth.data)
      if (z == 0) z = 1.2f;  // a background wall
    Eigen::Isometry3d scored = T;
    scored.translation().z() += 0.003;  // 3 mm off: a mix of inliers and ramp values
    k = MakeKernelParams(mesh, scored, camera);
    k.window = PixelRect{225, 124, 200, 200};
    k.depth = depth.data.data();
    k.depth_width = depth.width;
    k.depth_height = depth.height;
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
