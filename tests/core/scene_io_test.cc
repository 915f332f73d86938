// Tests of the camera / ground-truth / results JSON files (include/posefilter/scene_io.h).
#include "posefilter/scene_io.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>

#include "posefilter/error.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using testing_util::ExpectError;
using testing_util::ReadFile;

// A fresh directory per test.
class JsonFileTest : public testing_util::ScratchDirTest {
 protected:
  JsonFileTest() : ScratchDirTest("json") {}
};

Eigen::Isometry3d SomeTransform(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A valid camera.json, as a JSON object, for the error tests to break one key at a time.
json GoodCamera() {
  return json{{"fx", 1066.778}, {"fy", 1067.487}, {"cx", 312.9869}, {"cy", 241.3109},
              {"width", 640},   {"height", 480},  {"depth_scale", 0.0001}};
}

json GoodGt() {
  return json::parse(R"({"objects": [
    {"obj": "a", "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0.1, 0.2, 0.7]},
    {"obj": "b", "R": [0,-1,0, 1,0,0, 0,0,1], "t": [0, 0, 1]}]})");
}

json GoodResults() {
  return json::parse(R"({"objects": [
    {"obj": "mug", "x": 0.1, "y": -0.2, "z": 0.7, "roll": 0.1, "pitch": -0.3, "yaw": 2.0,
     "R": [[0,-1,0],[1,0,0],[0,0,1]], "t": [0.05, 0.0, 0.6],
     "weight": 0.83, "iterations": 12, "time_ms": 4.5}]})");
}

// ---- Camera ----------------------------------------------------------------------------------

TEST_F(JsonFileTest, CameraRoundTripIsExact) {
  CameraFile cf;
  cf.camera.width = 1280;
  cf.camera.height = 720;
  cf.camera.fx = 911.123456789;
  cf.camera.fy = 910.987654321;
  cf.camera.cx = 640.5;
  cf.camera.cy = 359.25;
  cf.camera.base_to_camera = SomeTransform(1.1, {0.3, -1, 0.2}, {0.4, -0.05, 1.25});
  cf.depth_scale = 0.00025;
  const std::string path = Path("camera.json");
  WriteCameraJson(cf, path);
  const CameraFile back = ReadCameraJson(path);
  EXPECT_EQ(back.camera.width, 1280);
  EXPECT_EQ(back.camera.height, 720);
  EXPECT_EQ(back.camera.fx, cf.camera.fx);
  EXPECT_EQ(back.camera.fy, cf.camera.fy);
  EXPECT_EQ(back.camera.cx, cf.camera.cx);
  EXPECT_EQ(back.camera.cy, cf.camera.cy);
  EXPECT_EQ(back.depth_scale, cf.depth_scale);
  EXPECT_EQ(back.camera.base_to_camera.matrix(), cf.camera.base_to_camera.matrix());
}

TEST_F(JsonFileTest, CameraWithoutExtrinsicIsIdentityAndExtraKeysAreIgnored) {
  json j = GoodCamera();
  j["sensor"] = "some camera";
  j["notes"] = json::array({1, "x", nullptr});
  const CameraFile cf = ReadCameraJson(Write("camera.json", j.dump()));
  EXPECT_EQ(cf.camera.fx, 1066.778);
  EXPECT_EQ(cf.camera.cy, 241.3109);
  EXPECT_EQ(cf.depth_scale, 0.0001);
  EXPECT_TRUE(cf.camera.base_to_camera.matrix().isIdentity(0));
}

TEST_F(JsonFileTest, CameraExtrinsicIsRowMajor) {
  json j = GoodCamera();
  j["base_to_camera"] = json::parse("[[0,-1,0,0.5],[1,0,0,-0.25],[0,0,1,2],[0,0,0,1]]");
  const CameraFile cf = ReadCameraJson(Write("camera.json", j.dump()));
  const Eigen::Vector3d p = cf.camera.base_to_camera * Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(0.5, 0.75, 2.0))) << p.transpose();
}

