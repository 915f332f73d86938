// Host-side steps shared by every engine's driver: merging restarts and the final polish.
// The float engines use them in src/filter/particle_filter.cc; the hw engine's host side
// (src/hw/engine.cc) uses them around the C-simulated hardware runs.
#pragma once

#include <vector>

#include "posefilter/filter.h"
#include "posefilter/pose.h"

namespace posefilter::filter {

// Merges run `r` into the best-so-far result of the restarts: statistics and iteration
// counts add up, the per-iteration histories are concatenated, and the run with the higher
// weight provides the pose (`first`: `best` holds no run yet).
void MergeRun(EstimateResult* best, EstimateResult&& r, bool first);

// A pose to polish: object → base, and the prior cell it is weighed with (its window, ρ).
struct PolishSeed {
  Pose6 pose;
  int cell = -1;
};

struct PolishResult {
  Pose6 pose;          // object → base
  int cell = -1;
  double weight = 0;   // eq. 7.4 at the final inlier threshold, float (cpu engine) weighing
};

// The final polish of FilterOptions (polish_steps, polish_turns, polish_pivots, polish_keep,
// polish_climbers; ALGORITHM.md §9) of the given seeds, every weighing by the float `cpu`
// engine whatever options.engine says. Returns the best weighed pose (a seed itself counts).
// Throws Error on invalid options, a cell out of range or an empty seed list.
PolishResult PolishPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                         const FilterOptions& options, const std::vector<PolishSeed>& seeds,
                         FilterStats* stats);

}  // namespace posefilter::filter
