// src/filter/scene_prep.h — the scene every engine scores against (internal).
//
// Two things change the depth image before any weighing (docs/ALGORITHM.md, "Support plane"
// and "Mask priors"):
//   - FilterOptions::support.plane: the pixels of the support surfaces (the table, the floor,
//     a chair's tablet, shelf boards) and of large planar structure (walls; support_plane.h,
//     FindSupportSurfaces) become missing: never an inlier, never an occluder, not in N_depth.
//     A pose laid into the table or sunk below it then explains nothing, and rendered pixels
//     below the table count against it instead of as "occluded".
//   - SceneInput::mask: pixels outside the object's instance mask are moved mask_shift_m
//     towards the camera. A fragment there is then either "occluded" (neither inlier nor
//     wrong: the pixel belongs to something else, or the mask missed a bit of the object)
//     or, when it lies further in front, wrong; never an inlier. N_depth counts mask pixels
//     only.
// `support` holds what can be the object: the scoring depth inside the mask (when one is
// given) and off the plane; the heuristic volumes and N_depth read it.
#pragma once

#include "posefilter/filter.h"
#include "posefilter/support_plane.h"

namespace posefilter::filter {

struct PreparedScene {
  SceneInput scoring;   // the depth the kernels compare with (camera unchanged, no mask)
  DepthImage support;   // valid where the object can be seen: volumes, N_depth
  SupportPlane plane;   // the largest support's plane; found = false when support_plane is off or there is none
  SupportSurfaces surfaces;  // every support surface (and structure patch); empty when support_plane is off
  double mask_shift_m = 0;  // how far pixels outside the mask were moved (0: no mask)
  std::size_t valid_pixels = 0;  // pixels of the input depth with a reading (> 0)
  std::size_t plane_pixels = 0;  // of those, the ones removed as support surfaces or structure
};

// Validates the scene (ValidateScene, naming `what`) and prepares it for `options`.
PreparedScene PrepareScene(const SceneInput& scene, const FilterOptions& options, const std::string& what = "scene");

}  // namespace posefilter::filter
