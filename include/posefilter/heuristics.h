// posefilter/heuristics.h — per-cell heuristic volumes (thesis §1.1.2, §7.4; docs/ALGORITHM.md §3).
//
// A heuristic is the axis-aligned volume of the base frame where the object seen in a cell's
// box can be. Initialisation (Listing 7.5 [ALGORITHM.md]) places a new sample at the volume's x, y centre
// with z uniform in [z_min, z_max]. We compute it from the depth pixels inside the box:
// back-project them (camera intrinsics), map them to the base frame
// (camera.base_to_camera.inverse()), and take robust per-axis percentiles.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/option_rows.h"
#include "posefilter/prior.h"

namespace posefilter {

struct Volume {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  // base frame, metres
  Eigen::Vector3d max = Eigen::Vector3d::Zero();  // base frame, metres
  bool valid = false;  // false when the box held too few valid depth pixels
  Eigen::Vector3d Centre() const { return 0.5 * (min + max); }
};

struct HeuristicOptions {
  // Robust bounds: per axis, the percentile_lo and percentile_hi quantiles of the cell's
  // points (nearest rank). 0 ≤ percentile_lo ≤ percentile_hi ≤ 1.
  double percentile_lo = 0.1, percentile_hi = 0.9;
  // Each valid point is also moved this far (metres, ≥ 0) further along its viewing ray and
  // both points enter the percentiles: the object's centre lies behind its visible surface,
  // so pass e.g. the object's radius. 0 = surface points only.
  double depth_extension_m = 0;
  // Depth pixels sampled per box (deterministic, centred regular grid subsample), ≥ 1.
  int max_samples = 400;
  // Depth beyond this (metres, > 0) is ignored (the thesis clips the depth at 4 m, §7.1).
  double max_depth_m = 4.0;
  // A box with fewer valid sampled pixels than this (≥ 1) gives valid = false.
  int min_valid_pixels = 5;
  // Every range of HeuristicOptionTable, then percentile_lo <= percentile_hi; `why` names the
  // field ("max_samples must be >= 1 (got 0)").
  bool IsValid(std::string* why) const;
};

// HeuristicOptions' fields as rows (posefilter/option_rows.h): range, help, unit. The one place
// their ranges are written: the filter's heuristics-* options (posefilter/option_table.h) take
// theirs from these rows.
std::span<const OptionInfo> HeuristicOptionTable();

// One volume per box (boxes in pixels, prior.h conventions: a pixel belongs to a box when its
// centre (u, v) lies in [cx − w/2, cx + w/2) × [cy − h/2, cy + h/2); boxes are cut to the
// image). Throws Error if the options or camera are invalid, the depth image's size differs
// from the camera's, or a box is not finite (naming its index). `threads`: worker threads over
// the boxes (0 or less = all cores, capped at 4 per hardware thread); the result does not
// depend on it.
std::vector<Volume> ComputeHeuristics(const DepthImage& depth, const Camera& camera,
                                      const std::vector<Box>& boxes,
                                      const HeuristicOptions& opt = {}, int threads = 0);

}  // namespace posefilter
