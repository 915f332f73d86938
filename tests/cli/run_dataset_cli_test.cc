// `posefilter run-dataset` (apps/run_dataset_cmd.cc) on the tiny synthetic BOP dataset: the CSV,
// the progress bar, resuming, rows kept after an error, detections input and usage errors.
// Filter budgets are tiny (the rows' accuracy is not the point here; eval tests check metrics).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "eval/bop_test_dataset.h"
#include "posefilter/bop.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ReadFile;
using testing_util::RunCli;
using testing_util::RunResult;

class RunDatasetCliTest : public testing_util::TinyBopTest {
 protected:
  RunDatasetCliTest() : TinyBopTest("run_dataset") {}
  // run-dataset with a tiny filter budget plus `extra`.
  RunResult Run(const std::string& dataset, const std::string& csv, const std::vector<std::string>& extra,
                const std::string& capture = "run") {
    std::vector<std::string> args = {"run-dataset", "--dataset", dataset, "--out", csv, "--particles", "24",
                                     "--iterations", "2", "--restarts", "1", "--elite", "2", "--threads", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunCli(args, dir() / capture);
  }
};

// Rows of a CSV without the time column (which differs between runs).
std::vector<std::string> RowsWithoutTime(const std::string& csv_text) {
  std::vector<std::string> out;
  for (const auto& l : testing_util::Lines(csv_text)) out.push_back(l.substr(0, l.rfind(',')));
  return out;
}

TEST_F(RunDatasetCliTest, WritesResumesAndMatchesAnUninterruptedRun) {
  const std::string csv = Path("r.csv");
  RunResult r = Run(tiny_->root, csv, {"--gt-boxes", "0", "--limit", "2"}, "first");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2/2 images"), std::string::npos) << r.err;
  std::vector<BopResult> rows = ReadBopResultsCsv(csv);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].im_id, 1);
  EXPECT_EQ(rows[0].obj_id, 1);
  EXPECT_EQ(rows[1].im_id, 2);
  EXPECT_EQ(rows[1].obj_id, 2);
  EXPECT_GT(rows[0].time_s, 0);
  EXPECT_GT(rows[0].score, 0);
  const std::string after_first = ReadFile(csv);

  // Resume: images 1 and 2 are skipped, image 3 appended; the earlier bytes stay.
  r = Run(tiny_->root, csv, {"--gt-boxes", "0"}, "second");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 image(s) estimated, 2 skipped"), std::string::npos) << r.out;
  const std::string after_second = ReadFile(csv);
  EXPECT_EQ(after_second.substr(0, after_first.size()), after_first);
  rows = ReadBopResultsCsv(csv);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[2].im_id, 3);
  EXPECT_EQ(rows[2].obj_id, 3);

  // Nothing left to do.
  r = Run(tiny_->root, csv, {"--gt-boxes", "0"}, "third");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("0 image(s) estimated, 3 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(ReadFile(csv), after_second);

  // An uninterrupted run gives the same rows (seeds derive from scene, image and object).
  const std::string fresh = Path("fresh.csv");
  r = Run(tiny_->root, fresh, {"--gt-boxes", "0"}, "fresh");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(RowsWithoutTime(ReadFile(fresh)), RowsWithoutTime(after_second));

  // And eval reads it.
  const std::string json = Path("eval.json");
  r = RunCli({"eval", "--dataset", tiny_->root, "--results", csv, "--json", json, "--quiet"}, dir() / "eval");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("AR"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 of 3 gt instance(s) without an estimate"), std::string::npos) << r.out;
}

TEST_F(RunDatasetCliTest, RowsWrittenBeforeAnErrorAreKept) {
  const std::string root = Copy();
  const fs::path depth2 = fs::path(root) / "test/000001/depth/000002.png";
  const fs::path saved = dir() / "saved.png";
  fs::copy_file(depth2, saved);
  fs::remove(depth2);
  const std::string csv = Path("r.csv");
  RunResult r = Run(root, csv, {"--gt-boxes", "2"}, "broken");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("000002.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("image 2"), std::string::npos) << r.err;
  std::vector<BopResult> rows = ReadBopResultsCsv(csv);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].im_id, 1);

  fs::copy_file(saved, depth2);
  r = Run(root, csv, {"--gt-boxes", "2"}, "fixed");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 image(s) estimated, 1 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(ReadBopResultsCsv(csv).size(), 3u);
}

