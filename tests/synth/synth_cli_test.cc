// `posefilter synth`: writes scenes, rejects bad option values with a non-zero exit.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.h"
#include "posefilter/scene_io.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

int RunSynthCli(std::vector<std::string> args) {
  args.insert(args.begin(), "synth");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return cli::RunSynth(int(args.size()), argv.data());
}

std::string TempDir(const std::string& tag) { return testing_util::FreshTempPath("synthcli_" + tag).string(); }

TEST(SynthCli, WritesScenes) {
  const std::string out = TempDir("ok");
  ASSERT_EQ(RunSynthCli({"--out", out, "--count", "2", "--seed", "5", "--target", "torus", "--occlusion", "0.3",
                 "--clutter", "2", "--false-positives", "1"}),
            0);
  for (const char* scene : {"scene_000", "scene_001"}) {
    const fs::path d = fs::path(out) / scene;
    for (const char* f : {"depth.png", "camera.json", "gt.json", "torus.ply", "detections.json", "prior.pyr",
                          "classes.txt", "label.png", "rgb.png"})
      EXPECT_TRUE(fs::exists(d / f)) << (d / f);
    const auto gt = ReadGtJson((d / "gt.json").string());
    ASSERT_EQ(gt.size(), 1u);
    EXPECT_EQ(gt[0].obj, "torus");
  }
  // Scene i uses seed + i: scene_001 of seed 5 equals scene_000 of seed 6.
  const std::string out2 = TempDir("ok2");
  ASSERT_EQ(RunSynthCli({"--out", out2, "--seed", "6", "--target", "torus", "--occlusion", "0.3", "--clutter", "2",
                 "--false-positives", "1"}),
            0);
  EXPECT_TRUE(ReadGtJson(out + "/scene_001/gt.json")[0].T_cam_obj.isApprox(
      ReadGtJson(out2 + "/scene_000/gt.json")[0].T_cam_obj, 1e-9));
  fs::remove_all(out);
  fs::remove_all(out2);
}

TEST(SynthCli, UserMesh) {
  const std::string out = TempDir("mesh");
  fs::create_directories(out);
  Mesh m = MakeBox(100, 60, 40, "widget");  // millimetres
  SaveMeshPly(m, out + "/widget.ply");
  ASSERT_EQ(RunSynthCli({"--out", out, "--mesh", out + "/widget.ply", "--unit-scale", "0.001", "--no-missing-edges"}), 0);
  const auto gt = ReadGtJson(out + "/scene_000/gt.json");
  EXPECT_EQ(gt[0].obj, "widget");
  const Mesh back = LoadMesh(out + "/scene_000/widget.ply");
  EXPECT_NEAR(back.Max().x() - back.Min().x(), 0.1, 1e-6);
  fs::remove_all(out);
}

TEST(SynthCli, RejectsBadOptions) {
  const std::string out = TempDir("bad");
  EXPECT_NE(RunSynthCli({"--out", out, "--occlusion", "2"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--target", "banana"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--miss-prob", "-1"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--count", "0"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--mesh", out + "/missing.ply"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--mesh", "x.ply", "--unit-scale", "-1"}), 0);
  EXPECT_NE(RunSynthCli({"--out", out, "--target", "box", "--mesh", "x.ply"}), 0);  // exclusive
  EXPECT_NE(RunSynthCli({"--occlusion", "0.3"}), 0);                                 // --out required
  EXPECT_FALSE(fs::exists(out + "/scene_000"));
  fs::remove_all(out);
}

// The shapes world's options, flags of SynthOptionTable's rows, on the YCB worlds: those the YCB
// worlds read pass the check; the others, either form of a switch, are refused by name.
TEST(SynthCli, ShapeOptionsOnTheYcbWorlds) {
  const std::string out = TempDir("ycbv");
  const std::string models = TempDir("ycbv_models");  // no meshes: a world that passes the check fails later
  struct Case {
    std::vector<std::string> flag;
    std::string message;  // "" = passes the check
  };
  const Case cases[] = {
      {{"--noise", "0.002"}, "--noise does not apply to --world room (shapes only)"},
      {{"--no-missing-edges"}, "--missing-edges/--no-missing-edges does not apply"},
      {{"--missing-edges"}, "--missing-edges/--no-missing-edges does not apply"},
      {{"--target", "box"}, "--target does not apply"},
      {{"--unit-scale", "2"}, "--unit-scale does not apply"},
      {{"--box-jitter", "3"}, ""},
      {{"--max-distance", "1.2"}, ""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.flag[0]);
    std::vector<std::string> args = {"--out", out, "--world", "room", "--models", models};
    args.insert(args.end(), c.flag.begin(), c.flag.end());
    testing::internal::CaptureStderr();
    EXPECT_EQ(RunSynthCli(args), 1);
    const std::string err = testing::internal::GetCapturedStderr();
    if (c.message.empty())
      EXPECT_EQ(err.find("does not apply"), std::string::npos) << err;
    else
      EXPECT_NE(err.find(c.message), std::string::npos) << err;
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(SynthCli, BinaryExitStatus) {
  const std::string out = TempDir("bin");
  const std::string cli = POSEFILTER_CLI_PATH;
  EXPECT_EQ(std::system((cli + " synth --out " + out + " --clutter 1 > /dev/null").c_str()), 0);
  EXPECT_TRUE(fs::exists(out + "/scene_000/depth.png"));
  const int bad = std::system((cli + " synth --out " + out + " --target banana 2> /dev/null").c_str());
  EXPECT_TRUE(WIFEXITED(bad) && WEXITSTATUS(bad) == 1) << bad;
  fs::remove_all(out);
}

}  // namespace
}  // namespace posefilter
