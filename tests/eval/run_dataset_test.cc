// tests/eval/run_dataset_test.cc — RunDataset (posefilter/run_dataset.h) on the tiny BOP
// dataset: every image's rows, resuming, a share of the images giving the same rows, and its
// input errors.
#include <gtest/gtest.h>

#include <algorithm>

#include "bop_test_dataset.h"
#include "posefilter/run_dataset.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::TinyBopTest;

class RunDatasetTest : public TinyBopTest {
 protected:
  RunDatasetTest() : TinyBopTest("run_dataset") {}
  // The cheapest run: tens of ms per target (the tests compare runs, not accuracy).
  RunDatasetOptions Options(const std::string& out) const {
    RunDatasetOptions o;
    o.dataset = base_dir_->string();
    o.prior = DatasetPriorKind::kGtBoxes;
    o.gt_jitter_px = 2;
    o.out = (dir() / out).string();
    o.no_time = true;
    o.filter.num_particles = 64;
    o.filter.stop.max_iterations = 3;
    o.filter.restarts = 1;
    o.filter.polish.steps = 0;
    o.filter.threads = 1;
    return o;
  }
  static std::vector<std::string> Lines(const std::string& path) {
    std::vector<std::string> lines;
    std::ifstream in(path);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  }
};

TEST_F(RunDatasetTest, WritesEveryImageThenResumesAndAShareGivesTheSameRows) {
  const RunDatasetOptions o = Options("all.csv");
  std::vector<std::pair<int, int>> seen;
  RunDatasetCallbacks cb;
  cb.on_image = [&](const DatasetImageDone& d) {
    seen.push_back({d.image->scene_id, d.image->im_id});
    EXPECT_EQ(d.total, 3);
    EXPECT_EQ(d.rows->size(), 1u);
  };
  const RunDatasetSummary s = RunDataset(o, cb);
  EXPECT_EQ(s.images, 3);
  EXPECT_EQ(s.estimated, 3);
  EXPECT_EQ(s.rows, 3);
  EXPECT_EQ(s.failed, 0);
  EXPECT_EQ(seen, (std::vector<std::pair<int, int>>{{1, 1}, {1, 2}, {1, 3}}));
  const std::vector<std::string> all = Lines(o.out);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0], kBopCsvHeader);

  // Again: every image is in the CSV, nothing is estimated, a note says so.
  std::vector<std::string> notes;
  cb = {};
  cb.on_note = [&](const std::string& n) { notes.push_back(n); };
  const RunDatasetSummary again = RunDataset(o, cb);
  EXPECT_EQ(again.skipped, 3);
  EXPECT_EQ(again.estimated, 0);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("3 of 3 image(s) already in"), std::string::npos) << notes[0];
  EXPECT_EQ(Lines(o.out), all);

  // One image alone (as a Dask task runs it): the same row as in the whole run.
  RunDatasetOptions share = Options("share.csv");
  share.images = {{1, 2}};
  EXPECT_EQ(RunDataset(share).images, 1);
  EXPECT_EQ(Lines(share.out), (std::vector<std::string>{all[0], all[2]}));
  EXPECT_EQ(DatasetTargetImages(OpenDataset(o.dataset, "test")), (std::vector<std::pair<int, int>>{{1, 1}, {1, 2}, {1, 3}}));
}

TEST_F(RunDatasetTest, NamesItsInputErrors) {
  RunDatasetOptions o = Options("err.csv");
  o.images = {{1, 9}};
  ExpectError([&] { RunDataset(o); }, {"scene 1, image 9", "no targets"});
  o = Options("err.csv");
  o.gt_box_score = 2;
  ExpectError([&] { RunDataset(o); }, {"gt_box_score"});
  o = Options("not_a_csv.txt");
  testing_util::WriteFile(o.out, "hello\n");
  o.out_label = "--out";
  ExpectError([&] { RunDataset(o); }, {"--out", "not a results CSV"});
  EXPECT_EQ(testing_util::ReadFile(o.out), "hello\n");
}

}  // namespace
}  // namespace posefilter
