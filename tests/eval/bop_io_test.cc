// BOP dataset / detections / results-CSV I/O (bop.h): round trips through the files, the
// exact CSV bytes, the YCB-Video folder reader, ground-truth boxes, and every bad-input path.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "eval/bop_test_dataset.h"
#include "posefilter/bop.h"
#include "posefilter/error.h"
#include "posefilter/projection.h"
#include "posefilter/rng.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectError;
using testing_util::ReadFile;
using testing_util::TinyBop;
using testing_util::WriteFile;

// One tiny dataset per test binary run, copied per test that changes it.
class BopIoTest : public testing_util::TinyBopTest {
 protected:
  BopIoTest() : TinyBopTest("bop_io") {}
};

// Replaces the first occurrence of `from` in the file by `to`; fails the test if absent.
void Patch(const fs::path& file, const std::string& from, const std::string& to) {
  std::string s = ReadFile(file);
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from << " not in " << file;
  s.replace(at, from.size(), to);
  WriteFile(file, s);
}

TEST_F(BopIoTest, ReadsWhatWasWritten) {
  const Dataset ds = ReadBopDataset(tiny_->root, "test");
  EXPECT_EQ(ds.format, "bop");
  ASSERT_EQ(ds.models.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(ds.models[k].obj_id, k + 1);
    EXPECT_NEAR(ds.models[k].diameter_m, tiny_->meshes[k].Diameter(), 1e-9);
    EXPECT_DOUBLE_EQ(ds.models[k].mesh_unit_scale, 1e-3);
  }
  ASSERT_EQ(ds.models[0].symmetries_discrete.size(), 3u);
  EXPECT_TRUE(ds.models[0].symmetries_discrete[2].isApprox(testing_util::HalfTurn(Eigen::Vector3d::UnitZ()), 1e-9));
  ASSERT_EQ(ds.models[1].symmetries_continuous.size(), 1u);
  EXPECT_TRUE(ds.models[1].symmetries_continuous[0].axis.isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(ds.models[2].symmetries_discrete.empty());

  ASSERT_EQ(ds.images.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const DatasetImage& im = ds.images[i];
    const DatasetImage& want = tiny_->images[i];
    EXPECT_EQ(im.scene_id, 1);
    EXPECT_EQ(im.im_id, i + 1);
    EXPECT_NEAR(im.camera.fx, want.camera.fx, 1e-9);
    EXPECT_NEAR(im.camera.cy, want.camera.cy, 1e-9);
    EXPECT_NEAR(im.depth_scale_m, want.depth_scale_m, 1e-15);
    ASSERT_EQ(im.gt.size(), 1u);
    EXPECT_EQ(im.gt[0].obj_id, want.gt[0].obj_id);
    EXPECT_TRUE(im.gt[0].T_cam_obj.isApprox(want.gt[0].T_cam_obj, 1e-9));
    // Depth and size come back from the PNG.
    const SceneInput s = LoadDatasetScene(im);
    EXPECT_EQ(s.camera.width, 640);
    EXPECT_EQ(s.camera.height, 480);
    double worst = 0;
    for (std::size_t p = 0; p < s.depth.data.size(); ++p)
      worst = std::max(worst, std::abs(double(s.depth.data[p]) - tiny_->depths[i].data[p]));
    EXPECT_LT(worst, 1e-6);
  }
  // Targets from the gt: one per image.
  ASSERT_EQ(ds.targets.size(), 3u);
  EXPECT_EQ(ds.targets_source, "scene_gt");
  EXPECT_EQ(ds.targets[1].obj_id, 2);
  EXPECT_EQ(ds.targets[1].inst_count, 1);

  // The mesh comes back in metres.
  const Mesh m = LoadDatasetMesh(ds.models[0]);
  ASSERT_EQ(m.vertices.size(), tiny_->meshes[0].vertices.size());
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    EXPECT_LT((m.vertices[v] - tiny_->meshes[0].vertices[v]).norm(), 1e-6f);
}

TEST_F(BopIoTest, TargetsFileAndGtInfoAreRead) {
  const std::string root = Copy();
  WriteFile(fs::path(root) / "test_targets_bop19.json",
            R"([{"im_id": 3, "inst_count": 1, "obj_id": 3, "scene_id": 1}])");
  WriteFile(fs::path(root) / "test/000001/scene_gt_info.json",
            R"({"1": [{"bbox_obj": [1,2,3,4], "bbox_visib": [1,2,3,3], "visib_fract": 0.75}],
                "2": [{"bbox_obj": [0,0,5,5], "bbox_visib": [0,0,5,5], "visib_fract": 1}],
                "3": [{"bbox_obj": [0,0,5,5], "bbox_visib": [0,0,5,5], "visib_fract": 1}]})");
  const Dataset ds = OpenDataset(root, "test");
  ASSERT_EQ(ds.targets.size(), 1u);
  EXPECT_EQ(ds.targets[0].im_id, 3);
  EXPECT_NE(ds.targets_source.find("test_targets_bop19.json"), std::string::npos);
  ASSERT_TRUE(ds.images[0].gt[0].has_info);
  EXPECT_DOUBLE_EQ(ds.images[0].gt[0].visib_fract, 0.75);
  EXPECT_DOUBLE_EQ(ds.images[0].gt[0].bbox_obj[3], 4);
}