struct BadJson {
  const char* label;
  std::function<void(json&)> mutate;
  std::vector<std::string> expected;  // substrings of the error message (besides the path)
};

void PrintTo(const BadJson& b, std::ostream* os) { *os << b.label; }

// A good file broken one way (the parameter) must be rejected naming the file and the key.
class JsonErrorTest : public JsonFileTest, public ::testing::WithParamInterface<BadJson> {
 protected:
  // Applies the parameter's mutation to `good`, writes it to `name` and expects `read(path)` to
  // throw an Error naming the path and every expected part.
  template <typename Read>
  void ExpectRejected(json good, const std::string& name, Read read) const {
    GetParam().mutate(good);
    const std::string path = Write(name, good.dump());
    SCOPED_TRACE("file: " + good.dump());
    std::vector<std::string> parts = GetParam().expected;
    parts.push_back(path);
    ExpectError([&] { read(path); }, parts);
  }
};

class CameraJsonErrorTest : public JsonErrorTest {};

TEST_P(CameraJsonErrorTest, RejectedNamingFileAndKey) {
  ExpectRejected(GoodCamera(), "camera.json", [](const std::string& path) { ReadCameraJson(path); });
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();

INSTANTIATE_TEST_SUITE_P(
    All, CameraJsonErrorTest,
    ::testing::Values(
        BadJson{"missingFx", [](json& j) { j.erase("fx"); }, {"missing key \"fx\""}},
        BadJson{"missingDepthScale", [](json& j) { j.erase("depth_scale"); },
                {"missing key \"depth_scale\""}},
        // nlohmann writes NaN as null: a NaN written by someone else's tool must not pass.
        BadJson{"nanFxIsNull", [](json& j) { j["fx"] = kNaN; },
                {"key \"fx\" must be a finite number"}},
        BadJson{"nanAsString", [](json& j) { j["fy"] = "nan"; },
                {"key \"fy\" must be a finite number"}},
        BadJson{"numberAsString", [](json& j) { j["cx"] = "312.9"; },
                {"key \"cx\" must be a finite number"}},
        BadJson{"boolean", [](json& j) { j["cy"] = true; }, {"key \"cy\" must be a finite number"}},
        BadJson{"widthZero", [](json& j) { j["width"] = 0; }, {"invalid camera", "width"}},
        BadJson{"heightNegative", [](json& j) { j["height"] = -480; }, {"height"}},
        BadJson{"widthFraction", [](json& j) { j["width"] = 640.5; },
                {"key \"width\" must be an integer"}},
        BadJson{"fxZero", [](json& j) { j["fx"] = 0; }, {"invalid camera", "fx"}},
        BadJson{"depthScaleNegative", [](json& j) { j["depth_scale"] = -0.001; },
                {"key \"depth_scale\" must be > 0"}},
        BadJson{"depthScaleZero", [](json& j) { j["depth_scale"] = 0; }, {"depth_scale"}},
        BadJson{"extrinsicWrongShape",
                [](json& j) { j["base_to_camera"] = json::parse("[[1,0,0,0],[0,1,0,0],[0,0,1,0]]"); },
                {"key \"base_to_camera\" must be a 4x4 array"}},
        BadJson{"extrinsicShortRow",
                [](json& j) {
                  j["base_to_camera"] = json::parse("[[1,0,0,0],[0,1,0],[0,0,1,0],[0,0,0,1]]");
                },
                {"key \"base_to_camera\" must be a 4x4 array"}},
        BadJson{"extrinsicNull",
                [](json& j) {
                  j["base_to_camera"] = json::parse("[[1,0,0,0],[0,1,0,null],[0,0,1,0],[0,0,0,1]]");
                },
                {"key \"base_to_camera[1][3]\" must be a finite number"}},
        BadJson{"extrinsicNotRigid",
                [](json& j) {
                  j["base_to_camera"] = json::parse("[[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]");
                },
                {"invalid camera", "rotation"}}),
    [](const ::testing::TestParamInfo<BadJson>& info) { return std::string(info.param.label); });

TEST_F(JsonFileTest, CameraFileLevelErrors) {
  ExpectError([&] { ReadCameraJson(Path("absent.json")); }, {Path("absent.json"), "cannot open"});
  const std::string bad = Write("bad.json", "{\"fx\": 1066.7, \"fy\": ");
  ExpectError([&] { ReadCameraJson(bad); }, {bad, "malformed JSON"});
  const std::string nan = Write("nan.json", "{\"fx\": NaN}");  // not JSON
  ExpectError([&] { ReadCameraJson(nan); }, {nan, "malformed JSON"});
  const std::string huge = Write("huge.json", R"({"fx": 1e999, "fy": 1, "cx": 1, "cy": 1,
    "width": 640, "height": 480, "depth_scale": 0.001})");
  ExpectError([&] { ReadCameraJson(huge); }, {huge, "1e999"});  // overflow → inf: rejected
  const std::string arr = Write("array.json", "[1, 2, 3]");
  ExpectError([&] { ReadCameraJson(arr); }, {arr, "object"});
  const std::string empty = Write("empty.json", "");
  ExpectError([&] { ReadCameraJson(empty); }, {empty, "malformed JSON"});
  ExpectError([&] { ReadCameraJson(dir().string()); }, {dir().string()});
}

