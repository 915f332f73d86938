// Table-top scenes of real meshes seen by the structured-light sensor model
// (posefilter/table_world.h).
#include "posefilter/table_world.h"
#include "posefilter/room_world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::ExpectInvalid;

const TableWorld& World() {
  static const TableWorld* w =
      new TableWorld({MakeBox(0.12, 0.08, 0.16, "box"), MakeCylinder(0.04, 0.14, 32, "cylinder"),
                      MakeLShape(0.14, 0.05, 0.06, "lshape"), MakeTorus(0.06, 0.025, 24, 16, "torus"),
                      MakeBox(0.18, 0.08, 0.012, "plate")});
  return *w;
}

TableScene Scene(std::uint64_t seed) {
  TableSceneOptions o;
  o.min_objects = 3;
  o.max_objects = 5;
  return World().MakeScene(o, seed);
}

TEST(TableWorldTest, TheSameSeedMakesTheSameScene) {
  const TableScene a = Scene(7), b = Scene(7), c = Scene(8);
  EXPECT_EQ(a.depth.data, b.depth.data);
  EXPECT_EQ(a.masks, b.masks);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) EXPECT_EQ(a.objects[i].T_cam_obj.matrix(), b.objects[i].T_cam_obj.matrix());
  EXPECT_NE(a.depth.data, c.depth.data);
}

// Every object rests on the table in a stable pose: its lowest point on the plane, the
// plane facing the camera, objects of distinct classes, none inside another, the camera
// 0.6–1.3 m from the group.
TEST(TableWorldTest, ObjectsRestOnTheTableInStablePoses) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const TableScene s = Scene(seed);
    ASSERT_GE(s.objects.size(), 3u);
    const Eigen::Vector3d n = s.table_plane.head<3>();
    EXPECT_NEAR(n.norm(), 1.0, 1e-9);
    EXPECT_GT(s.table_plane[3], 0.0);  // the camera is above the table
    EXPECT_GE(s.distance_m, 0.6);
    EXPECT_LE(s.distance_m, 1.3);
    std::vector<std::string> classes;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      const TableObject& o = s.objects[i];
      classes.push_back(o.cls);
      const Mesh& m = World().models()[std::size_t(o.model)].mesh;
      double lowest = 1e30;
      for (const auto& v : m.vertices) lowest = std::min(lowest, n.dot(o.T_cam_obj * v.cast<double>()) + s.table_plane[3]);
      EXPECT_NEAR(lowest, 0.0, 1e-4) << o.cls;
      // No other object's centre lies within this object's footprint radius of its centre.
      for (std::size_t j = 0; j < i; ++j)
        EXPECT_GT((o.T_cam_obj.translation() - s.objects[j].T_cam_obj.translation()).norm(), 0.02);
    }
    std::sort(classes.begin(), classes.end());
    EXPECT_EQ(std::unique(classes.begin(), classes.end()), classes.end());
  }
}

// The sensor model: depth rounded to 1 mm, missing depth where the sensor loses it (a few
// percent up to a third of the image), noise of a few millimetres that grows with depth.
TEST(TableWorldTest, TheSensorModelRoundsDropsAndAddsNoiseGrowingWithDepth) {
  const TableScene s = Scene(3);
  int valid = 0, lost = 0;
  std::vector<std::pair<double, double>> err;  // (clean z, |z − clean z|) on the table
  for (std::size_t i = 0; i < s.depth.data.size(); ++i) {
    const float z = s.depth.data[i], c = s.clean_depth.data[i];
    if (c <= 0) continue;
    if (z <= 0) {
      ++lost;
      continue;
    }
    ++valid;
    EXPECT_NEAR(z * 1000, std::round(z * 1000), 1e-3);
    if (s.labels[i] == 0) err.push_back({c, std::fabs(z - c)});
  }
  const double lost_fraction = double(lost) / (valid + lost);
  EXPECT_GT(lost_fraction, 0.01);
  EXPECT_LT(lost_fraction, 0.35);
  std::sort(err.begin(), err.end());
  auto median_error = [](std::vector<std::pair<double, double>>::const_iterator a, std::vector<std::pair<double, double>>::const_iterator b) {
    std::vector<double> e;
    for (auto it = a; it != b; ++it) e.push_back(it->second);
    std::nth_element(e.begin(), e.begin() + std::ptrdiff_t(e.size() / 2), e.end());
    return e[e.size() / 2];
  };
  const auto third = std::ptrdiff_t(err.size() / 3);
  const double near = median_error(err.begin(), err.begin() + third), far = median_error(err.end() - third, err.end());
  EXPECT_GT(near, 0.0001);
  EXPECT_LT(far, 0.01);
  EXPECT_GT(far, near);
}