TEST_F(BopIoTest, CameraJsonGivesTheImageSizeAndMustMatchTheDepth) {
  const std::string root = Copy();
  WriteFile(fs::path(root) / "camera.json", R"({"width": 320, "height": 240})");
  const Dataset ds = ReadBopDataset(root, "test");
  EXPECT_EQ(ds.images[0].camera.width, 320);
  ExpectError([&] { LoadDatasetScene(ds.images[0]); }, {"000001.png", "scene 1, image 1", "640x480", "320x240"});
}

TEST_F(BopIoTest, BadDatasetFilesNameFileAndEntry) {
  {
    const std::string root = Copy();
    Patch(fs::path(root) / "test/000001/scene_gt.json", "\"obj_id\": 2", "\"obj_id\": 99");
    ExpectError([&] { ReadBopDataset(root, "test"); },
                {"scene_gt.json", "image 2", "entry 0", "obj_id 99 not in models_info.json"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    WriteFile(fs::path(root) / "test/000001/scene_camera.json", "{\"1\": {\"cam_K\": [1, 2,");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"scene_camera.json", "malformed JSON"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    Patch(fs::path(root) / "test/000001/scene_camera.json", "\"depth_scale\"", "\"depth_scal\"");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"scene_camera.json", "image 1", "depth_scale"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    Patch(fs::path(root) / "models/models_info.json", "\"diameter\"", "\"diam\"");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"models_info.json", "obj_id 1", "diameter"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    fs::remove(fs::path(root) / "models/obj_000002.ply");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"obj_000002.ply", "obj_id 2"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    WriteFile(fs::path(root) / "test/000001/scene_gt_info.json", R"({"1": []})");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"scene_gt_info.json", "image 1", "one entry per"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    // A rotation that is not one (scaled by 2).
    WriteFile(fs::path(root) / "test/000001/scene_gt.json",
              R"({"1": [{"cam_R_m2c": [2,0,0,0,2,0,0,0,2], "cam_t_m2c": [0,0,500], "obj_id": 1}],
                  "2": [{"cam_R_m2c": [1,0,0,0,1,0,0,0,1], "cam_t_m2c": [0,0,500], "obj_id": 2}],
                  "3": [{"cam_R_m2c": [1,0,0,0,1,0,0,0,1], "cam_t_m2c": [0,0,500], "obj_id": 3}]})");
    ExpectError([&] { ReadBopDataset(root, "test"); }, {"scene_gt.json", "image 1", "entry 0", "not a rotation"});
    fs::remove_all(root);
  }
  {
    const std::string root = Copy();
    WriteFile(fs::path(root) / "test_targets_bop19.json",
              R"([{"im_id": 7, "inst_count": 1, "obj_id": 3, "scene_id": 1}])");
    ExpectError([&] { ReadBopDataset(root, "test"); },
                {"test_targets_bop19.json", "entry 0", "scene 1 image 7", "not in split 'test'"});
    fs::remove_all(root);
  }
  ExpectError([&] { ReadBopDataset(tiny_->root, "val"); }, {"val", "split folder not found"});
  ExpectError([&] { OpenDataset(Path("nowhere"), "test"); }, {"nowhere", "not found"});
}

TEST_F(BopIoTest, MoreBadEntriesAreNamed) {
  struct Case {
    std::string file;  // relative to the dataset root
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"models/models_info.json", R"({"1": {"diameter": 100, "symmetries_discrete": [[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,2]]}})",
       {"models_info.json", "obj_id 1", "symmetries_discrete[0]", "last row"}},
      {"models/models_info.json", R"({"1": {"diameter": 100, "symmetries_continuous": [{"axis": [0,0,0], "offset": [0,0,0]}]}})",
       {"models_info.json", "obj_id 1", "symmetries_continuous[0]", "axis"}},
      {"models/models_info.json", R"({"one": {"diameter": 100}})", {"models_info.json", "\"one\"", "obj_id"}},
      {"models/models_info.json", R"({"1": {"diameter": -5}})", {"models_info.json", "obj_id 1", "diameter"}},
      {"test/000001/scene_camera.json", R"({"1": {"cam_K": [500, 3, 320, 0, 500, 240, 0, 0, 1], "depth_scale": 0.1}})",
       {"scene_camera.json", "image 1", "skew"}},
      {"test/000001/scene_camera.json", R"({"1": {"cam_K": [500, 0, 320, 0, 500, 240], "depth_scale": 0.1}})",
       {"scene_camera.json", "image 1", "cam_K", "9 numbers"}},
      {"camera.json", R"({"width": 0, "height": 480})", {"camera.json", "width and height"}},
      {"test_targets_bop19.json", R"({"a": 1})", {"test_targets_bop19.json", "JSON array"}},
      {"test_targets_bop19.json", R"([{"scene_id": 1, "im_id": 1, "obj_id": 1, "inst_count": 0}])",
       {"test_targets_bop19.json", "entry 0", "inst_count"}},
      {"test_targets_bop19.json", R"([{"scene_id": 1, "im_id": 1, "obj_id": 8, "inst_count": 1}])",
       {"test_targets_bop19.json", "entry 0", "obj_id 8"}},
      {"test/000001/scene_gt_info.json", R"({"1": [{"bbox_obj": [0,0,1,1], "bbox_visib": [0,0,1,1], "visib_fract": 1.5}]})",
       {"scene_gt_info.json", "image 1", "entry 0", "visib_fract"}},
      {"test/000001/scene_gt.json", R"({"1": [{"obj_id": 1, "cam_R_m2c": [1,0,0,0,1,0,0,0,1], "cam_t_m2c": [0,0,1]}]})",
       {"scene_gt.json", "image 2", "has no entry"}},
      {"test/000001/scene_gt.json", R"({"9": []})", {"scene_gt.json", "image 9", "not in scene_camera.json"}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].text);
    const std::string root = Copy();
    WriteFile(fs::path(root) / cases[i].file, cases[i].text);
    ExpectError([&] { ReadBopDataset(root, "test"); }, cases[i].parts);
    fs::remove_all(root);
  }
  fs::create_directories(dir() / "empty");
  ExpectError([&] { OpenDataset(Path("empty"), "test"); }, {"empty", "neither a BOP dataset"});
  ExpectError([&] { ReadYcbvFolder(Path("empty")); }, {"models folder not found"});
}

