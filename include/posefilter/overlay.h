// posefilter/overlay.h — pictures for humans: depth shading and pose overlays.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"

namespace posefilter {

// Grey shading of a depth image: near = bright, far = dark, missing = black.
RgbImage ShadeDepth(const DepthImage& depth);

// Renders `mesh` at T_cam_obj (object → camera) and draws it over `image` (same size as the
// camera): the silhouette tinted with `color` at 35% opacity and its outline in full colour.
void DrawPoseOverlay(RgbImage* image, const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj,
                     const Camera& camera, std::array<std::uint8_t, 3> color);

}  // namespace posefilter
