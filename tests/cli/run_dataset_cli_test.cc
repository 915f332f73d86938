// `posefilter run-dataset` (apps/run_dataset_cmd.cc) on the tiny synthetic BOP dataset: the CSV,
// the progress bar, resuming, rows kept after an error, detections input and usage errors.
// Filter budgets are tiny (the rows' accuracy is not the point here; eval tests check metrics).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <tuple>
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
  // eval's --json is never a file of the dataset it reads.
  fs::path dataset_file;
  for (const auto& e : fs::recursive_directory_iterator(tiny_->root))
    if (e.is_regular_file() && e.path().extension() == ".json") dataset_file = e.path();
  ASSERT_FALSE(dataset_file.empty());
  const std::string file_before = ReadFile(dataset_file);
  r = RunCli({"eval", "--dataset", tiny_->root, "--results", csv, "--json", dataset_file.string(), "--quiet"},
             dir() / "eval_over");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("is a file of the input folder --dataset"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(dataset_file), file_before);
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

// A crash of the machine mid-append leaves a torn last row. The rerun removes it and the complete
// rows of its image, estimates that image again, and ends with the rows of an uninterrupted run.
TEST_F(RunDatasetCliTest, TornLastRowIsRedone) {
  const std::string fresh = Path("fresh.csv");
  ASSERT_EQ(Run(tiny_->root, fresh, {"--gt-boxes", "0"}, "fresh").code, 0);
  const std::string full = ReadFile(fresh);
  ASSERT_EQ(testing_util::Lines(full).size(), 4u) << full;
  // Cut the file in the middle of its last row (image 3).
  const std::string csv = Path("r.csv");
  const std::size_t last_row = full.rfind('\n', full.size() - 2) + 1;
  testing_util::WriteFile(csv, full.substr(0, last_row + 9));
  RunResult r = Run(tiny_->root, csv, {"--gt-boxes", "0"}, "resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("torn row"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("1 image(s) estimated, 2 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(RowsWithoutTime(ReadFile(csv)), RowsWithoutTime(full));
  // A fragment too short to name its image: the last complete image is redone too.
  testing_util::WriteFile(csv, full.substr(0, last_row + 2));
  r = Run(tiny_->root, csv, {"--gt-boxes", "0"}, "resume_short");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 image(s) estimated, 1 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(RowsWithoutTime(ReadFile(csv)), RowsWithoutTime(full));
}

TEST_F(RunDatasetCliTest, EmptyDetectionsAndOutputsOverInputsAreRefused) {
  const std::string empty = Write("empty.json", "[]");
  RunResult r = Run(tiny_->root, Path("r.csv"), {"--detections", empty}, "empty");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("empty.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no detections"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("r.csv")));

  const std::string dets = Write("dets.json", R"([
      {"scene_id": 1, "image_id": 2, "category_id": 2, "bbox": [250, 150, 140, 160], "score": 0.9}])");
  const std::string before = ReadFile(dets);
  r = Run(tiny_->root, dets, {"--detections", dets}, "over");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("would be overwritten"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(dets), before);
  r = Run(tiny_->root, Path("no_dir/r.csv"), {"--gt-boxes", "0"}, "nodir");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;

  // An existing file that is not a results CSV, without a final newline (what the torn-row
  // repair cuts): refused, and left byte for byte as it was.
  const std::string gt = Write("gt.json", "{\"objects\": []}");
  r = Run(tiny_->root, gt, {"--gt-boxes", "0"}, "not_csv");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("not a results CSV"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("left as it is"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(gt), "{\"objects\": []}");
}

// One writer per CSV: while another process holds the file's lock, a run stops with an error
// and the file keeps its bytes; once the lock is released, the run proceeds.
TEST_F(RunDatasetCliTest, ASecondWriterOfTheSameCsvIsRefused) {
  const std::string csv = Write("locked.csv", std::string(kBopCsvHeader) + "\n");
  const int fd = ::open(csv.c_str(), O_RDWR);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  RunResult r = Run(tiny_->root, csv, {"--gt-boxes", "0", "--limit", "1"}, "locked");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("another run-dataset is writing it"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(csv), std::string(kBopCsvHeader) + "\n");
  ::close(fd);
  r = Run(tiny_->root, csv, {"--gt-boxes", "0", "--limit", "1"}, "unlocked");
  EXPECT_EQ(r.code, 0) << r.err;
}

