// Tests of `posefilter eval` (apps/eval_cmd.cc): runs the built CLI (POSEFILTER_CLI_PATH) on
// files written here — a hand-written gt.json, an OBJ cube, results from WriteResultsJson.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "posefilter/scene_io.h"
#include "test_util.h"

namespace posefilter {
namespace {

// A cube of side 0.1 m centred at the origin (diameter 0.1·√3 m = 173.2 mm), CCW from outside.
constexpr const char* kCubeObj = R"(# unit test cube, metres
v -0.05 -0.05 -0.05
v  0.05 -0.05 -0.05
v  0.05  0.05 -0.05
v -0.05  0.05 -0.05
v -0.05 -0.05  0.05
v  0.05 -0.05  0.05
v  0.05  0.05  0.05
v -0.05  0.05  0.05
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
)";

using testing_util::ReadFile;
using testing_util::RunResult;

class EvalCmdTest : public testing_util::ScratchDirTest {
 protected:
  EvalCmdTest() : ScratchDirTest("eval_cmd") {}

  void SetUp() override {
    cube_ = Write("cube.obj", kCubeObj);

    // Ground truth, written by hand in the dataset's format: box_a upright, box_b turned 30° about z.
    const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
    std::ostringstream gt;
    gt.precision(17);
    gt << R"({"objects": [)"
       << R"({"obj": "box_a", "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0.0, 0.0, 0.6]},)"
       << R"({"obj": "box_b", "R": [[)" << c << "," << -s << ",0],[" << s << "," << c
       << R"(,0],[0,0,1]], "t": [0.1, 0.0, 0.7]}]})";
    gt_ = Write("gt.json", gt.str());
    gt_a_.translation() = Eigen::Vector3d(0, 0, 0.6);
    gt_b_.linear() = Eigen::AngleAxisd(std::numbers::pi / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    gt_b_.translation() = Eigen::Vector3d(0.1, 0, 0.7);
  }

  // Results via the library writer, so the test follows the results.json format.
  std::string WriteResults(const std::vector<std::pair<std::string, Eigen::Isometry3d>>& poses,
                           const std::string& name = "results.json") const {
    std::vector<ObjectResult> results;
    for (const auto& [obj, T] : poses) {
      ObjectResult r;
      r.obj = obj;
      r.T_cam_obj = T;
      r.weight = 0.5;
      r.iterations = 10;
      r.time_ms = 1.0;
      results.push_back(r);
    }
    const std::string path = Path(name);
    WriteResultsJson(results, path);
    return path;
  }

  // A good estimate of box_a (2 mm off) and a bad one of box_b (50 mm off).
  std::string GoodAndBadResults() const {
    return WriteResults({{"box_a", Eigen::Translation3d(0.002, 0, 0) * gt_a_},
                         {"box_b", Eigen::Translation3d(0.05, 0, 0) * gt_b_}});
  }

  // `posefilter eval <args>` (`args` shell-quoted by the caller).
  RunResult Run(const std::string& args) const { return testing_util::RunCliShell("eval " + args, dir() / "run"); }

  std::string Meshes() const { return "--mesh box_a='" + cube_ + "' --mesh box_b='" + cube_ + "'"; }

  std::string cube_, gt_;
  Eigen::Isometry3d gt_a_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d gt_b_ = Eigen::Isometry3d::Identity();
};

