// `posefilter view` and `estimate --view` (apps/view_cmd.cc, apps/estimate_cmd.cc): the page is
// written with the particle sets, recording them changes no pose, `view --results` shows a
// results JSON without estimating, and bad inputs and outputs are one-line errors that write
// nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "eval/bop_test_dataset.h"
#include "posefilter/bop.h"
#include "posefilter/depth_image.h"
#include "posefilter/scene_io.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ReadFile;
using testing_util::RunResult;

// The data JSON of a viewer page.
nlohmann::json PageData(const std::string& path) {
  const std::string html = ReadFile(path);
  const std::string open = "<script type=\"application/json\" id=\"posefilter-data\">";
  const std::size_t a = html.find(open);
  if (a == std::string::npos) return nullptr;
  const std::size_t b = html.find("</script>", a);
  const std::string text = html.substr(a + open.size(), b - a - open.size());
  return nlohmann::json::parse(text);
}

std::vector<std::string> Join(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST_F(CliTest, EstimateViewWritesThePageAndChangesNoPose) {
  const std::vector<std::string> base =
      Join({"--mesh", Scene("box.ply"), "--prior", Scene("detections.json"), "--polish-steps", "0"}, Small());
  RunResult r = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                 Join(base, {"--out", Path("plain.json")})));
  ASSERT_EQ(r.code, 0) << r.err;
  r = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                       Join(base, {"--out", Path("viewed.json"), "--view", Path("v.html"), "--gt", Scene("gt.json")})));
  ASSERT_EQ(r.code, 0) << r.err;
  const ObjectResult plain = ExpectOneBoxResult(Path("plain.json"), 5), viewed = ExpectOneBoxResult(Path("viewed.json"), 5);
  EXPECT_TRUE(plain.T_cam_obj.matrix().isApprox(viewed.T_cam_obj.matrix(), 1e-12)) << "recording moved the pose";
  const nlohmann::json d = PageData(Path("v.html"));
  ASSERT_TRUE(d.is_object());
  ASSERT_EQ(d["objects"].size(), 1u);
  const nlohmann::json& o = d["objects"][0];
  EXPECT_EQ(o["name"], "box");
  EXPECT_FALSE(o["gt"].is_null());
  EXPECT_GE(o["sets"].size(), 2u);
  EXPECT_LE(o["sets"].size(), 5u);
  EXPECT_EQ(o["sets"][0]["total"], 64);
  EXPECT_NEAR(o["estimate"][3].get<double>(), viewed.T_cam_obj.translation().x(), 1e-9);

  // `view` with the same inputs: the same page (deterministic), --json the same results.
  r = Run(Join({"view", "--depth", Scene("depth.png"), "--camera", Scene("camera.json"), "--quiet", "--out",
                Path("w.html"), "--json", Path("w.json"), "--gt", Scene("gt.json")}, base));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(ReadFile(Path("w.html")), ReadFile(Path("v.html")));
  EXPECT_TRUE(ExpectOneBoxResult(Path("w.json"), 5).T_cam_obj.matrix().isApprox(viewed.T_cam_obj.matrix(), 1e-12));

  // `view --results`: the results JSON on the frame, no particles.
  r = Run({"view", "--depth", Scene("depth.png"), "--camera", Scene("camera.json"), "--mesh", Scene("box.ply"),
           "--results", Path("viewed.json"), "--out", Path("r.html")});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json dr = PageData(Path("r.html"));
  ASSERT_EQ(dr["objects"].size(), 1u);
  EXPECT_TRUE(dr["objects"][0]["sets"].empty());
  for (int k = 0; k < 16; ++k)  // the results JSON holds the pose to 1e-15
    EXPECT_NEAR(dr["objects"][0]["estimate"][k].get<double>(), o["estimate"][k].get<double>(), 1e-9) << k;
}

