// posefilter/overlay.h — pictures for humans: depth shading and pose overlays.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

// One line of a legend: a colour swatch and its meaning.
struct LegendEntry {
  std::string text;                    // letters, digits, space and - _ . : , ( ) / % (lower case drawn as capitals)
  std::array<std::uint8_t, 3> color;
};
// Draws the legend in the image's top-left corner: a darkened box, one line per entry (swatch in
// its colour, text in white; 2× the 5×7 font, 3× on images from 1000 px wide).
void DrawLegend(RgbImage* image, const std::vector<LegendEntry>& entries);

// The overlay colours of the CLI and Python: estimates green, ground truth blue.
inline constexpr std::array<std::uint8_t, 3> kEstimateColor = {40, 220, 60};
inline constexpr std::array<std::uint8_t, 3> kGroundTruthColor = {60, 120, 255};

}  // namespace posefilter
