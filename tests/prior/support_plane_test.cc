// The dominant (table) plane of a depth image (posefilter/support_plane.h).
#include "posefilter/support_plane.h"

#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/auto_prior.h"
#include "posefilter/room_world.h"
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

// ---- Support surfaces, plural (FindSupportSurfaces) ------------------------------------------

const TableWorld& SmallWorld() {
  static const TableWorld* w =
      new TableWorld({MakeBox(0.12, 0.08, 0.16, "box"), MakeCylinder(0.04, 0.14, 32, "cylinder"),
                      MakeBox(0.07, 0.07, 0.07, "cube"), MakeCylinder(0.03, 0.10, 24, "can")});
  return *w;
}

// Whether patch p lies in `plane` (camera frame, n up): normal within 5°, the centre of its
// outline within 1.5 cm of the plane.
bool LiesIn(const SupportSurface& p, const Eigen::Vector4d& plane) {
  Eigen::Vector2d m = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& q : p.outline) m += q;
  m /= double(p.outline.size());
  const Eigen::Vector3d c = p.origin + m.x() * p.e1 + m.y() * p.e2;
  return p.plane.normal.dot(plane.head<3>()) > std::cos(5 * M_PI / 180) && std::fabs(plane.head<3>().dot(c) + plane[3]) < 0.015;
}

// The index of the first of `count` patches that lies in `plane`, −1 for none.
int MatchingPatch(const SupportSurfaces& s, const Eigen::Vector4d& plane, int count) {
  for (int i = 0; i < count; ++i)
    if (LiesIn(s.patches[std::size_t(i)], plane)) return i;
  return -1;
}

// In rooms with the objects on one or two raised surfaces: every support surface of the scene
// is found as a support, parallel to the floor; each object's centre lies over its own
// support, which is the surface just below it; the stage 1's regions hold most of each
// target's visible pixels and stand on the target's support.
TEST(SupportSurfacesTest, FindsEveryRaisedSurfaceOfARoom) {
  int found = 0, total = 0, own = 0, objects = 0, held = 0, targets = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    RoomSceneOptions o;
    o.two_surfaces_probability = seed % 2 ? 1.0 : 0.0;
    o.shelf_probability = 0;
    o.max_objects = 3;
    const TableScene sc = MakeRoomScene(SmallWorld(), o, seed);
    const SupportSurfaces s = FindSupportSurfaces(sc.depth, sc.camera);
    ASSERT_GT(s.supports, 0);
    EXPECT_GT(s.up.dot(sc.floor_plane.head<3>()), std::cos(5 * M_PI / 180));
    for (const Eigen::Vector4d& plane : sc.supports) {
      ++total;
      found += MatchingPatch(s, plane, s.supports) >= 0;
    }
    std::vector<int> labels;
    const std::vector<CandidateRegion> regions = FindCandidateRegions(sc.depth, sc.camera, s, AutoPriorOptions{}, &labels);
    for (std::size_t i = 0; i < sc.objects.size(); ++i) {
      const TableObject& obj = sc.objects[i];
      const int below = s.Below(obj.T_cam_obj.translation(), SupportSurfaceOptions{});
      ++objects;
      own += below >= 0 && LiesIn(s.patches[std::size_t(below)], sc.supports[std::size_t(obj.support)]);
      if (!obj.target) continue;
      int visible = 0, in_region = 0;
      for (std::size_t q = 0; q < labels.size(); ++q)
        if (sc.labels[q] == int(i) + 1 && sc.depth.data[q] > 0) ++visible, in_region += labels[q] > 0;
      ++targets;
      held += in_region > 0.8 * visible;
    }
  }
  // One surface of these scenes is missed today (docs/ALGORITHM.md §16), two in the clang build
  // (the sanitizer preset), whose float rounding draws other RANSAC planes: their objects have
  // no support.
  EXPECT_GE(found, total - 2);
  EXPECT_GE(own, objects - 2);
  EXPECT_GE(held, targets - 1);
}

TEST(SupportSurfacesTest, BadOptionsAreErrors) {
  SupportSurfaceOptions o;
  o.max_tilt_deg = 90;
  testing_util::ExpectInvalid(o, "max_tilt_deg");
  o = {};
  o.min_area_m2 = 0;
  testing_util::ExpectInvalid(o, "min_area_m2");
  o = {};
  o.plane.iterations = 0;
  testing_util::ExpectInvalid(o, "plane: iterations");
  const Camera cam = testing_util::PinholeCamera(500, 500);
  testing_util::ExpectError([&] { FindSupportSurfaces(DepthImage(10, 10, 1.f), cam); }, {"size"});
  EXPECT_EQ(FindSupportSurfaces(DepthImage(cam.width, cam.height, 0.f), cam).supports, 0);
}

}  // namespace
}  // namespace posefilter