// Complete data rows of a results CSV as (scene, image, object) keys, and whether any repeats.
std::vector<std::tuple<int, int, int>> RowKeys(const std::string& csv_text) {
  std::vector<std::tuple<int, int, int>> keys;
  const auto lines = testing_util::Lines(csv_text);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    int scene = 0, im = 0, obj = 0;
    if (std::sscanf(lines[i].c_str(), "%d,%d,%d", &scene, &im, &obj) == 3) keys.emplace_back(scene, im, obj);
  }
  return keys;
}

// run-dataset killed with SIGKILL at random moments, 20 runs in a row, each resuming the last:
// after every kill the CSV holds only whole, distinct rows, and a run that completes leaves
// exactly the rows of an uninterrupted run (the CSV is then removed and the next run starts
// over). Kill times are seeded and drawn over the expected time of the remaining images, so
// kills land in every phase: start-up, mid-image, between appends.
TEST_F(RunDatasetCliTest, SigkillLoopLosesNoRow) {
  constexpr int kImages = 8;
  const fs::path root = dir() / "ds8";
  testing_util::MakeTinyBop(root, kImages);
  const std::vector<std::string> base = {"run-dataset", "--dataset", root.string(), "--gt-boxes", "0", "--particles",
                                         "48", "--iterations", "4", "--restarts", "1", "--threads", "1", "--quiet"};
  auto args_for = [&](const std::string& csv) {
    std::vector<std::string> a = base;
    a.push_back("--out");
    a.push_back(csv);
    return a;
  };
  auto timed_run = [&](const std::string& csv, const std::string& capture) {
    const auto t0 = std::chrono::steady_clock::now();
    const RunResult r = RunCli(args_for(csv), dir() / capture);
    EXPECT_EQ(r.code, 0) << r.err;
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  // The uninterrupted run gives the expected rows; a second run on its CSV (nothing to do) the
  // start-up time.
  const std::string fresh = Path("fresh.csv");
  const double whole_ms = timed_run(fresh, "fresh");
  const double startup_ms = timed_run(fresh, "nothing_to_do");
  const double per_image_ms = std::max(1.0, (whole_ms - startup_ms) / kImages);
  const std::string expected = ReadFile(fresh);
  ASSERT_EQ(RowKeys(expected).size(), std::size_t(kImages)) << expected;

  const std::string csv = Path("killed.csv");
  std::vector<std::string> argv_s = args_for(csv);
  argv_s.insert(argv_s.begin(), POSEFILTER_CLI_PATH);
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::mt19937 rng(20261205);
  int killed = 0, completed = 0;
  for (int run = 0; run < 20; ++run) {
    SCOPED_TRACE("run " + std::to_string(run));
    const std::size_t rows_before = fs::exists(csv) ? RowKeys(ReadFile(csv)).size() : 0;
    const double remaining_ms = startup_ms + per_image_ms * double(kImages - int(rows_before));
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, 1);
      ::dup2(devnull, 2);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(long(1000 * std::uniform_real_distribution<double>(0, remaining_ms)(rng))));
    ::kill(pid, SIGKILL);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    if (WIFSIGNALED(status)) {
      ++killed;
    } else {
      ASSERT_TRUE(WIFEXITED(status));
      ASSERT_EQ(WEXITSTATUS(status), 0) << "run-dataset failed on resume";
    }
    if (!fs::exists(csv)) continue;
    const std::string text = ReadFile(csv);
    const auto keys = RowKeys(text);
    const std::set<std::tuple<int, int, int>> distinct(keys.begin(), keys.end());
    EXPECT_EQ(distinct.size(), keys.size()) << "duplicate rows:\n" << text;
    EXPECT_GE(keys.size(), rows_before) << "rows lost:\n" << text;
    if (!WIFSIGNALED(status)) {  // completed: every row, as in the uninterrupted run
      ++completed;
      EXPECT_EQ(RowsWithoutTime(text), RowsWithoutTime(expected));
      fs::remove(csv);
    }
  }
  EXPECT_GE(killed, 8) << "too few runs were killed mid-way to test anything";
  // Finish the last cycle.
  timed_run(csv, "last");
  EXPECT_EQ(RowsWithoutTime(ReadFile(csv)), RowsWithoutTime(expected));
  // No temporary file left beside the CSV by a killed atomic rewrite.
  for (const auto& e : fs::directory_iterator(dir()))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  std::printf("SIGKILL loop: %d of 20 runs killed, %d completed a cycle\n", killed, completed);
}

}  // namespace
}  // namespace posefilter