TEST_F(JsonFileTest, CameraWriterRejectsInvalidCameras) {
  CameraFile cf;
  cf.camera.width = 0;
  ExpectError([&] { WriteCameraJson(cf, Path("c.json")); }, {Path("c.json"), "width"});
  cf = CameraFile();
  cf.depth_scale = -1;
  ExpectError([&] { WriteCameraJson(cf, Path("c.json")); }, {Path("c.json"), "depth_scale"});
  cf = CameraFile();
  cf.camera.fx = kNaN;
  ExpectError([&] { WriteCameraJson(cf, Path("c.json")); }, {Path("c.json"), "fx"});
  ExpectError([&] { WriteCameraJson(CameraFile(), Path("no/dir/c.json")); }, {Path("no/dir/c.json")});
}

// ---- Ground truth ----------------------------------------------------------------------------

TEST_F(JsonFileTest, GtRoundTripAndFlatR) {
  std::vector<GtObject> gt(2);
  gt[0].obj = "009_gelatin_box";
  gt[0].T_cam_obj = SomeTransform(2.5, {1, 1, 0}, {-0.03, -0.008, 0.59});
  gt[1].obj = "025_mug";
  gt[1].T_cam_obj = SomeTransform(-0.4, {0, 0.2, 1}, {0.058, -0.021, 0.617});
  const std::string path = Path("gt.json");
  WriteGtJson(gt, path);
  const auto back = ReadGtJson(path);
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].obj, gt[i].obj);
    EXPECT_TRUE(back[i].T_cam_obj.matrix().isApprox(gt[i].T_cam_obj.matrix(), 1e-14));
  }

  // A flat, row-major R is read the same as the nested one.
  const auto both = ReadGtJson(Write("flat.json", GoodGt().dump()));
  ASSERT_EQ(both.size(), 2u);
  EXPECT_TRUE(both[0].T_cam_obj.linear().isIdentity(1e-15));
  EXPECT_EQ(both[0].T_cam_obj.translation(), Eigen::Vector3d(0.1, 0.2, 0.7));
  // R = [0 -1 0; 1 0 0; 0 0 1] maps x_model = (1,0,0) to (0,1,0) before t = (0,0,1).
  const Eigen::Vector3d x = both[1].T_cam_obj * Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(x.isApprox(Eigen::Vector3d(0, 1, 1))) << x.transpose();

  // An empty object list is valid (nothing in view).
  EXPECT_TRUE(ReadGtJson(Write("none.json", R"({"objects": []})")).empty());
}

TEST_F(JsonFileTest, GtSlightlyNonOrthonormalRIsProjectedOntoRotation) {
  json j = GoodGt();
  j["objects"][0]["R"] = json::parse("[[1.0004,0,0],[0,0.9997,0.0003],[0,0,1]]");
  const auto gt = ReadGtJson(Write("gt.json", j.dump()));
  const Eigen::Matrix3d r = gt[0].T_cam_obj.linear();
  EXPECT_TRUE((r.transpose() * r).isIdentity(1e-12));
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(r(0, 0), 1.0, 1e-3);
}