TEST_F(BopIoTest, MissingDepthImageNamesFileSceneAndImage) {
  const std::string root = Copy();
  fs::remove(fs::path(root) / "test/000001/depth/000002.png");
  const Dataset ds = ReadBopDataset(root, "test");  // depth is opened lazily
  EXPECT_NO_THROW(LoadDatasetScene(ds.images[0]));
  ExpectError([&] { LoadDatasetScene(ds.images[1]); }, {"scene 1, image 2", "000002.png"});
}

// ---- Results CSV -----------------------------------------------------------------------------

// R = [-19 -26 22; 34 -13 14; -2 26 29] / 39 (a rotation with nine different entries).
BopResult KnownResult() {
  BopResult r;
  r.scene_id = 7;
  r.im_id = 42;
  r.obj_id = 3;
  r.score = 0.875;
  Eigen::Matrix3d R;
  R << -19, -26, 22, 34, -13, 14, -2, 26, 29;
  r.T_cam_obj.linear() = R / 39.0;
  r.T_cam_obj.translation() = Eigen::Vector3d(0.1, -0.025, 0.75);
  r.time_s = 1.25;
  return r;
}

TEST_F(BopIoTest, CsvIsByteCompatibleWithBop) {
  const std::string path = Path("r.csv");
  WriteBopResultsCsv({KnownResult()}, path);
  EXPECT_EQ(ReadFile(path),
            "scene_id,im_id,obj_id,score,R,t,time\n"
            "7,42,3,0.875000,-0.487179487 -0.666666667 0.564102564 0.871794872 -0.333333333 0.358974359 "
            "-0.0512820513 0.666666667 0.743589744,100.000000 -25.000000 750.000000,1.250000\n");
  const std::vector<BopResult> back = ReadBopResultsCsv(path);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].scene_id, 7);
  EXPECT_EQ(back[0].im_id, 42);
  EXPECT_EQ(back[0].obj_id, 3);
  EXPECT_DOUBLE_EQ(back[0].score, 0.875);
  EXPECT_DOUBLE_EQ(back[0].time_s, 1.25);
  EXPECT_TRUE(back[0].T_cam_obj.linear().isApprox(KnownResult().T_cam_obj.linear(), 1e-8));
  EXPECT_TRUE(back[0].T_cam_obj.translation().isApprox(Eigen::Vector3d(0.1, -0.025, 0.75), 1e-12));
}

