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

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/prepared_frame.h"
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

// Validates the scene (ValidateScene, naming `what`) and prepares it for `options`:
// FrameScene, then WithObject with the scene's mask and seeds.
PreparedScene PrepareScene(const SceneInput& scene, const FilterOptions& options, const std::string& what = "scene");

// The part of a scene's preparation that reads the frame alone (depth and camera, checked by
// the caller): with `support_plane`, the support surfaces found and their pixels taken out of
// the scoring and support depths; no mask, no seeds.
PreparedScene FrameScene(const SceneInput& frame, bool support_plane);

// The object's part: `frame` (a FrameScene) with the object's pose seeds and, with a mask,
// the pixels outside it shifted towards the camera in the scoring depth and dropped from the
// support depth (`options`: the shift's distance). Mask and seeds checked by the caller.
PreparedScene WithObject(PreparedScene frame, const std::vector<std::uint8_t>& mask, const std::vector<PoseSeed>& seeds,
                         const FilterOptions& options);

// The scene an estimate with `options` scores against on a prepared frame with the object's
// mask and seeds (checked here, naming `what`): the frame's own scene when the object adds
// nothing and the frame was prepared with options.support.plane; else WithObject of it, or of
// the frame prepared again with the options' support.plane.
std::shared_ptr<const PreparedScene> SceneFor(const PreparedFrame& frame, const ObjectInput& object,
                                              const FilterOptions& options, const std::string& what = "scene");

// Checks a mask and pose seeds for an image of `pixels` pixels (ValidateScene's part for them);
// throws Error naming `what`.
void ValidateObjectInput(const std::vector<std::uint8_t>& mask, const std::vector<PoseSeed>& seeds, std::size_t pixels,
                         const std::string& what);

}  // namespace posefilter::filter
