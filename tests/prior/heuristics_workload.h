// tests/prior/heuristics_workload.h — the heuristic volumes of a whole thesis pyramid, shared by
// the correctness test (tests/prior/heuristics_test.cc) and the timing
// (bench/prior_bench.cc's BM_HeuristicsThesisPyramid), so both run exactly the same boxes.
//
// The thesis's 6300 cells, every box at the 200 px clip, on a 640×480 depth image of the
// default camera whose depths ramp through [0.7, 1.0) m; 5 cm depth extension.
#pragma once

#include <vector>

#include "posefilter/heuristics.h"
#include "posefilter/prior.h"

namespace posefilter::testing_util {

struct HeuristicsWorkload {
  Camera cam;
  DepthImage depth{cam.width, cam.height};
  std::vector<Box> boxes;
  HeuristicOptions opt;
};

inline HeuristicsWorkload ThesisPyramidWorkload() {
  HeuristicsWorkload w;
  for (int v = 0; v < w.cam.height; ++v)
    for (int u = 0; u < w.cam.width; ++u) w.depth.at(u, v) = float(0.7 + 0.001 * ((u * 7 + v * 3) % 300));
  const PyramidLayout l = PyramidLayout::Thesis();
  w.boxes.resize(l.CellCount());
  for (int c = 0; c < l.CellCount(); ++c) {
    w.boxes[c] = l.AnchorBox(c);
    w.boxes[c].w = w.boxes[c].h = 200;
  }
  w.opt.depth_extension_m = 0.05;
  return w;
}

}  // namespace posefilter::testing_util