TEST_F(BopIoTest, AppendWritesTheHeaderOnceAndRefusesAPartialLastRow) {
  const std::string path = Path("a.csv");
  BopResult a = KnownResult(), b = KnownResult();
  b.im_id = 43;
  AppendBopResultsCsv({a}, path);
  AppendBopResultsCsv({b}, path);
  const std::vector<std::string> lines = testing_util::Lines(ReadFile(path));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], kBopCsvHeader);
  EXPECT_EQ(ReadBopResultsCsv(path).size(), 2u);
  std::ofstream(path, std::ios::app) << "7,44,3,0.5";  // a crash mid-row
  ExpectError([&] { AppendBopResultsCsv({a}, path); }, {path, "newline"});
}

TEST_F(BopIoTest, BadCsvNamesFileAndLine) {
  const std::string row = FormatBopCsvRow(KnownResult());
  const std::string head = std::string(kBopCsvHeader) + "\n";
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"scene_id,im_id,obj_id,score,R,t\n" + row + "\n", {"line 1", "header"}},
      {head + row + "\n" + "7,42,3,0.5,1 0 0 0 1 0\n", {"line 3", "7 fields"}},
      {head + "7,42,3,0.5,1 0 0 0 1 0 0 0,0 0 0,1\n", {"line 2", "R must hold 9"}},
      {head + "7,42,3,0.5,1 0 0 0 1 0 0 0 1,0 0,1\n", {"line 2", "t must hold 3"}},
      {head + "7,42,x,0.5,1 0 0 0 1 0 0 0 1,0 0 0,1\n", {"line 2", "obj_id"}},
      {head + "7,42,3,nan,1 0 0 0 1 0 0 0 1,0 0 0,1\n", {"line 2", "score"}},
      {head + "7,42,3,0.5,2 0 0 0 2 0 0 0 2,0 0 0,1\n", {"line 2", "not a rotation"}},
      {head + "7,42,3,0.5,1 0 0 0 1 0 0 0 1,0 0 0,1\n7,42,4,0.5,1 0 0 0 1 0 0 0 1,0 0 0,2\n",
       {"line 3", "differs from line 2"}},
      {"", {"empty"}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = Write("bad" + std::to_string(i) + ".csv", cases[i].text);
    std::vector<std::string> parts = cases[i].parts;
    parts.push_back(path);
    ExpectError([&] { ReadBopResultsCsv(path); }, parts);
  }
  ExpectError([&] { ReadBopResultsCsv(Path("none.csv")); }, {"none.csv", "no such file"});
}