class GtJsonErrorTest : public JsonErrorTest {};

TEST_P(GtJsonErrorTest, RejectedNamingFileAndKey) {
  ExpectRejected(GoodGt(), "gt.json", [](const std::string& path) { ReadGtJson(path); });
}

INSTANTIATE_TEST_SUITE_P(
    All, GtJsonErrorTest,
    ::testing::Values(
        BadJson{"missingObjects", [](json& j) { j.erase("objects"); }, {"missing key \"objects\""}},
        BadJson{"objectsNotArray", [](json& j) { j["objects"] = 3; },
                {"key \"objects\" must be an array"}},
        BadJson{"entryNotObject", [](json& j) { j["objects"][1] = "mug"; },
                {"key \"objects[1]\" must be a JSON object"}},
        BadJson{"missingObj", [](json& j) { j["objects"][1].erase("obj"); },
                {"missing key \"objects[1].obj\""}},
        BadJson{"objNotString", [](json& j) { j["objects"][0]["obj"] = 25; },
                {"key \"objects[0].obj\" must be a string"}},
        BadJson{"missingR", [](json& j) { j["objects"][0].erase("R"); },
                {"missing key \"objects[0].R\""}},
        BadJson{"flatRTooShort", [](json& j) { j["objects"][1]["R"].erase(8); },
                {"key \"objects[1].R\" must be a 3x3 array"}},
        BadJson{"nestedRTooLong", [](json& j) { j["objects"][0]["R"][2].push_back(0); },
                {"key \"objects[0].R\" must be a 3x3 array"}},
        BadJson{"RNaN", [](json& j) { j["objects"][0]["R"][1][1] = kNaN; },
                {"key \"objects[0].R[1][1]\" must be a finite number"}},
        BadJson{"flatRString", [](json& j) { j["objects"][1]["R"][4] = "0"; },
                {"key \"objects[1].R[4]\" must be a finite number"}},
        BadJson{"RScaled",
                [](json& j) { j["objects"][0]["R"] = json::parse("[[2,0,0],[0,2,0],[0,0,2]]"); },
                {"key \"objects[0].R\" is not a rotation"}},
        BadJson{"RReflection",
                [](json& j) { j["objects"][0]["R"] = json::parse("[[1,0,0],[0,1,0],[0,0,-1]]"); },
                {"key \"objects[0].R\" is not a rotation", "det"}},
        BadJson{"RJustOutsideTolerance",
                [](json& j) { j["objects"][0]["R"][0][1] = 0.002; },
                {"key \"objects[0].R\" is not a rotation"}},
        BadJson{"tTooShort", [](json& j) { j["objects"][1]["t"].erase(2); },
                {"key \"objects[1].t\" must be an array of 3 numbers"}},
        BadJson{"tNull", [](json& j) { j["objects"][1]["t"][2] = nullptr; },
                {"key \"objects[1].t[2]\" must be a finite number"}},
        BadJson{"tInfinite",
                [](json& j) { j["objects"][0]["t"][0] = std::numeric_limits<double>::infinity(); },
                {"key \"objects[0].t[0]\" must be a finite number"}}),
    [](const ::testing::TestParamInfo<BadJson>& info) { return std::string(info.param.label); });

TEST_F(JsonFileTest, GtFileLevelErrors) {
  ExpectError([&] { ReadGtJson(Path("absent.json")); }, {Path("absent.json")});
  const std::string bad = Write("bad.json", "{\"objects\": [ {\"obj\": \"a\" ");
  ExpectError([&] { ReadGtJson(bad); }, {bad, "malformed JSON"});
  std::vector<GtObject> gt(1);
  gt[0].obj = "x";
  gt[0].T_cam_obj.translation().x() = kNaN;
  ExpectError([&] { WriteGtJson(gt, Path("w.json")); }, {Path("w.json"), "non-finite"});
  gt[0] = GtObject();
  ExpectError([&] { WriteGtJson(gt, Path("w.json")); }, {Path("w.json"), "obj"});
}

// ---- Results ---------------------------------------------------------------------------------

TEST_F(JsonFileTest, ResultsRoundTrip) {
  std::vector<ObjectResult> rs(2);
  rs[0].obj = "025_mug";
  rs[0].pose_base = {0.1, -0.2, 0.75, 0.3, -1.2, 3.0};
  rs[0].T_cam_obj = SomeTransform(0.9, {1, -2, 0.5}, {0.05, 0.01, 0.62});
  rs[0].weight = 0.8125;
  rs[0].iterations = 17;
  rs[0].time_ms = 12.75;
  rs[1].obj = "061_foam_brick";
  rs[1].pose_base = {-0.3, 0.0, 1.1, -3.0, 0.5, -0.1};
  rs[1].T_cam_obj = SomeTransform(-2.0, {0, 1, 0}, {-0.1, 0.2, 0.9});
  rs[1].weight = 0.0;
  rs[1].iterations = 0;
  rs[1].time_ms = 0.5;
  const std::string path = Path("results.json");
  WriteResultsJson(rs, path);

  // The documented key layout is there.
  const json j = json::parse(ReadFile(path));
  ASSERT_TRUE(j["objects"].is_array());
  for (const char* key : {"obj", "x", "y", "z", "roll", "pitch", "yaw", "R", "t", "weight",
                          "iterations", "time_ms"}) {
    EXPECT_TRUE(j["objects"][0].contains(key)) << key;
  }
  EXPECT_EQ(j["objects"][0]["R"].size(), 3u);
  EXPECT_EQ(j["objects"][0]["R"][0].size(), 3u);

  const auto back = ReadResultsJson(path);
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].obj, rs[i].obj);
    EXPECT_EQ(back[i].pose_base.x, rs[i].pose_base.x);
    EXPECT_EQ(back[i].pose_base.y, rs[i].pose_base.y);
    EXPECT_EQ(back[i].pose_base.z, rs[i].pose_base.z);
    EXPECT_EQ(back[i].pose_base.roll, rs[i].pose_base.roll);
    EXPECT_EQ(back[i].pose_base.pitch, rs[i].pose_base.pitch);
    EXPECT_EQ(back[i].pose_base.yaw, rs[i].pose_base.yaw);
    EXPECT_TRUE(back[i].T_cam_obj.matrix().isApprox(rs[i].T_cam_obj.matrix(), 1e-14));
    EXPECT_EQ(back[i].weight, rs[i].weight);
    EXPECT_EQ(back[i].iterations, rs[i].iterations);
    EXPECT_EQ(back[i].time_ms, rs[i].time_ms);
  }
  EXPECT_TRUE(ReadResultsJson(Write("none.json", R"({"objects": []})")).empty());
}

class ResultsJsonErrorTest : public JsonErrorTest {};

TEST_P(ResultsJsonErrorTest, RejectedNamingFileAndKey) {
  ASSERT_NO_THROW(ReadResultsJson(Write("ok.json", GoodResults().dump())));
  ExpectRejected(GoodResults(), "results.json", [](const std::string& path) { ReadResultsJson(path); });
}

INSTANTIATE_TEST_SUITE_P(
    All, ResultsJsonErrorTest,
    ::testing::Values(
        BadJson{"missingWeight", [](json& j) { j["objects"][0].erase("weight"); },
                {"missing key \"objects[0].weight\""}},
        BadJson{"missingYaw", [](json& j) { j["objects"][0].erase("yaw"); },
                {"missing key \"objects[0].yaw\""}},
        BadJson{"xNull", [](json& j) { j["objects"][0]["x"] = kNaN; },
                {"key \"objects[0].x\" must be a finite number"}},
        BadJson{"iterationsFraction", [](json& j) { j["objects"][0]["iterations"] = 1.5; },
                {"key \"objects[0].iterations\" must be an integer"}},
        BadJson{"iterationsNegative", [](json& j) { j["objects"][0]["iterations"] = -1; },
                {"objects[0].iterations"}},
        BadJson{"RNotRotation", [](json& j) { j["objects"][0]["R"][0][0] = 0.5; },
                {"key \"objects[0].R\" is not a rotation"}},
        BadJson{"tWrongLength", [](json& j) { j["objects"][0]["t"].push_back(1); },
                {"key \"objects[0].t\" must be an array of 3 numbers"}}),
    [](const ::testing::TestParamInfo<BadJson>& info) { return std::string(info.param.label); });

