// Google Benchmark case of the ADD-S metric (src/eval/metrics.cc) on a 10 000-point cloud.
#include <benchmark/benchmark.h>

#include "posefilter/metrics.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

void BM_AddSError(benchmark::State& state) {
  Rng rng(5);
  std::vector<Eigen::Vector3f> pts(std::size_t(state.range(0)));
  for (auto& p : pts) {  // one draw per statement (C++ leaves a call's argument order open), as GCC ordered them
    const double z = rng.Uniform(-0.1, 0.1), y = rng.Uniform(-0.1, 0.1), x = rng.Uniform(-0.1, 0.1);
    p = Eigen::Vector3f(float(x), float(y), float(z));
  }
  Eigen::Isometry3d T_gt = Eigen::Isometry3d::Identity(), T_est = Eigen::Isometry3d::Identity();
  T_gt.translation() = Eigen::Vector3d(0.01, -0.02, 0.6);
  T_est.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T_est.translation() = Eigen::Vector3d(0.03, 0.0, 0.65);
  for (auto _ : state) benchmark::DoNotOptimize(AddSError(pts, T_est, T_gt));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_AddSError)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefilter
