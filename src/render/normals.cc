// Scene normals for the ICP terms of the score kernel (render.h), all at once or on demand
// (scene_normals.h).
#include <algorithm>
#include <cmath>

#include "core/threads.h"
#include "posefilter/error.h"
#include "render/scene_normals.h"

namespace posefilter {
namespace render {

void NormalsInRect(const DepthImage& d, const Camera& c, int u0, int v0, int u1, int v1, float* out) {
  for (int v = v0; v < v1; ++v)
    for (int u = u0; u < u1; ++u) {
      float* o = out + 3 * (std::size_t(v) * d.width + u);
      o[0] = o[1] = o[2] = 0.f;
      // No normal on the image border (a 4-neighbour is missing).
      if (u < 1 || v < 1 || u + 1 >= d.width || v + 1 >= d.height) continue;
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
      o[0] = float(nn.x());
      o[1] = float(nn.y());
      o[2] = float(nn.z());
    }
}

SceneNormalTiles::SceneNormalTiles(int width, int height)
    : width_(width),
      height_(height),
      tiles_u_((width + kTile - 1) / kTile),
      tiles_v_((height + kTile - 1) / kTile),
      normals_(new float[std::size_t(width) * height * 3]),
      done_(std::size_t(tiles_u_) * tiles_v_, 0) {}

void SceneNormalTiles::Prepare(const DepthImage& depth, const Camera& camera, const std::vector<PixelRect>& windows,
                               int threads) {
  if (depth.width != width_ || depth.height != height_) throw Error("SceneNormalTiles: depth image size changed");
  const int w = width_, h = height_;
  std::vector<int> todo;  // tile indices, each once
  for (const PixelRect& r : windows) {
    const int u0 = std::max(r.u0, 0), v0 = std::max(r.v0, 0);
    const int u1 = std::min(r.u0 + r.width, w), v1 = std::min(r.v0 + r.height, h);
    if (u0 >= u1 || v0 >= v1) continue;
    for (int tv = v0 / kTile; tv <= (v1 - 1) / kTile; ++tv)
      for (int tu = u0 / kTile; tu <= (u1 - 1) / kTile; ++tu) {
        std::uint8_t& done = done_[std::size_t(tv) * tiles_u_ + tu];
        if (done) continue;
        done = 1;
        todo.push_back(tv * tiles_u_ + tu);
      }
  }
  computed_ += int(todo.size());
  const int n = int(todo.size());
  const int nt = WorkerThreads(threads);
  // Tiles write disjoint pixels: any split over threads gives the same array.
  ParallelFor(nt, n, 1, [&](int, int i) {
    const int tu = todo[std::size_t(i)] % tiles_u_, tv = todo[std::size_t(i)] / tiles_u_;
    NormalsInRect(depth, camera, tu * kTile, tv * kTile, std::min((tu + 1) * kTile, w),
                  std::min((tv + 1) * kTile, h), normals_.get());
  });
}

}  // namespace render

std::vector<float> ComputeSceneNormals(const DepthImage& d, const Camera& c, int threads) {
  std::vector<float> n(std::size_t(d.width) * d.height * 3);
  // Rows are independent (each pixel writes only its own normal): threads over rows (blocks of
  // kNormalRowChunk; small images on the calling thread), same result.
  constexpr int kNormalRowChunk = 16;
  const int nt = d.height > 64 ? WorkerThreads(threads) : 1;
  ParallelFor(nt, d.height, kNormalRowChunk,
              [&](int, int v) { render::NormalsInRect(d, c, 0, v, d.width, v + 1, n.data()); });
  return n;
}

}  // namespace posefilter
