// End-to-end tests of the hw engine through the built `posefilter` binary: `hw-report` (table
// and --json, input errors) and `--engine hw` accepted by the filter commands.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::FreshTempPath;
using testing_util::ReadFile;
using testing_util::RunCli;
using testing_util::RunResult;

class HwCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTempPath("hw_cli_test");
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(HwCliTest, HwReportPrintsTheTableAndWritesJson) {
  const fs::path json = dir_ / "report.json";
  const RunResult r = RunCli({"hw-report", "--target", "box", "--iterations", "2", "--particles", "30", "--cores", "1,5",
                              "--json", json.string()},
                             dir_ / "report");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("depth distribution"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("faces / rendered faces"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("M = 5 cores"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("configuration \"thesis\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("side by side"), std::string::npos) << r.out;
  const nlohmann::json all = nlohmann::json::parse(ReadFile(json));
  // Table 7.2/7.3 [HARDWARE.md]'s figures and both configurations.
  ASSERT_EQ(all["thesis"]["tables"].size(), 3u);
  EXPECT_EQ(all["thesis"]["tables"][1]["average_iteration_ms"], 120.0);
  EXPECT_TRUE(all["thesis"]["tables"][0]["first_iteration_ms"].get<double>() < 0);  // not reported
  for (const char* name : {"thesis", "ours"}) {
    SCOPED_TRACE(name);
    const nlohmann::json& j = all["configurations"][name];
    EXPECT_EQ(j["particles"], 30);
    EXPECT_EQ(j["iterations"], 2);
    ASSERT_EQ(j["models"].size(), 2u);
    EXPECT_EQ(j["models"][0]["cores"], 1);
    // One core never shares a depth pixel; five cores share some (windows overlap).
    EXPECT_EQ(j["models"][0]["depth_reads_shared"], j["models"][0]["depth_reads_unshared"]);
    EXPECT_LT(j["models"][1]["depth_reads_shared"].get<double>(), j["models"][1]["depth_reads_unshared"].get<double>());
    EXPECT_GT(j["models"][0]["average_iteration_ms"].get<double>(), j["models"][1]["average_iteration_ms"].get<double>());
    EXPECT_GT(j["faces_ratio"].get<double>(), 1.0);
    EXPECT_FALSE(j["models"][1]["modules"].empty());
  }
  // The thesis's mode has no z pass: its raster cores do less per particle than ours.
  const auto raster_ms = [&](const char* name) {
    for (const auto& m : all["configurations"][name]["models"][0]["modules"])
      if (m["module"] == "raster_core") return m["ms"].get<double>();
    return -1.0;
  };
  EXPECT_GT(raster_ms("thesis"), 0.0);
  EXPECT_LT(raster_ms("thesis"), raster_ms("ours"));
  // The DDR latency per module: the depth distributor's one burst (its copy of the depth image)
  // and the vertex multiplier's four (the model); none for the raster cores (on-chip only).
  const auto memory = [&](const char* module) {
    for (const auto& m : all["configurations"]["ours"]["models"][1]["modules"])
      if (m["module"] == module) return m["memory_latency_cycles"].get<double>();
    return -1.0;
  };
  EXPECT_EQ(memory("depth_distributor"), 64.0);
  EXPECT_EQ(memory("vertex_multiplier"), 4 * 64.0);
  EXPECT_EQ(memory("raster_core"), 0.0);
  EXPECT_GT(all["configurations"]["ours"]["models"][1]["memory_latency_ms"].get<double>(), 0.0);
}

// A real frame of the shared YCB-Video data: its depth, its label mask's box as the prior, the
// gelatin box's mesh.
TEST_F(HwCliTest, HwReportModelsARealFrame) {
  const fs::path frame = testing_util::YcbvDataDir() / "scenes" / "ycbv_0000_000001";
  if (!fs::exists(frame / "depth.png")) GTEST_SKIP() << "no shared YCB-Video frame at " << frame;
  const fs::path json = dir_ / "frame.json";
  const RunResult r = RunCli({"hw-report", "--frame", frame.string(), "--object", "061_foam_brick", "--iterations", "2",
                              "--particles", "40", "--cores", "5", "--configs", "thesis", "--json", json.string()},
                             dir_ / "frame");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("frame ycbv_0000_000001, 061_foam_brick"), std::string::npos) << r.out;
  const nlohmann::json all = nlohmann::json::parse(ReadFile(json));
  EXPECT_EQ(all["object"], "061_foam_brick");
  const nlohmann::json& j = all["configurations"]["thesis"];
  EXPECT_EQ(j["particles"], 40);
  EXPECT_GT(j["mean_window_area"].get<double>(), 0.0);
  EXPECT_LT(j["mean_window_area"].get<double>(), 200.0 * 200.0);  // the frame's windows, not forced to 200x200
  EXPECT_GT(j["models"][0]["average_iteration_ms"].get<double>(), 0.0);
}

TEST_F(HwCliTest, HwReportNamesABadFrame) {
  RunResult r = RunCli({"hw-report", "--frame", (dir_ / "nowhere").string(), "--iterations", "1"}, dir_ / "no_frame");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--frame"), std::string::npos) << r.err;
  fs::create_directories(dir_ / "half");
  r = RunCli({"hw-report", "--frame", (dir_ / "half").string(), "--iterations", "1"}, dir_ / "half_frame");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("depth.png"), std::string::npos) << r.err;
  r = RunCli({"hw-report", "--object", "025_mug", "--iterations", "1"}, dir_ / "object_alone");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--object applies to --frame"), std::string::npos) << r.err;
}

TEST_F(HwCliTest, HwReportRejectsBadOptions) {
  RunResult r = RunCli({"hw-report", "--cores", "11", "--iterations", "1"}, dir_ / "bad_cores");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("cores"), std::string::npos) << r.err;
  r = RunCli({"hw-report", "--engine", "reference", "--iterations", "1"}, dir_ / "bad_engine");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--engine"), std::string::npos) << r.err;
  r = RunCli({"hw-report", "--particles", "600", "--iterations", "1"}, dir_ / "bad_particles");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("510"), std::string::npos) << r.err;
  r = RunCli({"hw-report", "--profile-every", "0", "--iterations", "1"}, dir_ / "bad_every");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("profile_every"), std::string::npos) << r.err;
  r = RunCli({"hw-report", "--configs", "fpga", "--iterations", "1"}, dir_ / "bad_configs");
  EXPECT_EQ(r.code, 2);  // CLI11 usage error naming the option
  EXPECT_NE(r.err.find("--configs"), std::string::npos) << r.err;
}

TEST_F(HwCliTest, SuiteRunsTheHwEngine) {
  const RunResult r = RunCli({"suite", "--count", "1", "--targets", "box", "--engine", "hw", "--particles", "64",
                              "--iterations", "3", "--restarts", "1"},
                             dir_ / "suite");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("recall"), std::string::npos) << r.out;
  const RunResult bad = RunCli({"suite", "--count", "1", "--engine", "fpga"}, dir_ / "suite_bad");
  EXPECT_EQ(bad.code, 2);  // CLI11 usage error: not one of the engines
}

}  // namespace
}  // namespace posefilter
