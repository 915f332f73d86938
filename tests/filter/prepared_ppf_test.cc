// A mesh prepared with its PPF model (PrepareModel with a PpfPreparation,
// posefilter/prepared_model.h): the table equals BuildPpfModel's and is read from the cache
// folder the second time; AutoPriorForModels and AutoTrackStage1 on such models give the stage 1
// of BuildStage1 on the meshes bit for bit, without loading or building a table per call; a
// model prepared with other PPF options is not used for these.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "posefilter/auto_prior.h"
#include "posefilter/error.h"
#include "posefilter/ppf.h"
#include "posefilter/prepared_model.h"
#include "posefilter/stage1.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"
#include "posefilter/tracker.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::FreshTempPath;

const TableWorld& PpfWorld() {
  static const TableWorld* w = new TableWorld({MakeBox(0.12, 0.08, 0.16, "box"), MakeCylinder(0.04, 0.14, 32, "cylinder")});
  return *w;
}

const TableScene& PpfScene() {
  static const TableScene* s = [] {
    TableSceneOptions o;
    o.min_objects = 2;
    o.max_objects = 2;
    return new TableScene(PpfWorld().MakeScene(o, 4));
  }();
  return *s;
}

void ExpectSameTable(const PpfModel& a, const PpfModel& b) {
  EXPECT_EQ(a.mesh_hash, b.mesh_hash);
  EXPECT_EQ(a.diameter, b.diameter);
  EXPECT_EQ(a.offsets, b.offsets);
  ASSERT_EQ(a.entries.size(), b.entries.size());
  for (std::size_t i = 0; i < a.entries.size(); ++i) {
    ASSERT_EQ(a.entries[i].reference, b.entries[i].reference) << i;
    ASSERT_EQ(a.entries[i].alpha, b.entries[i].alpha) << i;
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) ASSERT_TRUE(a.points[i].p == b.points[i].p && a.points[i].n == b.points[i].n);
}

void ExpectSameStage1(const AutoStage1& a, const AutoStage1& b) {
  EXPECT_EQ(a.prior.classes, b.prior.classes);
  EXPECT_EQ(a.prior.prob, b.prior.prob);
  ASSERT_EQ(a.prior.boxes.size(), b.prior.boxes.size());
  for (std::size_t c = 0; c < a.prior.boxes.size(); ++c) {
    EXPECT_EQ(a.prior.boxes[c].cx, b.prior.boxes[c].cx) << c;
    EXPECT_EQ(a.prior.boxes[c].w, b.prior.boxes[c].w) << c;
  }
  ASSERT_EQ(a.seeds.size(), b.seeds.size());
  for (std::size_t k = 0; k < a.seeds.size(); ++k) {
    ASSERT_EQ(a.seeds[k].size(), b.seeds[k].size()) << k;
    for (std::size_t i = 0; i < a.seeds[k].size(); ++i) {
      EXPECT_TRUE(a.seeds[k][i].T_cam_obj.matrix() == b.seeds[k][i].T_cam_obj.matrix()) << k << " " << i;
      EXPECT_EQ(a.seeds[k][i].score, b.seeds[k][i].score) << k << " " << i;
    }
  }
}