TEST_F(EvalCmdTest, OneGoodOneBadGivesRecallHalf) {
  const std::string results = GoodAndBadResults();
  const std::string json_path = Path("eval.json");
  const RunResult r = Run("--results '" + results + "' --gt '" + gt_ + "' " + Meshes() + " --json '" + json_path + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("box_a"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("box_b"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ADD recall"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.500 (1/2)"), std::string::npos) << r.out;

  const auto j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_DOUBLE_EQ(j.at("recall_add").get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j.at("recall_adds").get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j.at("threshold").get<double>(), 0.1);
  ASSERT_EQ(j.at("objects").size(), 2u);
  const auto& a = j["objects"][0];
  const auto& b = j["objects"][1];
  EXPECT_EQ(a.at("obj"), "box_a");
  EXPECT_EQ(b.at("obj"), "box_b");
  EXPECT_NEAR(a.at("add_mm").get<double>(), 2.0, 1e-6);
  EXPECT_NEAR(a.at("trans_mm").get<double>(), 2.0, 1e-6);
  EXPECT_NEAR(a.at("rot_deg").get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(a.at("diameter_mm").get<double>(), 100 * std::sqrt(3.0), 1e-3);
  EXPECT_TRUE(a.at("add_ok").get<bool>());
  EXPECT_TRUE(a.at("adds_ok").get<bool>());
  EXPECT_NEAR(b.at("add_mm").get<double>(), 50.0, 1e-6);
  EXPECT_LE(b.at("adds_mm").get<double>(), b.at("add_mm").get<double>() + 1e-9);
  EXPECT_GT(b.at("adds_mm").get<double>(), 17.33);  // no corner within 10 % of the diameter
  EXPECT_FALSE(b.at("add_ok").get<bool>());
  EXPECT_FALSE(b.at("adds_ok").get<bool>());
  EXPECT_EQ(a.at("status"), "ok");

  // A looser threshold (40 % of 173 mm = 69 mm) accepts both.
  const RunResult loose = Run("--results '" + results + "' --gt '" + gt_ + "' " + Meshes() +
                              " --threshold 0.4 --json '" + json_path + "'");
  ASSERT_EQ(loose.code, 0) << loose.err;
  const auto jl = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_DOUBLE_EQ(jl.at("recall_add").get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(jl.at("recall_adds").get<double>(), 1.0);
}

TEST_F(EvalCmdTest, MissingResultCountsAsFailure) {
  const std::string results = WriteResults({{"box_b", gt_b_}, {"stray", gt_a_}});
  const std::string json_path = Path("eval.json");
  const RunResult r = Run("--results '" + results + "' --gt '" + gt_ + "' " + Meshes() + " --json '" + json_path + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stray"), std::string::npos) << r.out;  // listed as unmatched
  const auto j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_DOUBLE_EQ(j.at("recall_add").get<double>(), 0.5);
  EXPECT_EQ(j.at("n_missing").get<int>(), 1);
  EXPECT_EQ(j["objects"][0].at("status"), "missing");
  EXPECT_TRUE(j["objects"][0].at("add_mm").is_null());
  EXPECT_FALSE(j["objects"][0].at("add_ok").get<bool>());
  EXPECT_EQ(j["objects"][1].at("status"), "ok");
  EXPECT_NEAR(j["objects"][1].at("add_mm").get<double>(), 0.0, 1e-6);
  EXPECT_EQ(j.at("unmatched_results"), nlohmann::json::array({"stray"}));
}

TEST_F(EvalCmdTest, PointsFileOverridesMeshVertices) {
  // box_a estimated a quarter turn off about its own z axis: the cube corners move 100 mm
  // (ADD rejects, ADD-S accepts); a point set holding only the origin does not move at all.
  Eigen::Isometry3d turned = gt_a_;
  turned.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const std::string results = WriteResults({{"box_a", turned}, {"box_b", gt_b_}});
  const std::string json_path = Path("eval.json");
  const std::string base = "--results '" + results + "' --gt '" + gt_ + "' " + Meshes() + " --json '" + json_path + "'";

  ASSERT_EQ(Run(base).code, 0);
  auto j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_NEAR(j["objects"][0].at("add_mm").get<double>(), 100.0, 1e-4);
  EXPECT_NEAR(j["objects"][0].at("adds_mm").get<double>(), 0.0, 1e-4);
  EXPECT_NEAR(j["objects"][0].at("rot_deg").get<double>(), 90.0, 1e-6);
  EXPECT_FALSE(j["objects"][0].at("add_ok").get<bool>());
  EXPECT_TRUE(j["objects"][0].at("adds_ok").get<bool>());
  EXPECT_EQ(j["objects"][0].at("points"), "mesh");
  EXPECT_DOUBLE_EQ(j.at("recall_add").get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j.at("recall_adds").get<double>(), 1.0);

  const std::string xyz = Write("origin.xyz", "0 0 0\n");
  const RunResult r = Run(base + " --points box_a='" + xyz + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_NEAR(j["objects"][0].at("add_mm").get<double>(), 0.0, 1e-9);
  EXPECT_TRUE(j["objects"][0].at("add_ok").get<bool>());
  EXPECT_EQ(j["objects"][0].at("points"), xyz);
  EXPECT_EQ(j["objects"][0].at("n_points").get<int>(), 1);
  EXPECT_DOUBLE_EQ(j.at("recall_add").get<double>(), 1.0);

  // A broken points file is an error naming it.
  const std::string bad = Write("bad.xyz", "0 0 zero\n");
  const RunResult rb = Run(base + " --points box_a='" + bad + "'");
  EXPECT_EQ(rb.code, 1);
  EXPECT_NE(rb.err.find(bad + ":1"), std::string::npos) << rb.err;
}

TEST_F(EvalCmdTest, MissingFilesAreNamed) {
  const std::string results = GoodAndBadResults();
  const std::string no_results = Path("no_such_results.json");
  RunResult r = Run("--results '" + no_results + "' --gt '" + gt_ + "' " + Meshes());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(no_results), std::string::npos) << r.err;

  const std::string no_gt = Path("no_such_gt.json");
  r = Run("--results '" + results + "' --gt '" + no_gt + "' " + Meshes());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(no_gt), std::string::npos) << r.err;

  const std::string no_mesh_file = Path("no_such_mesh.obj");
  r = Run("--results '" + results + "' --gt '" + gt_ + "' --mesh box_a='" + cube_ + "' --mesh box_b='" +
          no_mesh_file + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(no_mesh_file), std::string::npos) << r.err;

  const std::string no_points = Path("no_such_points.xyz");
  r = Run("--results '" + results + "' --gt '" + gt_ + "' " + Meshes() + " --points box_b='" + no_points + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(no_points), std::string::npos) << r.err;

  // --json into a directory that does not exist.
  const std::string bad_json = Path("no_dir/eval.json");
  r = Run("--results '" + results + "' --gt '" + gt_ + "' " + Meshes() + " --json '" + bad_json + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(bad_json), std::string::npos) << r.err;
}

TEST_F(EvalCmdTest, GtObjectWithoutMeshIsNamed) {
  const std::string results = GoodAndBadResults();
  const RunResult r = Run("--results '" + results + "' --gt '" + gt_ + "' --mesh box_a='" + cube_ + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("box_b"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--mesh"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;  // no partial table
}

TEST_F(EvalCmdTest, BadOptionValuesFail) {
  const std::string results = GoodAndBadResults();
  const std::string base = "--results '" + results + "' --gt '" + gt_ + "' " + Meshes();
  for (const char* t : {"0", "-0.1", "nan", "inf"}) {
    const RunResult r = Run(base + " --threshold " + t);
    EXPECT_EQ(r.code, 1) << t;
    EXPECT_NE(r.err.find("--threshold"), std::string::npos) << t << ": " << r.err;
  }
  RunResult r = Run(base + " --threshold abc");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("threshold"), std::string::npos) << r.err;

  r = Run(base + " --unit-scale 0");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--unit-scale"), std::string::npos) << r.err;

  r = Run("--results '" + results + "' --gt '" + gt_ + "' --mesh '" + cube_ + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--mesh"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("NAME=PATH"), std::string::npos) << r.err;

  r = Run(base + " --points justaname");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--points"), std::string::npos) << r.err;

  r = Run(base + " --mesh box_a='" + cube_ + "'");  // same NAME twice
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("box_a"), std::string::npos) << r.err;

  r = Run("--results '" + results + "' " + Meshes());  // --gt is required
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--gt"), std::string::npos) << r.err;
}

TEST_F(EvalCmdTest, EmptyGroundTruthIsAnError) {
  const std::string results = GoodAndBadResults();
  const std::string empty_gt = Write("empty_gt.json", R"({"objects": []})");
  const RunResult r = Run("--results '" + results + "' --gt '" + empty_gt + "' " + Meshes());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(empty_gt), std::string::npos) << r.err;
}

}  // namespace
}  // namespace posefilter
