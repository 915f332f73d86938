// Google Benchmark case of the heuristic volumes (src/prior/heuristics.cc): the thesis's 6300
// cells, every box at the 200 px clip, on a 640×480 depth image (tests/prior/
// heuristics_workload.h, the workload heuristics_test.cc checks) — the set-up every
// EstimatePose call pays once.
#include <benchmark/benchmark.h>

#include "posefilter/heuristics.h"
#include "prior/heuristics_workload.h"  // tests/: the workload the test checks
#include "prior/volume_cache.h"

namespace posefilter {
namespace {

void BM_HeuristicsThesisPyramid(benchmark::State& state) {
  const testing_util::HeuristicsWorkload w = testing_util::ThesisPyramidWorkload();
  for (auto _ : state) benchmark::DoNotOptimize(ComputeHeuristics(w.depth, w.cam, w.boxes, w.opt));
  state.counters["boxes"] = double(w.boxes.size());
}
BENCHMARK(BM_HeuristicsThesisPyramid)->Unit(benchmark::kMillisecond)->UseRealTime();

// The filter's on-demand form: every box's validity, then the volumes of `range(0)` boxes
// spread over the pyramid (a run uses ≈ 400–650 of the 6300 cells).
void BM_VolumeCacheThesisPyramid(benchmark::State& state) {
  const testing_util::HeuristicsWorkload w = testing_util::ThesisPyramidWorkload();
  const int asked = int(state.range(0));
  for (auto _ : state) {
    const prior::VolumeCache cache(w.depth, w.cam, w.boxes, w.opt, 0);
    for (int k = 0; k < asked; ++k) benchmark::DoNotOptimize(cache.Get(int(std::int64_t(k) * cache.size() / asked)));
  }
  state.counters["boxes"] = double(w.boxes.size());
}
BENCHMARK(BM_VolumeCacheThesisPyramid)->Arg(0)->Arg(500)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace posefilter
