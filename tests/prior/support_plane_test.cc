// The dominant (table) plane of a depth image (posefilter/support_plane.h).
#include "posefilter/support_plane.h"

#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

// On a synthetic table-top scene the plane found is the table: its normal is the scene's
// table normal, nearly all table pixels are on it and nearly no object pixel is.
TEST(SupportPlaneTest, FindsTheTableOfASyntheticScene) {
  SynthOptions so;
  so.target = "box";
  so.occlusion = 0.3;
  const SynthScene sc = MakeSynthScene(so, 5);
  const SupportPlane p = FindSupportPlane(sc.depth, sc.camera);
  ASSERT_TRUE(p.found);
  const Eigen::Vector3d up(0, -std::cos(sc.table_angle_rad), -std::sin(sc.table_angle_rad));  // synth.h's table normal
  EXPECT_GT(p.normal.dot(up), 0.999);
  EXPECT_GT(p.fraction, 0.5);
  EXPECT_GT(p.sigma_1m, 0.0);
  EXPECT_LT(p.sigma_1m, 0.005);
  const std::vector<std::uint8_t> on = SupportPlanePixels(sc.depth, sc.camera, p);
  int table = 0, table_on = 0, target = 0, target_on = 0;
  for (std::size_t i = 0; i < on.size(); ++i) {
    if (!(sc.depth.data[i] > 0)) {
      EXPECT_EQ(on[i], 0);  // a missing pixel is never on the plane
      continue;
    }
    if (sc.labels[i] == 0) ++table, table_on += on[i];
    if (sc.labels[i] == 1) ++target, target_on += on[i];
  }
  EXPECT_GT(double(table_on) / table, 0.97);
  EXPECT_LT(double(target_on) / target, 0.05);
  // Deterministic.
  const SupportPlane q = FindSupportPlane(sc.depth, sc.camera);
  EXPECT_EQ(p.normal, q.normal);
  EXPECT_EQ(p.offset, q.offset);
}

// A scene without a dominant plane (a sphere filling the view) has none; an empty image has
// none; a size mismatch or bad options are errors.
TEST(SupportPlaneTest, NoPlaneNoErrorButBadInputsAreErrors) {
  const Camera cam = testing_util::PinholeCamera(500, 500);
  DepthImage sphere(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      // Ray-sphere intersection, sphere of radius 0.6 m at 1 m.
      const Eigen::Vector3d d = cam.Backproject(u, v, 1.0).normalized();
      const double b = d.z() * 1.0, disc = b * b - (1.0 - 0.36);
      if (disc > 0) sphere.at(u, v) = float((b - std::sqrt(disc)) * d.z());
    }
  EXPECT_FALSE(FindSupportPlane(sphere, cam).found);
  EXPECT_FALSE(FindSupportPlane(DepthImage(cam.width, cam.height, 0.f), cam).found);
  testing_util::ExpectError([&] { FindSupportPlane(DepthImage(10, 10, 1.f), cam); }, {"size"});
  SupportPlaneOptions o;
  o.min_fraction = 0;
  testing_util::ExpectInvalid(o, "min_fraction");
  o = {};
  o.max_band_m = 0.001;
  testing_util::ExpectInvalid(o, "band");
}

}  // namespace
}  // namespace posefilter
