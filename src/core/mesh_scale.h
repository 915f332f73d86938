// src/core/mesh_scale.h — the check that a mesh's units suit the scene it is looked for in
// (internal): the filter's engines and the detector-free stage 1 both run it before any work.
#pragma once

#include <string>

#include "posefilter/depth_image.h"

namespace posefilter {

// The median of the depth image's valid (> 0) pixels, metres; 0 when there is none.
double MedianValidDepth(const DepthImage& d);

// Catches mesh unit mistakes (a millimetre mesh read as metres, or the reverse), for every
// engine: throws Error naming the mesh and --unit-scale unless an object `diameter` metres
// across is 0.001–10 times the median depth of `support` (PreparedScene::support). No check
// when `support` has no valid pixel (nothing to compare with).
void CheckMeshScale(const std::string& mesh_name, double diameter, const DepthImage& support);

}  // namespace posefilter