// ---- Detections ---------------------------------------------------------------------------------

TEST_F(BopIoTest, DetectionsAreReadAndMappedToModelNames) {
  const std::string path = Write("dets.json", R"([
    {"scene_id": 1, "image_id": 2, "category_id": 3, "bbox": [10, 20, 30, 40], "score": 0.8, "time": 0.1},
    {"scene_id": 1, "image_id": 2, "category_id": 1, "bbox": [1, 2, 3, 4], "score": 0.2}])");
  const std::vector<BopDetection> d = ReadBopDetections(path);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].im_id, 2);
  EXPECT_EQ(d[0].obj_id, 3);
  EXPECT_DOUBLE_EQ(d[0].h, 40);
  EXPECT_DOUBLE_EQ(d[0].time_s, 0.1);
  EXPECT_DOUBLE_EQ(d[1].time_s, -1);
  const Dataset ds = ReadBopDataset(tiny_->root, "test");
  const std::vector<Detection> p = ToPriorDetections(d, ds, path);
  EXPECT_EQ(p[0].cls, "obj_000003");
  EXPECT_DOUBLE_EQ(p[0].x, 10);
  EXPECT_DOUBLE_EQ(p[0].score, 0.8);

  BopDetection bad = d[0];
  bad.obj_id = 9;
  ExpectError([&] { ToPriorDetections({bad}, ds, path); }, {"dets.json", "category_id 9"});
  const std::string no_box = Write("d2.json", R"([{"scene_id": 1, "image_id": 2, "category_id": 3, "score": 0.8}])");
  ExpectError([&] { ReadBopDetections(no_box); }, {"d2.json", "entry 0", "bbox"});
  const std::string bad_score =
      Write("d3.json", R"([{"scene_id": 1, "image_id": 2, "category_id": 3, "bbox": [0,0,1,1], "score": 1.5}])");
  ExpectError([&] { ReadBopDetections(bad_score); }, {"d3.json", "entry 0", "score"});
  const std::string zero_box =
      Write("d4.json", R"([{"scene_id": 1, "image_id": 2, "category_id": 3, "bbox": [0,0,0,1], "score": 0.5}])");
  ExpectError([&] { ReadBopDetections(zero_box); }, {"d4.json", "entry 0", "width and height"});
}

// ---- Ground-truth boxes ---------------------------------------------------------------------------

TEST_F(BopIoTest, GtBoxesAreTheSilhouetteJitteredAndAlwaysDrawFourNormals) {
  const Mesh& box = tiny_->meshes[0];
  const Eigen::Isometry3d T = tiny_->images[0].gt[0].T_cam_obj;
  const Camera& cam = tiny_->images[0].camera;
  Rng exact_rng(5);
  const GtBoxDetection exact = JitteredGtBox(box, T, cam, "obj_000001", 0, 0.9, exact_rng);
  ASSERT_TRUE(exact.in_view);
  const Box sil = ProjectedBox(box, T, cam);
  EXPECT_NEAR(exact.detection.x, sil.cx - sil.w / 2, 1e-9);
  EXPECT_NEAR(exact.detection.w, sil.w, 1e-9);
  EXPECT_EQ(exact.detection.cls, "obj_000001");
  EXPECT_DOUBLE_EQ(exact.detection.score, 0.9);

  Rng a(5), b(5);
  const GtBoxDetection j1 = JitteredGtBox(box, T, cam, "x", 8, 0.9, a);
  const GtBoxDetection j2 = JitteredGtBox(box, T, cam, "x", 8, 0.9, b);
  EXPECT_DOUBLE_EQ(j1.detection.x, j2.detection.x);
  EXPECT_GT(std::abs(j1.detection.w - sil.w) + std::abs(j1.detection.x - exact.detection.x), 1e-6);
  EXPECT_LE(std::abs(j1.detection.x + j1.detection.w / 2 - sil.cx), 0.25 * sil.w + 1e-9);

  // Out of view: no box, but the stream advanced by exactly four normals.
  Eigen::Isometry3d behind = T;
  behind.translation().z() = -1;
  Rng c(9), d(9);
  EXPECT_FALSE(JitteredGtBox(box, behind, cam, "x", 8, 0.9, c).in_view);
  for (int i = 0; i < 4; ++i) d.Normal();
  EXPECT_EQ(c.NextU64(), d.NextU64());
  ExpectError([&] { JitteredGtBox(box, T, cam, "x", -1, 0.9, c); }, {"jitter"});
}

