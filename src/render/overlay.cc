#include "posefilter/overlay.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "posefilter/render.h"

namespace posefilter {

RgbImage ShadeDepth(const DepthImage& depth) {
  RgbImage img(depth.width, depth.height);
  float lo = INFINITY, hi = 0;
  for (float z : depth.data)
    if (z > 0) lo = std::min(lo, z), hi = std::max(hi, z);
  const float range = hi > lo ? hi - lo : 1.f;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      const float z = depth.at(u, v);
      const std::uint8_t g = z > 0 ? std::uint8_t(60 + 195 * (1 - (z - lo) / range)) : 0;
      std::uint8_t* p = img.px(u, v);
      p[0] = p[1] = p[2] = g;
    }
  return img;
}

void DrawPoseOverlay(RgbImage* image, const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj,
                     const Camera& camera, std::array<std::uint8_t, 3> color) {
  DepthImage z(camera.width, camera.height, 0.f);
  std::vector<int> mask;
  RenderDepth(mesh, T_cam_obj, camera, &z, &mask, 1);
  const int w = std::min(image->width, camera.width), h = std::min(image->height, camera.height);
  auto inside = [&](int u, int v) {
    return u >= 0 && v >= 0 && u < w && v < h && mask[std::size_t(v) * camera.width + u] == 1;
  };
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if (!inside(u, v)) continue;
      const bool edge = !inside(u - 1, v) || !inside(u + 1, v) || !inside(u, v - 1) || !inside(u, v + 1);
      std::uint8_t* p = image->px(u, v);
      for (int c = 0; c < 3; ++c)
        p[c] = edge ? color[c] : std::uint8_t(0.65 * p[c] + 0.35 * color[c]);
    }
}

}  // namespace posefilter
