// The fixture of the `posefilter estimate` CLI tests (tests/cli/*_cli_test.cc): one synthetic
// scene made once per test binary run, a scratch folder per test, and the checks of an input
// error (exit 1, one line naming the file or option) and a usage error (exit 2).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "posefilter/scene_io.h"
#include "test_util.h"

namespace posefilter {

// The scene every test uses: `posefilter synth --target box --seed 3`, made once.
class CliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new std::filesystem::path(testing_util::FreshTempPath("cli_test"));
    std::filesystem::create_directories(*root_);
    const testing_util::RunResult r = Run({"synth", "--out", (*root_ / "synth").string(), "--target", "box", "--seed", "3"});
    ASSERT_EQ(r.code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*root_);
    delete root_;
    root_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(Scene("depth.png"))) << "synth did not write the scene";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = *root_ / info->name();
    std::filesystem::create_directories(dir_);
  }

  // Runs the binary with `args`; stdout and stderr captured through files.
  static testing_util::RunResult Run(const std::vector<std::string>& args) {
    static int n = 0;
    return testing_util::RunCli(args, *root_ / ("run_" + std::to_string(n++)));
  }

  static std::string Scene(const std::string& file) { return (*root_ / "synth" / "scene_000" / file).string(); }
  std::string Path(const std::string& file) const { return (dir_ / file).string(); }

  // `estimate` argv on `depth` and `camera`, --quiet, then `extra` (CLI11 rejects an option
  // given twice, so each test passes every other option once, in `extra`).
  static std::vector<std::string> EstimateArgs(const std::string& depth, const std::string& camera,
                                               const std::vector<std::string>& extra) {
    std::vector<std::string> a = {"estimate", "--depth", depth, "--camera", camera, "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  static std::vector<std::string> Small() { return {"--particles", "64", "--iterations", "5", "--restarts", "1"}; }

  // An input error: exit 1 and exactly one stderr line "posefilter <cmd>: error: …<needle>…".
  static void ExpectInputError(const testing_util::RunResult& r, const std::string& cmd, const std::string& needle) {
    EXPECT_EQ(r.code, 1) << r.err;
    const auto lines = testing_util::Lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("posefilter " + cmd + ": error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << needle << "' not in: " << lines[0];
  }
  // A usage error (CLI11's parser): exit 2 and exactly one stderr line "posefilter <cmd>: error:
  // …<needle>…" (for a command's own options; the top-level dispatcher has its own format).
  static void ExpectUsageError(const testing_util::RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.code, 2) << r.err;
    const auto lines = testing_util::Lines(r.err);
    ASSERT_FALSE(lines.empty());
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << needle << "' not in: " << lines[0];
    if (lines[0].rfind("posefilter ", 0) == 0 && lines[0].find(": error: ") != std::string::npos)
      EXPECT_EQ(lines.size(), 1u) << r.err;
  }

  // Reads a results JSON written by estimate and checks it holds one finite "box" pose.
  static ObjectResult ExpectOneBoxResult(const std::string& path, int max_iterations) {
    const std::vector<ObjectResult> res = ReadResultsJson(path);
    EXPECT_EQ(res.size(), 1u) << path;
    if (res.size() != 1) return {};
    const ObjectResult& o = res[0];
    EXPECT_EQ(o.obj, "box");
    EXPECT_TRUE(o.T_cam_obj.matrix().allFinite());
    EXPECT_NEAR(o.T_cam_obj.linear().determinant(), 1.0, 1e-6);
    EXPECT_GT(o.T_cam_obj.translation().z(), 0.1);  // in front of the camera
    EXPECT_GE(o.weight, 0.0);
    EXPECT_LE(o.weight, 1.0);
    EXPECT_GE(o.iterations, 1);
    EXPECT_LE(o.iterations, max_iterations);
    return o;
  }

  inline static std::filesystem::path* root_ = nullptr;
  std::filesystem::path dir_;
};


}  // namespace posefilter
