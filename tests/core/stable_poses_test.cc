// Convex hull, centre of mass and stable poses (posefilter/stable_poses.h).
#include "posefilter/stable_poses.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "posefilter/mesh.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

// The lowest vertex of `mesh` at T_table_obj, and the number of vertices within 0.1 mm of it.
double LowestZ(const Mesh& mesh, const Eigen::Isometry3d& T, int* on_table) {
  double lo = 1e30;
  for (const auto& v : mesh.vertices) lo = std::min(lo, (T * v.cast<double>()).z());
  *on_table = 0;
  for (const auto& v : mesh.vertices) *on_table += (T * v.cast<double>()).z() < lo + 1e-4;
  return lo;
}

TEST(ConvexHullTest, ABoxHasSixFacesOfItsAreas) {
  const Mesh box = MakeBox(0.1, 0.2, 0.3);
  std::vector<Eigen::Vector3d> pts;
  for (const auto& v : box.vertices) pts.push_back(v.cast<double>());
  const ConvexHull h = ComputeConvexHull(pts);
  ASSERT_EQ(h.faces.size(), 6u);  // coplanar triangles merged
  EXPECT_EQ(h.vertices.size(), 8u);
  EXPECT_NEAR(h.volume, 0.1 * 0.2 * 0.3, 1e-8);
  EXPECT_LT(h.centroid.norm(), 1e-7);
  std::vector<double> areas;
  for (const auto& f : h.faces) {
    EXPECT_EQ(f.polygon.size(), 4u);
    EXPECT_NEAR(f.normal.norm(), 1.0, 1e-9);
    areas.push_back(f.area);
  }
  std::sort(areas.begin(), areas.end());
  const std::vector<double> expected = {0.02, 0.02, 0.03, 0.03, 0.06, 0.06};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(areas[i], expected[i], 1e-7);  // float vertices
}

TEST(ConvexHullTest, FlatOrTooFewPointsAreErrorsNamingThem) {
  ExpectError([] { ComputeConvexHull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, "mesh 'tri'"); }, {"mesh 'tri'", "at least 4"});
  ExpectError([] { ComputeConvexHull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0}}, "mesh 'flat'"); },
              {"mesh 'flat'", "flat: every vertex lies in one plane", "1.41 m across", "no volume"});
  // A tilted plane and a line are flat too; a thin but solid slab is not.
  ExpectError([] { ComputeConvexHull({{0, 0, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 2}}, "tilted"); }, {"tilted", "flat"});
  ExpectError([] { ComputeConvexHull({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, "line"); }, {"line", "flat"});
  EXPECT_GT(ComputeConvexHull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0.001}}, "slab").volume, 0.0);
  ExpectError([] { ComputeConvexHull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, NAN}}, "pts"); }, {"pts", "not finite"});
}

TEST(CentreOfMassTest, SolidsAndOpenSurfaces) {
  Mesh box = MakeBox(0.1, 0.2, 0.3);
  for (auto& v : box.vertices) v += Eigen::Vector3f(1, 2, 3);
  EXPECT_LT((CentreOfMass(box) - Eigen::Vector3d(1, 2, 3)).norm(), 1e-6);
  // The L-shape's centre of mass is not its bounding box's centre: its legs meet at one corner.
  const Mesh l = MakeLShape(0.14, 0.05, 0.06);
  const Eigen::Vector3d c = CentreOfMass(l);
  const Eigen::Vector3d bbox = (0.5 * (l.Min() + l.Max())).cast<double>();
  EXPECT_GT((c - bbox).head<2>().norm(), 0.01);
  // Inverted winding: the same centre.
  Mesh flipped = box;
  for (auto& f : flipped.faces) std::swap(f[1], f[2]);
  EXPECT_LT((CentreOfMass(flipped) - Eigen::Vector3d(1, 2, 3)).norm(), 1e-6);
  // Only two faces of a box (no enclosed volume): the hull's centroid.
  Mesh open = box;
  open.faces.resize(2);
  EXPECT_LT((CentreOfMass(open) - Eigen::Vector3d(1, 2, 3)).norm(), 1e-6);
}