TEST_F(RunDatasetCliTest, DetectionsAndTargetsFile) {
  const std::string root = Copy();
  // Targets: image 2 only, two instances of the cylinder: each instance gets a prior of one of
  // the class's detections (best first), so two rows come out.
  testing_util::WriteFile(fs::path(root) / "test_targets_bop19.json",
                          R"([{"scene_id": 1, "im_id": 2, "obj_id": 2, "inst_count": 2}])");
  const std::string dets = Write("dets.json", R"([
      {"scene_id": 1, "image_id": 2, "category_id": 2, "bbox": [250, 150, 140, 160], "score": 0.9},
      {"scene_id": 1, "image_id": 2, "category_id": 2, "bbox": [280, 180, 100, 100], "score": 0.3},
      {"scene_id": 1, "image_id": 2, "category_id": 3, "bbox": [400, 300, 60, 60], "score": 0.5}])");
  const std::string csv = Path("r.csv");
  RunResult r = Run(root, csv, {"--detections", dets, "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("ETA"), std::string::npos) << "--quiet: " << r.err;
  const std::vector<BopResult> rows = ReadBopResultsCsv(csv);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].im_id, 2);
  EXPECT_EQ(rows[1].obj_id, 2);
  EXPECT_EQ(rows[0].time_s, rows[1].time_s);

  const std::string bad = Write("bad.json", R"([
      {"scene_id": 1, "image_id": 2, "category_id": 77, "bbox": [250, 150, 140, 160], "score": 0.9}])");
  r = Run(root, Path("r2.csv"), {"--detections", bad}, "bad");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("category_id 77"), std::string::npos) << r.err;
}

TEST_F(RunDatasetCliTest, UsageAndInputErrors) {
  const std::string csv = Path("r.csv");
  RunResult r = Run(tiny_->root, csv, {}, "noprior");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--gt-boxes"), std::string::npos) << r.err;
  r = Run(tiny_->root, csv, {"--gt-boxes", "1", "--detections", Path("d.json")}, "both");
  EXPECT_EQ(r.code, 2);
  r = Run(Path("nowhere"), csv, {"--gt-boxes", "1"}, "nodir");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  r = Run(tiny_->root, csv, {"--gt-boxes", "-3"}, "neg");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--gt-boxes"), std::string::npos) << r.err;
  r = Run(tiny_->root, csv, {"--gt-boxes", "1", "--limit", "0"}, "limit");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--limit"), std::string::npos) << r.err;
  r = Run(tiny_->root, csv, {"--gt-boxes", "1", "--confidence", "5"}, "confidence");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--confidence"), std::string::npos) << r.err;
  // No ground truth: --gt-boxes and eval cannot work (targets from a file).
  const std::string no_gt = Copy();
  fs::remove(fs::path(no_gt) / "test/000001/scene_gt.json");
  testing_util::WriteFile(fs::path(no_gt) / "test_targets_bop19.json",
                          R"([{"scene_id": 1, "im_id": 1, "obj_id": 1, "inst_count": 1}])");
  r = Run(no_gt, Path("nogt.csv"), {"--gt-boxes", "1"}, "nogt");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("image 1: --gt-boxes needs ground truth"), std::string::npos) << r.err;
  testing_util::WriteFile(Path("gt_rows.csv"), std::string(kBopCsvHeader) + "\n");
  r = RunCli({"eval", "--dataset", no_gt, "--results", Path("gt_rows.csv")}, dir() / "nogt_eval");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("image 1: no ground truth"), std::string::npos) << r.err;
  // A truncated CSV to resume from.
  const std::string trunc = Write("t.csv", std::string(kBopCsvHeader) + "\n1,1,1,0.5,1 0 0\n");
  r = Run(tiny_->root, trunc, {"--gt-boxes", "1"}, "trunc");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("t.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace posefilter