TEST_F(CliTest, ViewBadInputsAreOneLineErrorsThatWriteNothing) {
  const std::vector<std::string> frame = {"view", "--depth", Scene("depth.png"), "--camera", Scene("camera.json"),
                                          "--mesh", Scene("box.ply")};
  const CameraFile cam = ReadCameraJson(Scene("camera.json"));
  SaveRgbPng(RgbImage(cam.camera.width / 2, cam.camera.height), Path("small.png"));
  testing_util::WriteFile(Path("broken.json"), "{\"objects\": [");
  struct Case {
    std::vector<std::string> args;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{"--results", Path("missing.json"), "--out", Path("a.html")}, "missing.json"},
      {{"--results", Path("broken.json"), "--out", Path("a.html")}, "broken.json"},
      {{"--prior", Scene("detections.json"), "--out", Path("no_dir/a.html")}, "--out"},
      {{"--prior", Scene("detections.json"), "--out", Scene("depth.png")}, "--out"},
      {{"--prior", Scene("detections.json"), "--out", Path("a.html"), "--rgb", Path("small.png")}, "--rgb"},
      {{"--prior", Scene("detections.json"), "--out", Path("a.html"), "--gt", Path("missing_gt.json")}, "missing_gt.json"},
      {{"--results", Scene("depth.png"), "--prior", Scene("detections.json"), "--out", Path("a.html")}, "--results"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[1]);
    ExpectInputError(Run(Join(frame, c.args)), "view", c.needle);
  }
  EXPECT_FALSE(fs::exists(Path("a.html")));
  // A results JSON whose object has no --mesh.
  testing_util::WriteFile(Path("other.json"),
                          R"({"objects": [{"obj": "mug", "x": 0, "y": 0, "z": 0.5, "roll": 0, "pitch": 0, "yaw": 0,
                              "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0,0,0.5], "weight": 0.5, "iterations": 1,
                              "time_ms": 1}]})");
  const RunResult r = Run(Join(frame, {"--results", Path("other.json"), "--out", Path("a.html")}));
  if (r.code == 1) ExpectInputError(r, "view", "'mug' has no --mesh");
  else ADD_FAILURE() << r.err;
  EXPECT_FALSE(fs::exists(Path("a.html")));
  // The page is required; --gt belongs to a page.
  ExpectUsageError(Run({"view", "--depth", Scene("depth.png"), "--camera", Scene("camera.json"), "--mesh",
                        Scene("box.ply")}),
                   "--out");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                    {"--mesh", Scene("box.ply"), "--gt", Scene("gt.json")})),
                   "estimate", "--gt");
}

class ViewRunDatasetTest : public testing_util::TinyBopTest {
 protected:
  ViewRunDatasetTest() : TinyBopTest("view_run_dataset") {}
  RunResult RunDataset(const std::string& csv, const std::vector<std::string>& extra, const std::string& capture) {
    return testing_util::RunCli(Join({"run-dataset", "--dataset", tiny_->root, "--out", csv, "--gt-boxes", "0",
                                      "--limit", "2", "--particles", "24", "--iterations", "2", "--restarts", "1",
                                      "--threads", "1", "--no-time", "--quiet"},
                                     extra),
                                dir() / capture);
  }
};

TEST_F(ViewRunDatasetTest, ChosenImagesGetAPageAndTheRowsStayTheSame) {
  fs::create_directories(dir() / "pages");
  RunResult r = RunDataset(Path("plain.csv"), {}, "plain");
  ASSERT_EQ(r.code, 0) << r.err;
  r = RunDataset(Path("viewed.csv"), {"--view-dir", Path("pages"), "--view-images", "2"}, "viewed");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(ReadFile(Path("plain.csv")), ReadFile(Path("viewed.csv"))) << "recording changed a row";
  std::vector<fs::path> pages;
  for (const auto& e : fs::directory_iterator(dir() / "pages")) pages.push_back(e.path());
  ASSERT_EQ(pages.size(), 1u);
  EXPECT_NE(pages[0].filename().string().find("_000002.html"), std::string::npos) << pages[0];
  const nlohmann::json d = PageData(pages[0].string());
  ASSERT_EQ(d["objects"].size(), 1u);
  EXPECT_FALSE(d["objects"][0]["gt"].is_null());
  EXPECT_EQ(d["objects"][0]["sets"].size(), 2u);

  struct Case {
    std::vector<std::string> args;
    std::string needle;
  };
  for (const Case& c : std::vector<Case>{{{"--view-images", "2"}, "--view-dir"},
                                         {{"--view-dir", Path("missing"), "--view-images", "2"}, "--view-dir"},
                                         {{"--view-dir", Path("pages"), "--view-images", "two"}, "--view-images"}}) {
    r = RunDataset(Path("bad.csv"), c.args, "bad");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(Path("bad.csv")));
  }
}

}  // namespace
}  // namespace posefilter
