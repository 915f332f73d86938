// `posefilter eval --dataset` (apps/eval_cmd.cc, dataset mode) on the tiny synthetic BOP dataset:
// the table and JSON of a results CSV, hand-checked ADD / ADD-S, and the error paths.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval/bop_test_dataset.h"
#include "posefilter/bop.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ReadFile;
using testing_util::RunCli;
using testing_util::RunResult;

class BopEvalCliTest : public testing_util::TinyBopTest {
 protected:
  BopEvalCliTest() : TinyBopTest("bop_eval_cli") {}
  RunResult Eval(const std::vector<std::string>& extra, const std::string& capture = "eval") {
    std::vector<std::string> args = {"eval", "--dataset", tiny_->root, "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunCli(args, dir() / capture);
  }
  static nlohmann::json ReadJson(const std::string& path) { return nlohmann::json::parse(ReadFile(path)); }
};

TEST_F(BopEvalCliTest, GroundTruthCsvScoresOne) {
  const std::string csv = Path("gt.csv"), json = Path("e.json");
  WriteBopResultsCsv(testing_util::GtResults(*tiny_), csv);
  const RunResult r = Eval({"--results", csv, "--json", json});
  ASSERT_EQ(r.code, 0) << r.err;
  // The "all" row: 3 instances, 3 estimated, every recall, AUC and AR 1.
  bool found = false;
  for (const auto& line : testing_util::Lines(r.out))
    if (line.rfind("all ", 0) == 0) {
      found = true;
      EXPECT_NE(line.find("3      3  1.000  1.000    1.000      1.000  1.000  1.000  1.000  1.000"), std::string::npos)
          << line;
    }
  EXPECT_TRUE(found) << r.out;
  const nlohmann::json j = ReadJson(json);
  EXPECT_EQ(j["format"], "bop");
  EXPECT_DOUBLE_EQ(j["overall"]["ar"].get<double>(), 1);
  EXPECT_NEAR(j["overall"]["auc_adds"].get<double>(), 1, 1e-6);  // R has 9 digits in the CSV
  EXPECT_EQ(j["objects"].size(), 3u);
  EXPECT_EQ(j["instances"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["mean_time_per_image_s"].get<double>(), 0.5);
}

TEST_F(BopEvalCliTest, TranslationByDGivesAddD) {
  std::vector<BopResult> rows = testing_util::GtResults(*tiny_);
  const double d = 0.012;  // 12 mm along the camera's z: ADD = 12 mm exactly
  rows[2].T_cam_obj.translation().z() += d;
  rows.erase(rows.begin());  // no estimate for image 1
  const std::string csv = Path("t.csv"), json = Path("t.json");
  WriteBopResultsCsv(rows, csv);
  const RunResult r = Eval({"--results", csv, "--json", json, "--no-vsd"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 of 3 gt instance(s) without an estimate"), std::string::npos) << r.out;
  const nlohmann::json j = ReadJson(json);
  const auto& inst = j["instances"];
  ASSERT_EQ(inst.size(), 3u);
  EXPECT_FALSE(inst[0]["estimated"].get<bool>());
  EXPECT_TRUE(inst[0]["add_mm"].is_null());
  EXPECT_NEAR(inst[2]["add_mm"].get<double>(), 12.0, 1e-6);
  EXPECT_NEAR(inst[2]["mssd_mm"].get<double>(), 12.0, 1e-6);
  EXPECT_LE(inst[2]["adds_mm"].get<double>(), 12.0 + 1e-9);
  EXPECT_TRUE(j["overall"]["vsd_recall"].is_null());  // --no-vsd
  // 12 mm is below 10 % of every model's diameter: 2 of 3 accepted.
  EXPECT_NEAR(j["overall"]["add_recall"].get<double>(), 2.0 / 3, 1e-12);

  // --limit 1: only image 1 (no estimate) is evaluated.
  const RunResult l = Eval({"--results", csv, "--json", json, "--no-vsd", "--limit", "1"}, "limit");
  ASSERT_EQ(l.code, 0) << l.err;
  EXPECT_EQ(ReadJson(json)["overall"]["n_instances"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(ReadJson(json)["overall"]["add_recall"].get<double>(), 0);
}

TEST_F(BopEvalCliTest, BadInputsNameFileAndEntry) {
  std::vector<BopResult> rows = testing_util::GtResults(*tiny_);
  rows[1].obj_id = 99;
  const std::string alien = Path("alien.csv");
  WriteBopResultsCsv(rows, alien);
  RunResult r = Eval({"--results", alien}, "alien");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("alien.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("obj_id 99"), std::string::npos) << r.err;

  const std::string trunc = Write("trunc.csv", std::string(kBopCsvHeader) + "\n1,1,1,0.9,1 0 0 0 1 0 0 0 1\n");
  r = Eval({"--results", trunc}, "trunc");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("trunc.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.err;

  r = Eval({"--results", Path("none.csv")}, "none");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("none.csv"), std::string::npos) << r.err;

  const std::string csv = Path("gt.csv");
  WriteBopResultsCsv(testing_util::GtResults(*tiny_), csv);
  r = Eval({"--results", csv, "--split", "val"}, "split");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("val"), std::string::npos) << r.err;
  r = Eval({"--results", csv, "--vsd-delta", "-1"}, "delta");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--vsd-delta"), std::string::npos) << r.err;
  r = Eval({"--results", csv, "--gt", Path("gt.json")}, "gtboth");  // --gt excludes --dataset
  EXPECT_EQ(r.code, 2);
  r = Eval({"--results", csv, "--mesh", "a=b.ply"}, "mesh");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--mesh"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace posefilter
