// The documented dataset example (docs/DATASETS.md, scripts/ycbv_bop_example.sh) on the real
// YCB-Video frames of ../shared/data/ycbv: run-dataset → results CSV → eval --dataset prints a
// per-object table with ADD-S and AUC. Skips when the shared folder is absent. A tiny budget
// (one frame, few particles, no polish) keeps it short; only the pipeline is checked here, not
// the accuracy (the filter's accuracy has its own tests and the suite).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::Lines;
using testing_util::ReadFile;
using testing_util::RunCli;
using testing_util::RunResult;
using testing_util::ScratchDir;

TEST(YcbvExampleCli, RunDatasetThenEvalPrintsAddSAndAucPerObject) {
  const fs::path data = testing_util::YcbvDataDir();
  if (!fs::exists(data / "scenes")) GTEST_SKIP() << "no " << data;
  ScratchDir dir("ycbv_example");
  const std::string csv = dir.Path("ycbv.csv"), json = dir.Path("eval.json");
  RunResult r = RunCli({"run-dataset", "--dataset", data.string(), "--gt-boxes", "8", "--out", csv, "--limit", "1",
                        "--particles", "64", "--iterations", "3", "--restarts", "1", "--polish-steps", "0", "--quiet"},
                       dir.dir() / "run");
  ASSERT_EQ(r.code, 0) << r.err;
  // One row per object of the first frame, BOP CSV header first.
  const std::vector<std::string> rows = Lines(ReadFile(csv));
  ASSERT_EQ(rows.size(), 4u) << ReadFile(csv);
  EXPECT_EQ(rows[0], "scene_id,im_id,obj_id,score,R,t,time");

  r = RunCli({"eval", "--dataset", data.string(), "--results", csv, "--limit", "1", "--json", json}, dir.dir() / "eval");
  ASSERT_EQ(r.code, 0) << r.err;
  bool header = false;
  int object_rows = 0;
  for (const std::string& l : Lines(r.out)) {
    if (l.find("ADD-S") != std::string::npos && l.find("AUC ADD-S") != std::string::npos) header = true;
    for (const char* obj : {"009_gelatin_box", "025_mug", "061_foam_brick"})
      if (l.rfind(obj, 0) == 0) ++object_rows;
  }
  EXPECT_TRUE(header) << r.out;
  EXPECT_EQ(object_rows, 3) << r.out;
  // The JSON carries the same per-object numbers, each a recall or an area in [0, 1].
  const nlohmann::json j = nlohmann::json::parse(ReadFile(json));
  const std::string text = j.dump();
  for (const char* obj : {"009_gelatin_box", "025_mug", "061_foam_brick"})
    EXPECT_NE(text.find(obj), std::string::npos) << obj;
}

}  // namespace
}  // namespace posefilter