TEST(PreparedPpf, TheTableEqualsBuildPpfModelsAndComesFromTheCacheTheSecondTime) {
  const Mesh& mesh = PpfWorld().models()[0].mesh;
  const auto dir = FreshTempPath("prepared_ppf");
  const std::shared_ptr<const PreparedModel> first = PrepareModel(mesh, {FilterOptions{}}, PpfPreparation{{}, dir.string()});
  ASSERT_NE(first->ppf(), nullptr);
  EXPECT_EQ(first->ppf_status(), "built");
  ExpectSameTable(*first->ppf(), BuildPpfModel(mesh));
  const std::shared_ptr<const PreparedModel> second = PrepareModel(mesh, {FilterOptions{}}, PpfPreparation{{}, dir.string()});
  EXPECT_EQ(second->ppf_status(), "loaded");
  ExpectSameTable(*first->ppf(), *second->ppf());
  EXPECT_TRUE(first->HasPpf(PpfOptions{}));
  PpfOptions other;
  other.distance_step = 0.08;
  EXPECT_FALSE(first->HasPpf(other)) << "a table of another distance step";
  const std::shared_ptr<const PreparedModel> plain = PrepareModel(mesh, FilterOptions{});
  EXPECT_EQ(plain->ppf(), nullptr);
  EXPECT_FALSE(plain->HasPpf(PpfOptions{}));
  EXPECT_EQ(plain->ppf_status(), "");
  std::filesystem::remove_all(dir);

  PpfOptions bad;
  bad.angle_bins = 1;
  ExpectError([&] { PrepareModel(mesh, {FilterOptions{}}, PpfPreparation{bad, ""}); }, {"PPF option", "angle_bins"});
}

TEST(PreparedPpf, AutoPriorForModelsEqualsBuildStage1OnTheMeshes) {
  const TableScene& s = PpfScene();
  std::vector<std::shared_ptr<const PreparedModel>> models;
  std::vector<const PreparedModel*> with_ppf, without_ppf;
  std::vector<std::shared_ptr<const PreparedModel>> plain;
  std::vector<const Mesh*> meshes;
  std::vector<std::string> names;
  std::vector<Stage1Object> objects;
  for (const auto& m : PpfWorld().models()) {
    models.push_back(PrepareModel(m.mesh, {FilterOptions{}}, PpfPreparation{{}, ""}));
    plain.push_back(PrepareModel(m.mesh, FilterOptions{}));
    with_ppf.push_back(models.back().get());
    without_ppf.push_back(plain.back().get());
    meshes.push_back(&m.mesh);
    names.push_back(m.mesh.name);
    objects.push_back({m.mesh.name, &m.mesh});
  }
  Stage1Options so;
  so.kind = Stage1Kind::kAuto;
  so.what = "test";
  Stage1 built = BuildStage1(SceneInput{s.depth, s.camera}, objects, so);
  const AutoStage1 expected{std::move(built.prior), std::move(built.seeds)};
  ASSERT_FALSE(expected.prior.classes.empty());
  EXPECT_FALSE(expected.seeds[0].empty() && expected.seeds[1].empty()) << "the PPF voting proposes poses here";
  ExpectSameStage1(expected, AutoPriorForModels(s.depth, s.camera, with_ppf, names, "test"));
  // Models without the table build one for the call: the same stage 1.
  ExpectSameStage1(expected, AutoPriorForModels(s.depth, s.camera, without_ppf, names, "test"));
  ExpectError([&] { AutoPriorForModels(s.depth, s.camera, with_ppf, {"box"}, "frame 9"); }, {"frame 9", "one name per model"});

  // The tracker's stage 1 on the models: the one on the meshes.
  std::vector<Mesh> mesh_copies;
  for (const Mesh* m : meshes) mesh_copies.push_back(*m);
  const TrackStage1 on_meshes = AutoTrackStage1(SceneInput{s.depth, s.camera}, mesh_copies, "", "test");
  const TrackStage1 on_models = AutoTrackStage1(SceneInput{s.depth, s.camera}, models, "test");
  EXPECT_EQ(on_meshes.prior.prob, on_models.prior.prob);
  ASSERT_EQ(on_meshes.seeds.size(), on_models.seeds.size());
  for (const auto& [name, seeds] : on_meshes.seeds) {
    ASSERT_EQ(on_models.seeds.count(name), 1u) << name;
    ASSERT_EQ(on_models.seeds.at(name).size(), seeds.size()) << name;
    for (std::size_t i = 0; i < seeds.size(); ++i)
      EXPECT_TRUE(on_models.seeds.at(name)[i].T_cam_obj.matrix() == seeds[i].T_cam_obj.matrix()) << name << " " << i;
  }
}

}  // namespace
}  // namespace posefilter
