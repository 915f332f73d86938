// src/synth/synth_util.cc — shared pieces of the synthetic worlds (synth_util.h).
#include "synth/synth_util.h"

#include <algorithm>
#include <cmath>

namespace posefilter::synth {

Eigen::Matrix3d RandomRotation(Rng& rng) {
  Eigen::Quaterniond q;
  double n = 0;
  do {
    // One draw per statement: C++ leaves the order of a call's argument evaluations open (GCC
    // draws the last argument first, Clang the first), so the scene would depend on the
    // compiler. The order is the one every scene so far was made with (z first).
    const double z = rng.Normal(), y = rng.Normal(), x = rng.Normal(), w = rng.Normal();
    q = Eigen::Quaterniond(w, x, y, z);
    n = q.norm();
  } while (n < 1e-9);
  q.coeffs() /= n;
  return q.toRotationMatrix();
}

Mesh PlaneGridMesh(const Eigen::Vector3d& centre, const Eigen::Vector3d& ex, const Eigen::Vector3d& ey, double a0,
                   double a1, double b0, double b1, double step, const Eigen::Isometry3d& T_cam, double min_z) {
  Mesh m;
  m.name = "plane";
  const int na = int(std::lround((a1 - a0) / step)), nb = int(std::lround((b1 - b0) / step));
  std::vector<double> cam_z;
  for (int j = 0; j <= nb; ++j)
    for (int i = 0; i <= na; ++i) {
      const Eigen::Vector3d p = centre + ex * (a0 + i * step) + ey * (b0 + j * step);
      m.vertices.push_back(p.cast<float>());
      cam_z.push_back((T_cam * m.vertices.back().cast<double>()).z());
    }
  auto idx = [&](int i, int j) { return std::uint32_t(j * (na + 1) + i); };
  for (int j = 0; j < nb; ++j)
    for (int i = 0; i < na; ++i) {
      const std::uint32_t a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
      bool near = false;
      for (auto q : {a, b, c, d}) near = near || cam_z[q] < min_z;
      if (near) continue;
      m.faces.push_back({a, b, c});  // ex × ey: counter-clockwise seen from that side
      m.faces.push_back({a, c, d});
    }
  return m;
}

std::size_t CountLabel(const std::vector<int>& labels, int label) {
  return std::size_t(std::count(labels.begin(), labels.end(), label));
}

std::vector<std::uint8_t> DepthEdgePixels(const DepthImage& depth, double jump_m) {
  const int w = depth.width, h = depth.height;
  std::vector<std::uint8_t> edge(std::size_t(w) * h, 0);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float z = depth.at(u, v);
      if (z <= 0) continue;
      const int du[4] = {-1, 1, 0, 0}, dv[4] = {0, 0, -1, 1};
      for (int n = 0; n < 4; ++n) {
        const int uu = u + du[n], vv = v + dv[n];
        if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
        const float zn = depth.at(uu, vv);
        if (zn > 0 && std::fabs(zn - z) > jump_m) {
          edge[std::size_t(v) * w + u] = 1;
          break;
        }
      }
    }
  return edge;
}

void DropHoles(DepthImage* depth, double fraction, Rng& rng) {
  const int w = depth->width, h = depth->height;
  const std::size_t goal = std::size_t(std::ceil(fraction * double(w) * h));
  if (goal == 0) return;
  std::vector<std::uint8_t> hole(std::size_t(w) * h, 0);
  std::size_t covered = 0;
  while (covered < goal) {
    const int cu = int(rng.UniformInt(std::uint64_t(w))), cv = int(rng.UniformInt(std::uint64_t(h)));
    const double r = rng.Uniform(2.0, 8.0);
    const int ir = int(std::ceil(r));
    for (int v = std::max(0, cv - ir); v <= std::min(h - 1, cv + ir) && covered < goal; ++v)
      for (int u = std::max(0, cu - ir); u <= std::min(w - 1, cu + ir) && covered < goal; ++u) {
        if ((u - cu) * (u - cu) + (v - cv) * (v - cv) > r * r) continue;
        auto& hp = hole[std::size_t(v) * w + u];
        if (!hp) {
          hp = 1;
          ++covered;
          depth->at(u, v) = 0;
        }
      }
  }
}

}  // namespace posefilter::synth
