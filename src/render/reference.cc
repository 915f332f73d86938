// The reference score kernel and the full-image depth renderer (readable float/int64 C++).
#include <cmath>
#include <limits>

#include "render/raster.h"

namespace posefilter {
namespace {

// One rendered fragment at depth z against the scene depth zs (0 = missing: never an inlier).
// One rendered fragment at pixel (u, v), depth z, against the scene depth zs there.
inline void Compare(int u, int v, float z, float zs, const ScoreKernelParams& k, ScoreKernelResult* r) {
  if (zs <= 0) return;
  const float d = zs - z;
  const float chi = SoftInlier(std::fabs(d), k.inlier);
  r->inlier_sum += chi;
  if (chi == 0.f && d < 0) ++r->n_occluded;
  if (std::fabs(d) > k.align_band_m) return;
  r->depth_diff_sum += d;
  ++r->depth_diff_count;
  if (!k.scene_normals) return;
  // Point-to-plane ICP with projective association: rendered point p, scene point q on the
  // same pixel, scene normal n; linearised residual (q − p)·n against a small motion
  // (ω, τ) of the object in the camera frame: J = [p × n; n], A += J·Jᵀ, b += J·r.
  const float* nn = k.scene_normals + 3 * (std::size_t(v) * k.depth_width + u);
  if (nn[0] == 0.f && nn[1] == 0.f && nn[2] == 0.f) return;
  const double x = (u - k.cx) / k.fx, y = (v - k.cy) / k.fy;
  const double p[3] = {x * z, y * z, z};
  const double n[3] = {nn[0], nn[1], nn[2]};
  const double res = d * n[2] + (x * d) * n[0] + (y * d) * n[1];  // (q − p)·n, q − p = d·(x, y, 1)
  const double J[6] = {p[1] * n[2] - p[2] * n[1], p[2] * n[0] - p[0] * n[2], p[0] * n[1] - p[1] * n[0],
                       n[0], n[1], n[2]};
  int e = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) r->icp_A[e++] += J[i] * J[j];
    r->icp_b[i] += J[i] * res;
  }
  ++r->icp_count;
}

}  // namespace

ScoreKernelResult ScoreReference(const ScoreKernelParams& k, RenderWorkspace* ws) {
  ScoreKernelResult r;
  r.faces_total = k.num_faces;
  const PixelRect& w = k.window;
  if (w.width <= 0 || w.height <= 0) return r;
  ws->cam_vertices.resize(std::size_t(k.num_vertices) * 3);
  render::TransformVertices(k, ws->cam_vertices.data());
  auto scene_depth = [&](int u, int v) { return k.depth[std::size_t(v) * k.depth_width + u]; };

  if (k.zbuffer) {
    // Exact z-buffer over the window: only the nearest fragment of each pixel counts.
    constexpr float kEmpty = std::numeric_limits<float>::infinity();
    ws->zbuffer.assign(std::size_t(w.Area()), kEmpty);
    float* zb = ws->zbuffer.data();
    r.faces_front = render::RasterizeMesh(k, ws->cam_vertices.data(), w, [&](int u, int v, float z) {
      float& cell = zb[std::size_t(v - w.v0) * w.width + (u - w.u0)];
      if (z < cell) cell = z;
    });
    for (int v = 0; v < w.height; ++v) {
      for (int u = 0; u < w.width; ++u) {
        const float z = zb[std::size_t(v) * w.width + u];
        if (z == kEmpty) continue;
        ++r.n_raster;
        Compare(w.u0 + u, w.v0 + v, z, scene_depth(w.u0 + u, w.v0 + v), k, &r);
        // Silhouette edge test: an uncovered 4-neighbour (inside the window) with valid scene
        // depth is an edge sample; it is "continued" when the scene surface there lies
        // within edge_band_m of this boundary pixel's rendered depth — no depth step where
        // the object's outline claims one.
        static constexpr int kDu[4] = {-1, 1, 0, 0}, kDv[4] = {0, 0, -1, 1};
        for (int n = 0; n < 4; ++n) {
          const int un = u + kDu[n], vn = v + kDv[n];
          if (un < 0 || vn < 0 || un >= w.width || vn >= w.height) continue;
          if (zb[std::size_t(vn) * w.width + un] != kEmpty) continue;
          const float zs = scene_depth(w.u0 + un, w.v0 + vn);
          ++r.n_edge;  // a missing reading next to the outline is a discontinuity: not continued
          if (zs > 0 && std::fabs(zs - z) <= k.edge_band_m) ++r.n_edge_continued;
        }
      }
    }
  } else {
    // Thesis mode (§7.5.1): no z-buffer, every front-face fragment is compared directly.
    r.faces_front = render::RasterizeMesh(k, ws->cam_vertices.data(), w, [&](int u, int v, float z) {
      ++r.n_raster;
      Compare(u, v, z, scene_depth(u, v), k, &r);
    });
  }
  return r;
}

ScoreKernelParams MakeKernelParams(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera) {
  ScoreKernelParams k;
  k.vertices = mesh.vertices.empty() ? nullptr : mesh.vertices[0].data();
  k.num_vertices = int(mesh.vertices.size());
  k.faces = mesh.faces.empty() ? nullptr : mesh.faces[0].data();
  k.num_faces = int(mesh.faces.size());
  const Eigen::Matrix3d R = T_cam_obj.linear();
  for (int i = 0; i < 9; ++i) k.R[i] = float(R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) k.t[i] = float(T_cam_obj.translation()[i]);
  k.fx = float(camera.fx);
  k.fy = float(camera.fy);
  k.cx = float(camera.cx);
  k.cy = float(camera.cy);
  k.window = PixelRect{0, 0, camera.width, camera.height};
  return k;
}

void RenderDepth(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera,
                 DepthImage* depth, std::vector<int>* labels, int label) {
  if (depth->width != camera.width || depth->height != camera.height) {
    *depth = DepthImage(camera.width, camera.height, 0.f);
  }
  if (labels && labels->size() != std::size_t(camera.width) * camera.height) {
    labels->assign(std::size_t(camera.width) * camera.height, 0);
  }
  const ScoreKernelParams k = MakeKernelParams(mesh, T_cam_obj, camera);
  std::vector<float> cam(std::size_t(k.num_vertices) * 3);
  render::TransformVertices(k, cam.data());
  render::RasterizeMesh(k, cam.data(), k.window, [&](int u, int v, float z) {
    float& d = depth->at(u, v);
    if (d == 0.f || z < d) {
      d = z;
      if (labels) (*labels)[std::size_t(v) * camera.width + u] = label;
    }
  });
}

}  // namespace posefilter
