// Google Benchmark case of the heuristic volumes (src/prior/heuristics.cc): the thesis's 6300
// cells, every box at the 200 px clip, on a 640×480 depth image (tests/prior/
// heuristics_workload.h, the workload heuristics_test.cc checks) — the set-up every
// EstimatePose call pays once.
#include <benchmark/benchmark.h>

#include "posefilter/heuristics.h"
#include "prior/heuristics_workload.h"  // tests/: the workload the test checks

namespace posefilter {
namespace {

void BM_HeuristicsThesisPyramid(benchmark::State& state) {
  const testing_util::HeuristicsWorkload w = testing_util::ThesisPyramidWorkload();
  for (auto _ : state) benchmark::DoNotOptimize(ComputeHeuristics(w.depth, w.cam, w.boxes, w.opt));
  state.counters["boxes"] = double(w.boxes.size());
}
BENCHMARK(BM_HeuristicsThesisPyramid)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace posefilter
