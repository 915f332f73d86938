// Rendering against analytic cases: area and depth of a fronto-parallel square, culling,
// the shared-edge rule, the soft inlier at its thresholds, and both z-buffer modes.
#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/render.h"
#include "render/raster.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::At;
using testing_util::FrontSquare;
using testing_util::PinholeCamera;

ScoreKernelParams Params(const Mesh& m, double z, const DepthImage& depth, PixelRect window) {
  ScoreKernelParams k;
  k.vertices = m.vertices[0].data();
  k.num_vertices = int(m.vertices.size());
  k.faces = m.faces[0].data();
  k.num_faces = int(m.faces.size());
  k.t[2] = float(z);
  k.fx = k.fy = 500;
  k.cx = 320;
  k.cy = 240;
  k.window = window;
  k.depth = depth.data.data();
  k.depth_width = depth.width;
  k.depth_height = depth.height;
  return k;
}

TEST(RenderTest, FrontoParallelSquareHasExpectedAreaAndDepth) {
  const Mesh sq = FrontSquare(0.1f);  // 10 cm at 1 m, f = 500 → 50 px wide
  DepthImage scene(640, 480, 1.0f);
  for (bool zbuffer : {true, false}) {
    ScoreKernelParams k = Params(sq, 1.0, scene, PixelRect{0, 0, 640, 480});
    k.zbuffer = zbuffer;
    RenderWorkspace ws;
    const ScoreKernelResult r = ScoreReference(k, &ws);
    // Pixel centres u in [295, 345): x_px = 320 ± 25 → 50 columns × 50 rows (edges at
    // exactly ±25 px: the left/top edge owns its pixels, the right/bottom does not).
    EXPECT_EQ(r.n_raster, 50 * 50) << "zbuffer=" << zbuffer;
    EXPECT_EQ(r.faces_front, 2);
    EXPECT_NEAR(r.inlier_sum, 2500.0, 1e-6);  // depth equals the scene everywhere
  }
  DepthImage z(640, 480, 0.f);
  RenderDepth(sq, At(0, 0, 1), PinholeCamera(500, 500), &z);
  EXPECT_EQ(z.CountValid(), 2500u);
  EXPECT_FLOAT_EQ(z.at(320, 240), 1.0f);
  EXPECT_FLOAT_EQ(z.at(295, 215), 1.0f);
  EXPECT_EQ(z.at(294, 240), 0.f);
  EXPECT_EQ(z.at(345, 240), 0.f);
}

TEST(RenderTest, TiltedPlaneDepthIsPerspectiveCorrect) {
  // A plane tilted about the y axis: exact depth at each pixel is the ray–plane intersection.
  Mesh sq = FrontSquare(0.2f);
  const Camera cam = PinholeCamera(500, 500);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0, 0, 0.8);
  DepthImage z(640, 480, 0.f);
  RenderDepth(sq, T, cam, &z);
  const Eigen::Vector3d n = T.linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d p0 = T.translation();
  int checked = 0;
  for (int v = 200; v < 280; v += 7)
    for (int u = 280; u < 360; u += 7) {
      if (z.at(u, v) == 0) continue;
      const Eigen::Vector3d ray((u - 320) / 500.0, (v - 240) / 500.0, 1.0);
      const double depth = n.dot(p0) / n.dot(ray);  // z of the intersection (ray.z = 1)
      EXPECT_NEAR(z.at(u, v), depth, 1e-5) << u << "," << v;
      ++checked;
    }
  EXPECT_GT(checked, 50);
}

TEST(RenderTest, BackFacesAreCulled) {
  Mesh sq = FrontSquare(0.1f);
  for (auto& f : sq.faces) std::swap(f[1], f[2]);  // now facing away from the camera
  DepthImage scene(640, 480, 1.0f);
  RenderWorkspace ws;
  const ScoreKernelResult r = ScoreReference(Params(sq, 1.0, scene, PixelRect{0, 0, 640, 480}), &ws);
  EXPECT_EQ(r.faces_front, 0);
  EXPECT_EQ(r.n_raster, 0);
}

