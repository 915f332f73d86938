// ProjectedBox: render the mesh alone into an empty depth image, box the covered pixels.
#include "posefilter/projection.h"

#include <algorithm>

#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/render.h"

namespace posefilter {

Box ProjectedBox(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera) {
  std::string why;
  if (!camera.IsValid(&why)) throw Error("ProjectedBox: invalid camera: " + why);
  if (!mesh.IsValid(&why)) throw Error("ProjectedBox: invalid mesh '" + mesh.name + "': " + why);
  if (!T_cam_obj.matrix().allFinite()) throw Error("ProjectedBox: pose of '" + mesh.name + "' is not finite");

  DepthImage depth(camera.width, camera.height, 0.f);
  RenderDepth(mesh, T_cam_obj, camera, &depth);
  int u0 = camera.width, v0 = camera.height, u1 = -1, v1 = -1;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u)
      if (depth.at(u, v) > 0.f) {
        u0 = std::min(u0, u);
        v0 = std::min(v0, v);
        u1 = std::max(u1, u);
        v1 = std::max(v1, v);
      }
  if (u1 < 0) return {};
  return {0.5 * (u0 + u1), 0.5 * (v0 + v1), double(u1 - u0 + 1), double(v1 - v0 + 1)};
}

}  // namespace posefilter