// ---- YCB-Video folder -------------------------------------------------------------------------------

TEST_F(BopIoTest, YcbvFolderIsADataset) {
  if (!fs::exists(testing_util::YcbvDataDir())) GTEST_SKIP() << "no " << testing_util::YcbvDataDir();
  const Dataset ds = OpenDataset(testing_util::YcbvDataDir().string(), "test");
  EXPECT_EQ(ds.format, "ycbv");
  EXPECT_EQ(ds.models.size(), 21u);
  ASSERT_NE(ds.Model(1), nullptr);
  EXPECT_EQ(ds.Model(1)->name, "002_master_chef_can");
  // models_info.json of the folder states 171.7 mm from the points.
  EXPECT_NEAR(ds.Model(1)->diameter_m, 0.1717, 0.0002);
  ASSERT_EQ(ds.images.size(), 10u);
  EXPECT_EQ(ds.images[0].scene_id, 0);
  EXPECT_EQ(ds.images[0].im_id, 1);
  std::set<int> ids;
  for (const auto& g : ds.images[0].gt) ids.insert(g.obj_id);
  EXPECT_EQ(ids, (std::set<int>{8, 14, 21}));  // 009_gelatin_box, 025_mug, 061_foam_brick
  EXPECT_EQ(ds.targets.size(), 30u);
  EXPECT_FALSE(ds.Model(8)->points_path.empty());
  const SceneInput s = LoadDatasetScene(ds.images[0]);
  EXPECT_EQ(s.depth.width, 640);
  EXPECT_GT(s.depth.CountValid(), 100000u);
}

TEST_F(BopIoTest, YcbvFolderErrorsNameTheFile) {
  const fs::path root = dir() / "yv";
  fs::create_directories(root / "models");
  fs::create_directories(root / "scenes" / "a_0001_000005");
  SaveMeshPly(tiny_->meshes[0], (root / "models" / "box.ply").string());
  const fs::path scene = root / "scenes" / "a_0001_000005";
  CameraFile cam;
  cam.camera = tiny_->images[0].camera;
  cam.depth_scale = tiny_->images[0].depth_scale_m;
  WriteCameraJson(cam, (scene / "camera.json").string());
  SaveDepthPng(tiny_->depths[0], (scene / "depth.png").string(), cam.depth_scale);
  WriteGtJson({{"box", tiny_->images[0].gt[0].T_cam_obj}}, (scene / "gt.json").string());
  const Dataset ds = ReadYcbvFolder(root.string());
  ASSERT_EQ(ds.images.size(), 1u);
  EXPECT_EQ(ds.images[0].scene_id, 1);
  EXPECT_EQ(ds.images[0].im_id, 5);
  EXPECT_EQ(ds.Model(22)->name, "box");  // not a YCB-Video name: ids after the 21
  EXPECT_NEAR(ds.Model(22)->diameter_m, tiny_->meshes[0].Diameter(), 1e-6);

  WriteGtJson({{"mug", tiny_->images[0].gt[0].T_cam_obj}}, (scene / "gt.json").string());
  ExpectError([&] { ReadYcbvFolder(root.string()); }, {"gt.json", "objects[0]", "'mug'", "no model"});
}

}  // namespace
}  // namespace posefilter