TEST_F(JsonFileTest, ResultsWriterRejectsNonFinite) {
  std::vector<ObjectResult> rs(1);
  rs[0].obj = "mug";
  rs[0].weight = kNaN;
  ExpectError([&] { WriteResultsJson(rs, Path("r.json")); }, {Path("r.json"), "weight"});
  rs[0].weight = 0.5;
  rs[0].pose_base.yaw = std::numeric_limits<double>::infinity();
  ExpectError([&] { WriteResultsJson(rs, Path("r.json")); }, {Path("r.json"), "yaw"});
  rs[0].pose_base.yaw = 0;
  EXPECT_NO_THROW(WriteResultsJson(rs, Path("r.json")));
  ExpectError([&] { WriteResultsJson(rs, Path("no/dir/r.json")); }, {Path("no/dir/r.json")});
}

// ---- Real YCB-Video files (optional) ---------------------------------------------------------

fs::path YcbvScenes() { return testing_util::YcbvDataDir() / "scenes"; }

TEST(SceneIoYcbvTest, ReadsRealCameraJson) {
  const fs::path file = YcbvScenes() / "ycbv_0000_000001" / "camera.json";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const CameraFile cf = ReadCameraJson(file.string());
  // Compare with the file's own values, parsed independently.
  const json j = json::parse(ReadFile(file));
  EXPECT_EQ(cf.camera.fx, j["fx"].get<double>());
  EXPECT_EQ(cf.camera.fy, j["fy"].get<double>());
  EXPECT_EQ(cf.camera.cx, j["cx"].get<double>());
  EXPECT_EQ(cf.camera.cy, j["cy"].get<double>());
  EXPECT_EQ(cf.camera.width, j["width"].get<int>());
  EXPECT_EQ(cf.camera.height, j["height"].get<int>());
  EXPECT_EQ(cf.depth_scale, j["depth_scale"].get<double>());
  EXPECT_TRUE(cf.camera.base_to_camera.matrix().isIdentity(0));
}

TEST(SceneIoYcbvTest, ReadsEveryRealGtJson) {
  if (!fs::exists(YcbvScenes())) GTEST_SKIP() << YcbvScenes() << " not found";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(YcbvScenes())) {
    const fs::path file = entry.path() / "gt.json";
    if (!fs::exists(file)) continue;
    ++files;
    const auto gt = ReadGtJson(file.string());
    const json j = json::parse(ReadFile(file));
    ASSERT_EQ(gt.size(), j["objects"].size()) << file;
    for (size_t i = 0; i < gt.size(); ++i) {
      const json& o = j["objects"][i];
      EXPECT_EQ(gt[i].obj, o["obj"].get<std::string>());
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(gt[i].T_cam_obj.translation()[r], o["t"][r].get<double>(), 1e-12);
        for (int c = 0; c < 3; ++c) {
          // The file's R has 8 decimals; projection onto SO(3) moves it by less than 1e-6.
          EXPECT_NEAR(gt[i].T_cam_obj.linear()(r, c), o["R"][r][c].get<double>(), 1e-6);
        }
      }
      // Objects sit in front of the camera, within the sensor's range.
      EXPECT_GT(gt[i].T_cam_obj.translation().z(), 0.3);
      EXPECT_LT(gt[i].T_cam_obj.translation().z(), 1.5);
    }
  }
  EXPECT_GT(files, 0);
}

}  // namespace
}  // namespace posefilter