TEST(RenderTest, SharedEdgesCoverEachPixelOnce) {
  // A fan of 16 triangles around a centre: without z-buffer every pixel must be counted once,
  // so the fragment count equals the covered-pixel count of the z-buffered render.
  Mesh fan;
  fan.vertices.push_back({0, 0, 0});
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n + 0.1;
    fan.vertices.push_back({float(0.07 * std::cos(a)), float(0.07 * std::sin(a)), 0});
  }
  for (int i = 0; i < n; ++i) fan.faces.push_back({0u, std::uint32_t(1 + (i + 1) % n), std::uint32_t(1 + i)});
  DepthImage scene(640, 480, 0.f);
  RenderWorkspace ws;
  ScoreKernelParams k = Params(fan, 0.9, scene, PixelRect{0, 0, 640, 480});
  k.zbuffer = true;
  const auto with_z = ScoreReference(k, &ws);
  k.zbuffer = false;
  const auto without_z = ScoreReference(k, &ws);
  EXPECT_EQ(with_z.faces_front, n);
  EXPECT_GT(with_z.n_raster, 3000);
  EXPECT_EQ(with_z.n_raster, without_z.n_raster);
  EXPECT_EQ(with_z.inlier_sum, 0.0);  // scene depth missing: never an inlier
}

TEST(RenderTest, WindowClipsAndZBufferKeepsNearestSurface) {
  // Two parallel squares, the nearer one at 0.9 m, the farther at 1.0 m (scene depth 1.0).
  Mesh two = FrontSquare(0.1f);
  Mesh back = FrontSquare(0.1f);
  for (auto& v : back.vertices) v.z() += 0.1f;
  for (auto f : back.faces) two.faces.push_back({f[0] + 4, f[1] + 4, f[2] + 4});
  two.vertices.insert(two.vertices.end(), back.vertices.begin(), back.vertices.end());
  DepthImage scene(640, 480, 1.0f);
  RenderWorkspace ws;
  // Window of 20×10 pixels inside both squares' silhouettes.
  ScoreKernelParams k = Params(two, 0.9, scene, PixelRect{310, 235, 20, 10});
  k.zbuffer = true;
  const auto zr = ScoreReference(k, &ws);
  EXPECT_EQ(zr.n_raster, 200);
  EXPECT_EQ(zr.inlier_sum, 0.0);  // nearest surface is 10 cm in front of the scene
  k.zbuffer = false;
  const auto nz = ScoreReference(k, &ws);
  EXPECT_EQ(nz.n_raster, 400);  // the thesis mode counts both layers (self-overlap error)
  EXPECT_NEAR(nz.inlier_sum, 200.0, 1e-9);
}

TEST(RenderTest, SoftInlierValuesAtThresholds) {
  InlierParams p;  // thr1 = 2^-8 m, thr2 = 2^-7 m
  EXPECT_EQ(SoftInlier(0.f, p), 1.f);
  EXPECT_EQ(SoftInlier(1.0f / 256, p), 1.f);            // χ = 1 at thr1 (continuous)
  EXPECT_NEAR(SoftInlier(1.5f / 256, p), 0.5f, 1e-6);   // mid-ramp
  EXPECT_NEAR(SoftInlier(1.0f / 256 + 1e-7f, p), 1.f, 1e-4);  // no jump to 0.5 (erratum)
  EXPECT_EQ(SoftInlier(2.0f / 256, p), 0.f);
  EXPECT_EQ(SoftInlier(0.1f, p), 0.f);
  p.hard = true;
  EXPECT_EQ(SoftInlier(0.005f, p), 1.f);
  EXPECT_EQ(SoftInlier(0.0051f, p), 0.f);
}

TEST(RenderTest, NearPlaneSkipsTriangles) {
  const Mesh sq = FrontSquare(0.1f);
  DepthImage scene(640, 480, 1.0f);
  RenderWorkspace ws;
  ScoreKernelParams k = Params(sq, 0.04, scene, PixelRect{0, 0, 640, 480});
  EXPECT_EQ(ScoreReference(k, &ws).faces_front, 0);
}

}  // namespace
}  // namespace posefilter
