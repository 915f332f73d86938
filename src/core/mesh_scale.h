// src/core/mesh_scale.h — the check that a mesh's units suit the scene it is looked for in
// (internal): the filter's engines and the detector-free stage 1 both run it before any work.
#pragma once

#include <string>

#include "posefilter/depth_image.h"

namespace posefilter {

// The median of the depth image's valid (> 0) pixels, metres; 0 when there is none.
double MedianValidDepth(const DepthImage& d);

// Whether MedianValidDepth(d) lies in [lo, hi] (metres), decided in one pass over the pixels
// without copying or sorting them: the median (the valid depth at rank n/2 of n, as
// MedianValidDepth picks it) is at least lo when at most n/2 valid depths are below lo, and at
// most hi when at most n - 1 - n/2 are above hi. False when there is no valid pixel.
bool MedianValidDepthWithin(const DepthImage& d, double lo, double hi);

// Catches mesh unit mistakes (a millimetre mesh read as metres, or the reverse), for every
// engine: throws Error naming the mesh and --unit-scale unless an object `diameter` metres
// across is 0.001–10 times the median depth of `support` (PreparedScene::support). No check
// when `support` has no valid pixel (nothing to compare with).
void CheckMeshScale(const std::string& mesh_name, double diameter, const DepthImage& support);

}  // namespace posefilter