// The stable poses of a box are its 6 faces; opposite faces are equally likely, and larger
// faces (a lower centre of mass, a larger solid angle) more likely than smaller ones. Each
// pose rests its face on z = 0 with the centre of mass above the origin.
TEST(StablePosesTest, TheStablePosesOfABoxAreItsSixFaces) {
  const Mesh box = MakeBox(0.1, 0.2, 0.3);
  const std::vector<StablePose> poses = ComputeStablePoses(box);
  ASSERT_EQ(poses.size(), 6u);
  double total = 0;
  for (const StablePose& p : poses) {
    total += p.probability;
    int on_table = 0;
    EXPECT_NEAR(LowestZ(box, p.T_table_obj, &on_table), 0.0, 1e-6);
    EXPECT_EQ(on_table, 4);  // a whole face on the table
    const Eigen::Vector3d com = p.T_table_obj * Eigen::Vector3d::Zero();
    EXPECT_NEAR(com.head<2>().norm(), 0.0, 1e-7);
    EXPECT_NEAR(com.z(), p.com_height_m, 1e-7);
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
  // Most probable first: the two 0.2 × 0.3 faces (centre of mass 5 cm high), then 0.1 × 0.3,
  // then 0.1 × 0.2 (15 cm high).
  EXPECT_NEAR(poses[0].com_height_m, 0.05, 1e-7);
  EXPECT_NEAR(poses[1].com_height_m, 0.05, 1e-7);
  EXPECT_NEAR(poses[0].probability, poses[1].probability, 1e-7);
  EXPECT_NEAR(poses[2].com_height_m, 0.10, 1e-7);
  EXPECT_NEAR(poses[4].com_height_m, 0.15, 1e-7);
  EXPECT_GT(poses[1].probability, poses[2].probability);
  EXPECT_GT(poses[3].probability, poses[4].probability);
  // A cube: six equally likely poses.
  for (const StablePose& p : ComputeStablePoses(MakeBox(0.1, 0.1, 0.1))) EXPECT_NEAR(p.probability, 1.0 / 6, 1e-6);
}

// Faces the centre of mass does not lie above drain to stable ones: a thin wedge's slanted
// and narrow faces tip it onto a large one, and a long thin rod lies on a long face nearly
// always (its 1 × 1 cm ends catch few drops and tip over).
TEST(StablePosesTest, UnstableFacesDrainToStableOnes) {
  // A wedge: a triangular prism whose slanted face tips onto the long base.
  Mesh wedge;
  wedge.name = "wedge";
  wedge.vertices = {{0, 0, 0}, {0.3, 0, 0}, {0, 0.02, 0}, {0, 0, 0.1}, {0.3, 0, 0.1}, {0, 0.02, 0.1}};
  wedge.faces = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {2, 0, 3}, {2, 3, 5}};
  const std::vector<StablePose> poses = ComputeStablePoses(wedge);
  double total = 0;
  for (const StablePose& p : poses) total += p.probability;
  EXPECT_NEAR(total, 1.0, 1e-9);
  // Every pose reported is stable: the centre of mass lies above the hull of its contact.
  for (const StablePose& p : poses) {
    int on_table = 0;
    EXPECT_NEAR(LowestZ(wedge, p.T_table_obj, &on_table), 0.0, 1e-6);
    EXPECT_GE(on_table, 3);
  }
  // A long thin rod (1 × 1 × 20 cm) lies on one of its long faces nearly always.
  const std::vector<StablePose> rod = ComputeStablePoses(MakeBox(0.01, 0.01, 0.2));
  double lying = 0;
  for (const StablePose& p : rod) lying += p.com_height_m < 0.006 ? p.probability : 0.0;
  EXPECT_GT(lying, 0.95);
}

TEST(StablePosesTest, BadOptionsAndMeshesAreErrors) {
  StablePoseOptions o;
  o.min_probability = 1;
  testing_util::ExpectInvalid(o, "min_probability");
  ExpectError([&] { ComputeStablePoses(MakeBox(0.1, 0.1, 0.1), o); }, {"min_probability"});
  Mesh flat = testing_util::FrontSquare(0.1f);
  flat.name = "sheet";
  ExpectError([&] { ComputeStablePoses(flat); }, {"mesh 'sheet'"});
}

}  // namespace
}  // namespace posefilter