// Targets have a jittered detection each (first, in object order), then the false boxes; a
// target's instance mask covers its visible pixels up to the outline's noise.
TEST(TableWorldTest, DetectionsAndMasksOfTheTargets) {
  const TableScene s = Scene(5);
  int targets = 0;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const TableObject& o = s.objects[i];
    if (!o.target) {
      EXPECT_EQ(std::count(s.masks.begin(), s.masks.end(), std::uint16_t(i + 1)), 0);
      continue;
    }
    ASSERT_LT(std::size_t(targets), s.detections.size());
    const Detection& d = s.detections[std::size_t(targets++)];
    EXPECT_EQ(d.cls, o.cls);
    EXPECT_GT(BoxIoU(DetectionBox(d), o.box), 0.5);
    int both = 0, either = 0;
    for (std::size_t q = 0; q < s.masks.size(); ++q) {
      const bool in_mask = s.masks[q] == i + 1, in_label = s.labels[q] == int(i) + 1;
      both += in_mask && in_label;
      either += in_mask || in_label;
    }
    EXPECT_GT(double(both) / either, 0.6) << o.cls;
  }
  EXPECT_GT(targets, 0);
  EXPECT_EQ(s.detections.size(), std::size_t(targets + 2));  // two false boxes by default
}

TEST(TableWorldTest, BadOptionsAndMeshesAreErrors) {
  TableSceneOptions o;
  o.min_objects = 0;
  ExpectInvalid(o, "min_objects");
  o = {};
  o.max_distance_m = 0.5;
  ExpectInvalid(o, "distance");
  o = {};
  o.sensor.hole_fraction = 0.9;
  ExpectInvalid(o, "sensor.hole_fraction");
  o = {};
  o.max_objects = 6;
  ExpectError([&] { World().MakeScene(o, 1); }, {"max_objects", "5 classes"});
  ExpectError([] { TableWorld({MakeBox(0.1, 0.1, 0.1, "a"), MakeBox(0.1, 0.1, 0.1, "a")}); }, {"'a'", "twice"});
  ExpectError([] { TableWorld::LoadYcbVideo("/nonexistent/models"); }, {"/nonexistent/models"});
}

// A BOP ycbv models folder (obj_000001.ply … obj_000021.ply, millimetres) is read as the same
// world: class i + 1's mesh, scaled to metres and named by its class; a missing id is named.
TEST(TableWorldTest, ABopModelsFolderIsReadInMillimetres) {
  testing_util::ScratchDir dir("table_world_bop");
  const std::vector<std::string> classes = YcbVideoClassNames();
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const double mm = 40.0 + 5.0 * double(i);  // one box size per class
    char name[32];
    std::snprintf(name, sizeof name, "obj_%06zu.ply", i + 1);
    SaveMeshPly(MakeBox(mm, mm, 2 * mm, "b"), dir.Path(name));
  }
  const TableWorld w = TableWorld::LoadYcbVideo(dir.dir().string());
  ASSERT_EQ(w.models().size(), classes.size());
  for (std::size_t i = 0; i < classes.size(); ++i) {
    EXPECT_EQ(w.models()[i].mesh.name, classes[i]);
    const double m = (40.0 + 5.0 * double(i)) / 1000.0;
    EXPECT_NEAR(w.models()[i].diameter, std::sqrt(6.0) * m, 1e-6) << classes[i];
  }
  std::filesystem::remove(dir.Path("obj_000007.ply"));
  ExpectError([&] { TableWorld::LoadYcbVideo(dir.dir().string()); }, {classes[6] + ".ply", "obj_000007.ply"});
}

