// Scene normals for the ICP terms of the score kernel (render.h).
#include <cmath>

#include "core/threads.h"
#include "posefilter/render.h"

namespace posefilter {

std::vector<float> ComputeSceneNormals(const DepthImage& d, const Camera& c, int threads) {
  std::vector<float> n(std::size_t(d.width) * d.height * 3, 0.f);
  // Rows are independent (each pixel writes only its own normal): threads over rows, same result.
  const int nt = WorkerThreads(threads);
#pragma omp parallel for schedule(static) num_threads(nt) if (d.height > 64)
  for (int v = 1; v < d.height - 1; ++v)
    for (int u = 1; u + 1 < d.width; ++u) {
      const float z = d.at(u, v), zl = d.at(u - 1, v), zr = d.at(u + 1, v), zu = d.at(u, v - 1), zd = d.at(u, v + 1);
      if (z <= 0 || zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) continue;
      if (std::fabs(zr - zl) > 0.02f || std::fabs(zd - zu) > 0.02f) continue;
      const Eigen::Vector3d dx = c.Backproject(u + 1, v, zr) - c.Backproject(u - 1, v, zl);
      const Eigen::Vector3d dy = c.Backproject(u, v + 1, zd) - c.Backproject(u, v - 1, zu);
      Eigen::Vector3d nn = dx.cross(dy);
      const double len = nn.norm();
      if (!(len > 0)) continue;
      nn /= len;
      if (nn.dot(c.Backproject(u, v, z)) > 0) nn = -nn;
      float* o = &n[3 * (std::size_t(v) * d.width + u)];
      o[0] = float(nn.x());
      o[1] = float(nn.y());
      o[2] = float(nn.z());
    }
  return n;
}

}  // namespace posefilter
