// The dominant (table) plane of a depth image (posefilter/support_plane.h).
#include "posefilter/support_plane.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "posefilter/auto_prior.h"
#include "posefilter/room_world.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"
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

// On the table world's scenes (the 21 YCB-Video meshes of the shared data; skipped without
// them) the table is a support and gives up. Seed 222: a plane of the table's own noise left
// in the pool grazed the table, and its footprint area outvoted the table's for up, so the
// table was taken for structure and the scene had no stage-1 region.
TEST(SupportSurfacesTest, TheTableOfTheTableWorldIsASupport) {
  const auto models = testing_util::YcbvDataDir() / "models";
  if (!std::filesystem::exists(models)) GTEST_SKIP() << "no YCB-Video meshes at " << models;
  const TableWorld w = TableWorld::LoadYcbVideo(models.string());
  for (std::uint64_t seed : {201, 205, 217, 222, 230}) {
    const TableScene sc = w.MakeScene({}, seed);
    const SupportSurfaces s = FindSupportSurfaces(sc.depth, sc.camera);
    ASSERT_GT(s.supports, 0) << "seed " << seed;
    EXPECT_GT(s.up.dot(sc.table_plane.head<3>()), std::cos(5 * M_PI / 180)) << "seed " << seed;
    EXPECT_GE(MatchingPatch(s, sc.table_plane, s.supports), 0) << "seed " << seed;
  }
}

// A camera 1.3 m above a floor, looking down 50°, over a 20 × 14 cm tablet 0.7 m up whose
// middle 6 cm are hidden by a dark object (no depth): two pieces of the tablet, each under
// min_area_m2, both together over it. The tablet is tilted by `tilt_deg` about the image's x
// axis. Camera frame; `up` is the floor's normal.
DepthImage TabletSceneDepth(const Camera& cam, double tilt_deg, Eigen::Vector3d* up) {
  const double a = 50 * M_PI / 180;
  *up = Eigen::Vector3d(0, -std::cos(a), -std::sin(a));
  const Eigen::Vector3d e1(1, 0, 0), e2 = up->cross(e1);
  const Eigen::Vector3d centre(0, 0, 0.6 / std::sin(a));  // on the optical axis, 0.7 m up
  const Eigen::Vector3d nt = Eigen::AngleAxisd(tilt_deg * M_PI / 180, e1) * *up;
  DepthImage depth(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d r = cam.Backproject(u, v, 1.0);
      double z = 0;
      if (nt.dot(r) < 0) {  // the tablet's plane: nt·(x − centre) = 0
        const Eigen::Vector3d x = r * (nt.dot(centre) / nt.dot(r));
        const double s = (x - centre).dot(e1), t = (x - centre).dot(e2);
        if (std::fabs(s) <= 0.1 && std::fabs(t) <= 0.07) z = std::fabs(s) <= 0.03 ? -1 : x.z();
      }
      if (z == 0 && up->dot(r) < 0) z = (-1.3 / up->dot(r)) * r.z();  // the floor: up·x = −1.3
      if (z > 0 && z < 4) depth.at(u, v) = float(z);
    }
  return depth;
}

// The two pieces are one support, level with the floor (the tablet's 1° tilt is the kind of
// tilt a small patch's fit gets from the sensor's correlated noise), at the tablet's height;
// with merge_gap_m = 0 each piece is too small and the tablet is not found.
TEST(SupportSurfacesTest, ATabletCutApartByItsObjectIsOneLevelSupport) {
  const Camera cam = testing_util::PinholeCamera(525, 525);
  Eigen::Vector3d up;
  const DepthImage depth = TabletSceneDepth(cam, 1.0, &up);
  const Eigen::Vector3d centre(0, 0, 0.6 / std::sin(50 * M_PI / 180));
  auto tablet_of = [&](const SupportSurfaces& s) {
    for (int i = 0; i < s.supports; ++i)
      if (std::fabs(s.patches[std::size_t(i)].plane.Height(centre)) < 0.01) return i;
    return -1;
  };
  const SupportSurfaces s = FindSupportSurfaces(depth, cam);
  ASSERT_EQ(s.supports, 2);
  EXPECT_GT(s.up.dot(up), std::cos(0.1 * M_PI / 180));
  const int tablet = tablet_of(s);
  ASSERT_GE(tablet, 0);
  const SupportSurface& t = s.patches[std::size_t(tablet)];
  EXPECT_GT(t.plane.normal.dot(up), std::cos(0.1 * M_PI / 180));  // level, not tilted by 1°
  EXPECT_NEAR(t.plane.Height(centre), 0.0, 0.002);
  EXPECT_TRUE(t.Over(centre, 0.0));  // the hidden middle lies inside the outline
  EXPECT_EQ(s.Below(centre + 0.05 * up, SupportSurfaceOptions{}), tablet);
  SupportSurfaceOptions apart;
  apart.merge_gap_m = 0;
  EXPECT_LT(tablet_of(FindSupportSurfaces(depth, cam, apart)), 0);
}

TEST(SupportSurfacesTest, HullDistanceOfConvexPolygons) {
  const std::vector<Eigen::Vector2d> a = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<Eigen::Vector2d> b = a;
  for (Eigen::Vector2d& q : b) q += Eigen::Vector2d(1.5, 0.5);
  EXPECT_NEAR(HullDistance(a, b), 0.5, 1e-12);
  EXPECT_NEAR(HullDistance(b, a), 0.5, 1e-12);
  for (Eigen::Vector2d& q : b) q -= Eigen::Vector2d(1.0, 0.0);  // overlapping
  EXPECT_EQ(HullDistance(a, b), 0.0);
  EXPECT_GT(HullDistance(a, {}), 1e29);
}

TEST(SupportSurfacesTest, BadOptionsAreErrors) {
  SupportSurfaceOptions o;
  o.max_tilt_deg = 90;
  testing_util::ExpectInvalid(o, "max_tilt_deg");
  o = {};
  o.min_area_m2 = 0;
  testing_util::ExpectInvalid(o, "min_area_m2");
  o = {};
  o.merge_gap_m = -1;
  testing_util::ExpectInvalid(o, "merge_gap_m");
  o = {};
  o.plane.iterations = 0;
  testing_util::ExpectInvalid(o, "plane: iterations");
  const Camera cam = testing_util::PinholeCamera(500, 500);
  testing_util::ExpectError([&] { FindSupportSurfaces(DepthImage(10, 10, 1.f), cam); }, {"size"});
  EXPECT_EQ(FindSupportSurfaces(DepthImage(cam.width, cam.height, 0.f), cam).supports, 0);
}

}  // namespace
}  // namespace posefilter