// The 21 YCB-Video meshes of the shared data (skipped without them): every class has stable
// poses, and a scene of them writes every file a peer reads.
TEST(TableWorldTest, TheYcbVideoWorldWritesItsScenes) {
  const auto models = testing_util::YcbvDataDir() / "models";
  if (!std::filesystem::exists(models)) GTEST_SKIP() << "no YCB-Video meshes at " << models;
  const TableWorld w = TableWorld::LoadYcbVideo(models.string());
  ASSERT_EQ(w.models().size(), 21u);
  for (const TableModel& m : w.models()) EXPECT_FALSE(m.poses.empty()) << m.mesh.name;
  const TableScene s = w.MakeScene({}, 1);
  testing_util::ScratchDir dir("table_world");
  WriteTableScene(s, dir.Path("scene"));
  for (const char* f : {"depth.png", "camera.json", "gt.json", "detections.json", "prior.pyr", "classes.txt", "mask.png", "mask_classes.json",
                        "label.png", "rgb.png", "scene.json"})
    EXPECT_TRUE(std::filesystem::exists(dir.dir() / "scene" / f)) << f;
}

// ---- The room world (posefilter/room_world.h) ----------------------------------------------

TableScene Room(std::uint64_t seed, double two_surfaces = 0.3, double shelf = 0.25) {
  RoomSceneOptions o;
  o.two_surfaces_probability = two_surfaces;
  o.shelf_probability = shelf;
  return MakeRoomScene(World(), o, seed);
}

// The height of the lowest vertex of object o above plane (camera frame, n up), metres.
double LowestAbove(const TableObject& o, const Eigen::Vector4d& plane) {
  double lowest = 1e30;
  for (const auto& v : World().models()[std::size_t(o.model)].mesh.vertices)
    lowest = std::min(lowest, plane.head<3>().dot(o.T_cam_obj * v.cast<double>()) + plane[3]);
  return lowest;
}

TEST(RoomWorldTest, TheSameSeedMakesTheSameRoom) {
  const TableScene a = Room(11), b = Room(11), c = Room(12);
  EXPECT_EQ(a.depth.data, b.depth.data);
  EXPECT_EQ(a.masks, b.masks);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) EXPECT_EQ(a.objects[i].T_cam_obj.matrix(), b.objects[i].T_cam_obj.matrix());
  EXPECT_NE(a.depth.data, c.depth.data);
}

// Every object rests on its support surface, 0.4–1.2 m above the floor and parallel to it;
// the camera is 0.5–1.5 m from the objects, looking down 15–60°; the supports cover 5–40 %
// of the view in most scenes; the floor, walls and furniture fill much of the rest, the
// background reaching metres beyond the objects; with two surfaces both hold objects.
TEST(RoomWorldTest, ObjectsRestOnRaisedSurfacesInARoom) {
  int in_range = 0, scenes = 0, two = 0, far_background = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const TableScene s = Room(seed, seed % 2 ? 1.0 : 0.0, seed == 2 ? 1.0 : 0.0);
    ++scenes;
    ASSERT_FALSE(s.objects.empty());
    ASSERT_EQ(s.supports.size(), s.support_view_fractions.size());
    EXPECT_GE(s.distance_m, 0.5);
    EXPECT_LE(s.distance_m, 1.5);
    EXPECT_GE(s.elevation_deg, 15);
    EXPECT_LE(s.elevation_deg, 60);
    const Eigen::Vector3d up = s.floor_plane.head<3>();
    EXPECT_NEAR(up.norm(), 1.0, 1e-9);
    for (const Eigen::Vector4d& p : s.supports) {
      EXPECT_GT(p.head<3>().dot(up), std::cos(1e-6));  // horizontal
      const double height = s.floor_plane[3] - p[3];    // the surface's height above the floor
      EXPECT_GE(height, 0.4 - 1e-9);
      EXPECT_LE(height, 1.2 + 1e-9);
    }
    std::vector<int> on(s.supports.size(), 0);
    for (const TableObject& o : s.objects) {
      ASSERT_GE(o.support, 0);
      ASSERT_LT(std::size_t(o.support), s.supports.size());
      EXPECT_NEAR(LowestAbove(o, s.supports[std::size_t(o.support)]), 0.0, 1e-4) << o.cls;
      ++on[std::size_t(o.support)];
    }
    for (int n : on) EXPECT_GT(n, 0) << "a support without objects, seed " << seed;
    if (s.supports.size() == 2) {
      ++two;
      EXPECT_GE(std::fabs(s.supports[0][3] - s.supports[1][3]), 0.1 - 1e-9);
    }
    double view = 0;
    for (double f : s.support_view_fractions) view += f;
    in_range += view >= 0.05 && view <= 0.4;
    // Depth well beyond the objects (floor, walls, furniture): at least 1 m farther than they are.
    int far = 0;
    for (float z : s.clean_depth.data) far += z > s.distance_m + 1.0;
    far_background += far > int(s.clean_depth.data.size() / 20);
  }
  EXPECT_GE(in_range, scenes - 1);
  EXPECT_GE(two, 1);
  EXPECT_GE(far_background, scenes / 2);
}

