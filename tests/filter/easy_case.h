// tests/filter/easy_case.h — a clean synthetic scene (no occlusion, no false detections) with
// its prior, for the filter tests that run EstimatePose end to end.
#pragma once

#include <cstdint>
#include <string>

#include "posefilter/filter.h"
#include "posefilter/synth.h"

namespace posefilter {

inline SynthScene EasyScene(const std::string& target, std::uint64_t seed) {
  SynthOptions so;
  so.target = target;
  so.occlusion = 0;
  so.false_positives = 0;
  return MakeSynthScene(so, seed);
}

// EasyScene with its post-processed prior, the filter input and the target's class.
struct EasyCase {
  EasyCase(const std::string& target, std::uint64_t seed)
      : sc(EasyScene(target, seed)), prior(PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes)),
        in{sc.depth, sc.camera}, cls(prior.ClassIndex(sc.target.name)) {}
  EstimateResult Run(const FilterOptions& o) const { return EstimatePose(in, sc.target, prior, cls, o); }
  // A small, fast budget: 64 particles, one run of at most `iterations` iterations.
  static FilterOptions Small(int iterations) {
    FilterOptions o;
    o.num_particles = 64;
    o.stop.max_iterations = iterations;
    o.restarts = 1;
    return o;
  }
  // Small, with every weighing countable: all `iterations` run (no stall stop), no polish, no
  // ICP move (whose parents are weighed again), no niching (the pool always holds the 10 elite,
  // which keep their weights once the threshold is final).
  static FilterOptions Countable(int iterations) {
    FilterOptions o = Small(iterations);
    o.polish.steps = 0;
    o.stop.stall_iterations = 0;
    o.diffusion.move_probabilities[int(Move::kIcpStep)] = 0;
    o.niches.region_cap = o.niches.rotation_cap = 1;
    return o;
  }
  SynthScene sc;
  Prior prior;
  SceneInput in;
  int cls;
};

}  // namespace posefilter
