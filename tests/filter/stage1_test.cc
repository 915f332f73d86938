// tests/filter/stage1_test.cc — the stage-1 builder (posefilter/stage1.h): each kind gives the
// prior the functions it stands for give, on the classes it documents.
#include <gtest/gtest.h>

#include <filesystem>

#include "posefilter/auto_prior.h"
#include "posefilter/ppf.h"
#include "posefilter/stage1.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

// A scene (depth and camera) of one synthetic object on a table.
SceneInput Stage1Scene() {
  SynthOptions so;
  so.target = "box";
  so.false_positives = 0;
  const SynthScene s = MakeSynthScene(so, 7);
  return {s.depth, s.camera};
}

void ExpectSamePrior(const Prior& a, const Prior& b) {
  EXPECT_EQ(a.classes, b.classes);
  EXPECT_EQ(a.layout.num_classes, b.layout.num_classes);
  EXPECT_EQ(a.prob, b.prob);
  ASSERT_EQ(a.boxes.size(), b.boxes.size());
  for (std::size_t c = 0; c < a.boxes.size(); ++c) EXPECT_EQ(a.boxes[c].cx, b.boxes[c].cx) << c;
}

TEST(Stage1, NoneIsTheUniformPriorOfTheObjectsOrOfTheGivenClasses) {
  const SceneInput scene = Stage1Scene();
  const int W = scene.camera.width, H = scene.camera.height;
  Stage1Options so;
  const Stage1 s = BuildStage1(scene, {{"a"}, {"b"}}, so);
  ExpectSamePrior(s.prior, UniformPrior(PyramidLayout::Thesis(W, H, 2), {"a", "b"}));
  ASSERT_EQ(s.seeds.size(), 2u);
  EXPECT_TRUE(s.seeds[0].empty() && s.seeds[1].empty() && s.instances.empty());
  so.classes = {"x", "a", "y"};
  ExpectSamePrior(BuildStage1(scene, {{"a"}}, so).prior, UniformPrior(PyramidLayout::Thesis(W, H, 3), so.classes));
}

TEST(Stage1, DetectionsPutTheObjectsFirstAndWarnAboutAnObjectWithoutOne) {
  const SceneInput scene = Stage1Scene();
  const int W = scene.camera.width, H = scene.camera.height;
  Stage1Options so;
  so.kind = Stage1Kind::kDetections;
  so.detections = {{"c", 0.8, 100, 100, 60, 50}, {"a", 0.9, 300, 200, 80, 80}};
  so.check_detections = true;
  so.what = "dets.json";
  const Stage1 s = BuildStage1(scene, {{"a"}, {"b"}}, so);
  const std::vector<std::string> classes = {"a", "b", "c"};
  ExpectSamePrior(s.prior, PriorFromDetections(so.detections, PyramidLayout::Thesis(W, H, 3), classes));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("dets.json"), std::string::npos);
  EXPECT_NE(s.warnings[0].find("'b'"), std::string::npos) << s.warnings[0];
  // No object with a detection on the image: an Error naming the source.
  so.detections = {{"c", 0.8, 100, 100, 60, 50}};
  ExpectError([&] { BuildStage1(scene, {{"a"}}, so); }, {"dets.json"});
}

TEST(Stage1, APyramidNeedsItsClassesAndIsPostProcessed) {
  const SceneInput scene = Stage1Scene();
  const PyramidLayout layout = PyramidLayout::Thesis(scene.camera.width, scene.camera.height, 2);
  Stage1Options so;
  so.kind = Stage1Kind::kPyramid;
  so.raw_pyramid = DetectionsToRawPyramid({{"b", 0.7, 200, 150, 90, 70}}, layout, {"a", "b"});
  ExpectError([&] { BuildStage1(scene, {{"a"}}, so); }, {"classes"});
  so.classes = {"a", "b"};
  ExpectSamePrior(BuildStage1(scene, {{"b"}}, so).prior, PostProcessPyramid(so.raw_pyramid, layout, so.classes));
}