// The same targets, boxes and masks as the table world.
TEST(RoomWorldTest, TargetsHaveBoxesAndMasks) {
  const TableScene s = Room(3);
  int targets = 0;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const TableObject& o = s.objects[i];
    if (!o.target) continue;
    const Detection& d = s.detections[std::size_t(targets++)];
    EXPECT_EQ(d.cls, o.cls);
    EXPECT_GT(BoxIoU(DetectionBox(d), o.box), 0.5);
    EXPECT_GT(std::count(s.masks.begin(), s.masks.end(), std::uint16_t(i + 1)), 0);
  }
  EXPECT_GT(targets, 0);
  EXPECT_EQ(s.detections.size(), std::size_t(targets + 2));
}

// Seed 110 of the room world with the YCB-Video meshes (skipped without them): its first
// layout shows no object well enough, so the seed's later streams draw it again.
TEST(RoomWorldTest, ASeedWhoseFirstLayoutShowsNoObjectIsDrawnAgain) {
  const auto models = testing_util::YcbvDataDir() / "models";
  if (!std::filesystem::exists(models)) GTEST_SKIP() << "no YCB-Video meshes at " << models;
  const TableWorld w = TableWorld::LoadYcbVideo(models.string());
  const TableScene a = MakeRoomScene(w, RoomSceneOptions{}, 110);
  EXPECT_GT(std::count_if(a.objects.begin(), a.objects.end(), [](const TableObject& o) { return o.target; }), 0);
}

// Where no layout gives a scene (a 2 m crate fits on no support), the error names the seed.
TEST(RoomWorldTest, NoLayoutGivingASceneIsAnErrorNamingTheSeed) {
  RoomSceneOptions one;
  one.min_objects = one.max_objects = 1;
  ExpectError([&] { MakeRoomScene(TableWorld({MakeBox(2, 2, 2, "crate")}), one, 3); }, {"room scene 3", "8 layouts"});
}

TEST(RoomWorldTest, BadOptionsAreErrors) {
  RoomSceneOptions o;
  o.min_surface_height_m = 0.05;
  ExpectInvalid(o, "min_surface_height_m");
  o = {};
  o.max_surface_view = 0.01;
  ExpectInvalid(o, "max_surface_view");
  o = {};
  o.max_furniture = 1;
  ExpectInvalid(o, "max_furniture");
  o = {};
  o.two_surfaces_probability = 2;
  ExpectInvalid(o, "two_surfaces_probability");
  o = {};
  o.max_objects = 6;
  ExpectError([&] { MakeRoomScene(World(), o, 1); }, {"max_objects", "5 classes"});
}

}  // namespace
}  // namespace posefilter
