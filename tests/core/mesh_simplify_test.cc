// Level of detail: SimplifyMesh (meshoptimizer) meets its face budget, keeps the shape (bounds,
// diameter, surface distance, closedness, outward winding), leaves small meshes alone, rejects
// bad arguments; MeshAtLod and FilterOptions::render.lod_max_faces apply it in the filter.
#include "posefilter/mesh_simplify.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "posefilter/filter.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::ExpectInvalid;

// Every undirected edge is used by exactly two faces, in opposite directions (a closed,
// consistently wound surface).
bool IsClosedAndOriented(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : m.faces)
    for (int e = 0; e < 3; ++e) ++directed[{f[e], f[(e + 1) % 3]}];
  for (const auto& [edge, n] : directed) {
    if (n != 1) return false;
    const auto back = directed.find({edge.second, edge.first});
    if (back == directed.end() || back->second != 1) return false;
  }
  return true;
}

// Signed volume (divergence theorem): > 0 when the faces wind CCW seen from outside. m³.
double SignedVolume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    v += m.vertices[f[0]].cast<double>().dot(m.vertices[f[1]].cast<double>().cross(m.vertices[f[2]].cast<double>()));
  return v / 6;
}

// The torus with every face given its own three vertices (as loaders of per-face data give).
Mesh Unwelded(const Mesh& m) {
  Mesh out;
  out.name = m.name;
  for (const auto& f : m.faces) {
    const auto base = std::uint32_t(out.vertices.size());
    for (int a = 0; a < 3; ++a) out.vertices.push_back(m.vertices[f[a]]);
    out.faces.push_back({base, base + 1, base + 2});
  }
  return out;
}

TEST(SimplifyMesh, TorusMeetsBudgetAndKeepsItsShape) {
  const Mesh torus = MakeTorus(0.06, 0.025, 32, 32);  // 2048 faces, 17 cm across
  ASSERT_EQ(torus.faces.size(), 2048u);
  for (int budget : {1024, 500, 200}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    SimplifyReport rep;
    const Mesh lod = SimplifyMesh(torus, budget, {}, &rep);
    std::string why;
    ASSERT_TRUE(lod.IsValid(&why)) << why;
    EXPECT_EQ(lod.name, torus.name);
    EXPECT_LE(int(lod.faces.size()), budget);
    EXPECT_GE(int(lod.faces.size()), budget / 2);  // it did not throw the shape away
    EXPECT_EQ(rep.faces_in, 2048);
    EXPECT_EQ(rep.faces_out, int(lod.faces.size()));
    EXPECT_EQ(rep.vertices_out, int(lod.vertices.size()));
    EXPECT_FALSE(rep.unchanged);
    EXPECT_FALSE(rep.sloppy);
    EXPECT_TRUE(IsClosedAndOriented(lod));
    // Tolerance: 4% of the diameter (6.8 mm) on each bound, on the diameter and on the
    // largest distance of an input vertex from the simplified surface.
    const double tol = 0.04 * torus.Diameter();
    EXPECT_LE((lod.Min() - torus.Min()).cwiseAbs().maxCoeff(), tol);
    EXPECT_LE((lod.Max() - torus.Max()).cwiseAbs().maxCoeff(), tol);
    EXPECT_NEAR(lod.Diameter(), torus.Diameter(), tol);
    EXPECT_GT(rep.max_distance_m, 0.0);
    EXPECT_LE(rep.max_distance_m, tol);
    EXPECT_GE(rep.error_m, 0.0);
    // Winding kept outward; the volume within 10 %.
    EXPECT_NEAR(SignedVolume(lod), SignedVolume(torus), 0.1 * SignedVolume(torus));
  }
}

TEST(SimplifyMesh, SmallerBudgetMeansLargerError) {
  const Mesh torus = MakeTorus(0.06, 0.025, 32, 32);
  SimplifyReport fine, coarse;
  SimplifyMesh(torus, 1500, {}, &fine);
  SimplifyMesh(torus, 100, {}, &coarse);
  EXPECT_LT(fine.max_distance_m, coarse.max_distance_m);
  EXPECT_LE(fine.error_m, coarse.error_m);
}

TEST(SimplifyMesh, WeldsPerFaceVertices) {
  // Without welding no edge is shared and the edge-collapse pass could not remove anything.
  const Mesh soup = Unwelded(MakeTorus(0.06, 0.025, 32, 32));
  ASSERT_EQ(soup.vertices.size(), 3 * 2048u);
  SimplifyReport rep;
  const Mesh lod = SimplifyMesh(soup, 400, {}, &rep);
  EXPECT_LE(lod.faces.size(), 400u);
  EXPECT_FALSE(rep.sloppy);
  EXPECT_TRUE(IsClosedAndOriented(lod));
  EXPECT_LE(lod.vertices.size(), 1024u);  // at most the torus's distinct positions
}

TEST(SimplifyMesh, IsDeterministic) {
  const Mesh torus = MakeTorus(0.06, 0.025, 24, 20);
  const Mesh a = SimplifyMesh(torus, 300), b = SimplifyMesh(torus, 300);
  ASSERT_EQ(a.faces, b.faces);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]);
}

TEST(SimplifyMesh, SmallMeshReturnedUnchanged) {
  const Mesh box = MakeBox(0.1, 0.2, 0.3);  // 12 faces
  for (int budget : {12, 13, 1000}) {
    SimplifyReport rep;
    const Mesh out = SimplifyMesh(box, budget, {}, &rep);
    EXPECT_TRUE(rep.unchanged);
    EXPECT_FALSE(rep.sloppy);
    EXPECT_EQ(rep.faces_out, 12);
    EXPECT_EQ(rep.error_m, 0.0);
    EXPECT_EQ(rep.max_distance_m, 0.0);
    EXPECT_EQ(out.name, box.name);
    EXPECT_EQ(out.faces, box.faces);
    EXPECT_EQ(out.vertices, box.vertices);
  }
}