TEST(Stage1, MasksGiveEachInstanceOfAnObjectItsOwnPriorAndPixels) {
  const SceneInput scene = Stage1Scene();
  const int W = scene.camera.width, H = scene.camera.height;
  LabelImage labels{W, H, std::vector<std::uint16_t>(std::size_t(W) * H, 0)};
  for (int y = 100; y < 140; ++y)
    for (int x = 0; x < W; ++x) labels.ids[std::size_t(y) * W + x] = x < 200 ? 1 : x < 400 ? 2 : 3;
  Stage1Options so;
  so.kind = Stage1Kind::kMasks;
  so.masks = MasksFromLabels(labels, {{1, "a"}, {2, "z"}, {3, "a"}}, "labels.png");
  const Stage1 s = BuildStage1(scene, {{"a"}, {"b"}}, so);
  ASSERT_EQ(s.instances.size(), 2u);  // the two of "a"; none of "b", "z" is no object
  const std::vector<std::string> classes = {"a", "b"};
  for (std::size_t n = 0; n < 2; ++n) {
    const InstanceMask& m = so.masks[n == 0 ? 0 : 2];
    EXPECT_EQ(s.instances[n].object, 0u);
    EXPECT_EQ(s.instances[n].mask, m.pixels);
    ExpectSamePrior(s.instances[n].prior, PriorFromDetections({MaskDetection(m)}, PyramidLayout::Thesis(W, H, 2), classes));
  }
}

TEST(Stage1, AutoRegionsAreProposeAutosDetectionsAndAnEmptySceneHasNoCandidates) {
  const SceneInput scene = Stage1Scene();
  const Mesh box = MakeShape("box");
  Stage1Options so;
  so.kind = Stage1Kind::kAuto;
  so.auto_ppf = false;  // regions only: no PPF model is built
  so.what = "--prior auto";
  const Stage1 s = BuildStage1(scene, {{"box", &box}}, so);
  const AutoProposals p = ProposeAuto(scene.depth, scene.camera, {{"box", box.Diameter(), nullptr}});
  ASSERT_FALSE(p.detections.empty());
  EXPECT_FALSE(s.no_candidates);
  ExpectSamePrior(s.prior, PriorFromDetections(p.detections, PyramidLayout::Thesis(scene.camera.width,
                                                                                     scene.camera.height, 1), {"box"}));
  // A flat wall: no region stands out. An Error naming `what`, or (not required) a flag.
  SceneInput flat = scene;
  for (float& z : flat.depth.data) z = 1.0f;
  ExpectError([&] { BuildStage1(flat, {{"box", &box}}, so); }, {"--prior auto", "no candidates"});
  so.require_candidates = false;
  EXPECT_TRUE(BuildStage1(flat, {{"box", &box}}, so).no_candidates);
}

// --prior auto on a mesh in the wrong units: an Error naming it before any PPF table is built
// or cached, and also when the caller gives the object's PPF model.
TEST(Stage1, AutoRejectsAMeshInTheWrongUnitsBeforeAnyTableIsBuilt) {
  SynthOptions so;
  so.target = "box";
  so.clutter = 0;
  const SynthScene sc = MakeSynthScene(so, 3);
  const SceneInput scene{sc.depth, sc.camera};
  Mesh millimetres = sc.target;
  for (Eigen::Vector3f& v : millimetres.vertices) v *= 1000.f;
  const std::filesystem::path dir = testing_util::FreshTempPath("stage1_units");
  Stage1Options opt;
  opt.kind = Stage1Kind::kAuto;
  opt.what = "--prior auto";
  opt.cache_dir = dir.string();
  ExpectError([&] { BuildStage1(scene, {{"box", &millimetres}}, opt); }, {"mesh 'box'", "units"});
  EXPECT_FALSE(std::filesystem::exists(dir));
  const PpfModel model = BuildPpfModel(millimetres);
  ExpectError([&] { BuildStage1(scene, {{"box", &millimetres, &model}}, opt); }, {"mesh 'box'", "units"});
  const PpfModel metres = BuildPpfModel(sc.target);
  opt.require_candidates = false;
  EXPECT_NO_THROW(BuildStage1(scene, {{"box", &sc.target, &metres}}, opt)) << "the mesh in metres";
}

}  // namespace
}  // namespace posefilter
