// Google Benchmark case of the heuristic volumes (src/prior/heuristics.cc): the thesis's 6300
// cells, every box at the 200 px clip, on a 640×480 depth image — the set-up every
// EstimatePose call pays once.
#include <benchmark/benchmark.h>

#include "posefilter/heuristics.h"
#include "posefilter/prior.h"

namespace posefilter {
namespace {

void BM_HeuristicsThesisPyramid(benchmark::State& state) {
  const Camera cam;
  DepthImage depth(cam.width, cam.height);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) depth.at(u, v) = float(0.7 + 0.001 * ((u * 7 + v * 3) % 300));
  const PyramidLayout l = PyramidLayout::Thesis();
  std::vector<Box> boxes(l.CellCount());
  for (int c = 0; c < l.CellCount(); ++c) {
    boxes[c] = l.AnchorBox(c);
    boxes[c].w = boxes[c].h = 200;
  }
  HeuristicOptions opt;
  opt.depth_extension_m = 0.05;
  for (auto _ : state) benchmark::DoNotOptimize(ComputeHeuristics(depth, cam, boxes, opt));
  state.counters["boxes"] = double(boxes.size());
}
BENCHMARK(BM_HeuristicsThesisPyramid)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace posefilter