TEST(SimplifyMesh, SloppyFallbackReachesABudgetTheErrorBoundBlocks) {
  const Mesh torus = MakeTorus(0.06, 0.025, 32, 32);
  SimplifyOptions strict;
  strict.max_relative_error = 1e-6;  // no collapse is that cheap on a curved surface
  SimplifyReport rep;
  const Mesh lod = SimplifyMesh(torus, 300, strict, &rep);
  EXPECT_TRUE(rep.sloppy);
  EXPECT_LE(lod.faces.size(), 300u);
  EXPECT_GT(lod.faces.size(), 0u);
  std::string why;
  EXPECT_TRUE(lod.IsValid(&why)) << why;

  strict.allow_sloppy = false;
  ExpectError([&] { SimplifyMesh(torus, 300, strict); }, {"torus", "300", "max_relative_error"});
}

TEST(SimplifyMesh, RejectsInvalidTargets) {
  const Mesh torus = MakeTorus(0.06, 0.025, 16, 16);
  for (int budget : {3, 1, 0, -5, std::numeric_limits<int>::min()})
    ExpectError([&] { SimplifyMesh(torus, budget); }, {"torus", "max_faces", ">= 4"});
}

TEST(SimplifyMesh, RejectsInvalidOptionsAndMeshes) {
  const Mesh torus = MakeTorus(0.06, 0.025, 16, 16);
  for (double e : {0.0, -0.1, 1.5, std::nan("")}) {
    SimplifyOptions o;
    o.max_relative_error = e;
    ExpectInvalid(o, "max_relative_error");
    ExpectError([&] { SimplifyMesh(torus, 100, o); }, {"torus", "max_relative_error"});
  }
  Mesh empty;
  empty.name = "nothing";
  ExpectError([&] { SimplifyMesh(empty, 100); }, {"nothing", "no vertices"});
  Mesh bad = torus;
  bad.name = "broken";
  bad.faces[5][1] = 100000;
  ExpectError([&] { SimplifyMesh(bad, 100); }, {"broken"});
  Mesh nan = torus;
  nan.name = "nan";
  nan.vertices[3].x() = std::nanf("");
  ExpectError([&] { SimplifyMesh(nan, 100); }, {"nan"});
}

TEST(MeshAtLod, FullMeshUnlessTheBudgetIsSmaller) {
  const Mesh torus = MakeTorus(0.06, 0.025, 32, 32);
  Mesh storage;
  EXPECT_EQ(&MeshAtLod(torus, 0, &storage), &torus);
  EXPECT_EQ(&MeshAtLod(torus, 2048, &storage), &torus);
  EXPECT_EQ(&MeshAtLod(torus, 5000, &storage), &torus);
  EXPECT_EQ(&MeshAtLod(torus, 2, &storage), &torus);  // invalid: left to FilterOptions::IsValid
  const Mesh& lod = MeshAtLod(torus, 600, &storage);
  EXPECT_EQ(&lod, &storage);
  EXPECT_LE(lod.faces.size(), 600u);
  EXPECT_GT(lod.faces.size(), 300u);
}

TEST(FilterOptionsLod, ValidatesTheBudget) {
  FilterOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  for (int v : {-1, 1, 3}) {
    o.render.lod_max_faces = v;
    ExpectInvalid(o, "lod_max_faces");
  }
  o.render.lod_max_faces = 4;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

TEST(FilterOptionsLod, WeighPosesRendersTheSimplifiedMesh) {
  // The true pose scores about the same with the full torus and a 500-face LOD; a budget that
  // invalid options reject is refused with the option's name.
  SynthOptions so;
  so.target = "torus";
  so.clutter = 0;
  so.false_positives = 0;
  so.hole_fraction = 0;
  so.noise_sigma_m = 0;
  const SynthScene scene = MakeSynthScene(so, 3);
  const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
  const int cls = prior.ClassIndex("torus");
  // The cell with the most mass for the class hosts the hypothesis.
  int cell = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (prior.Prob(c, cls) > prior.Prob(cell, cls)) cell = c;
  const Pose6 truth = TransformToPose(scene.camera.base_to_camera.inverse() * scene.gt[0].T_cam_obj);
  Pose6 off = truth;
  off.z += 0.03;
  FilterOptions o;
  o.threads = 1;
  // No silhouette edge penalty: the simplified outline lies up to ~1.5 px inside the true one
  // (vertices are kept, so the facets are inscribed), and the scene surface just outside it
  // counts as "continued" — that is the penalty's business, measured in docs/PERFORMANCE.md.
  o.score.delta = 0;
  const std::vector<std::pair<Pose6, int>> hyps = {{truth, cell}, {off, cell}};
  const std::vector<double> full = WeighPoses({scene.depth, scene.camera}, scene.target, prior, cls, o, hyps);
  o.render.lod_max_faces = 500;
  const std::vector<double> lod = WeighPoses({scene.depth, scene.camera}, scene.target, prior, cls, o, hyps);
  ASSERT_EQ(full.size(), 2u);
  ASSERT_EQ(lod.size(), 2u);
  EXPECT_GT(full[0], full[1] + 0.1);
  EXPECT_GT(lod[0], lod[1] + 0.1);
  EXPECT_NEAR(lod[0], full[0], 0.05);
  EXPECT_NE(lod[0], full[0]);  // a different mesh was rendered
  o.render.lod_max_faces = 2;
  ExpectError([&] { WeighPoses({scene.depth, scene.camera}, scene.target, prior, cls, o, hyps); },
              {"lod_max_faces"});
}

}  // namespace
}  // namespace posefilter
