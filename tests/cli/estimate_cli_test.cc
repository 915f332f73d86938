// End-to-end tests of the built `posefilter` binary (POSEFILTER_CLI_PATH): `estimate` on a
// synthetic scene (made with `posefilter synth`) with every prior form, its input errors (each
// a non-zero exit and a one-line message naming the file or option), `gt-detections`, `demo`,
// and the dispatcher (unknown command, no arguments).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "posefilter/depth_image.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "cli/cli_fixture.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

using testing_util::FreshTempPath;
using testing_util::Lines;
using testing_util::ReadFile;
using testing_util::RunResult;
using testing_util::WriteFile;


// ---------------------------------------------------------------------------------------------
// estimate: success paths.

// --prior auto on a scene with nothing above the table: "no candidates", exit 1, nothing written.
TEST_F(CliTest, AutoPriorWithoutCandidatesIsAClearError) {
  const CameraFile cam = ReadCameraJson(Scene("camera.json"));
  const DepthImage flat(cam.camera.width, cam.camera.height, 1.2f);  // a wall 1.2 m away, nothing before it
  SaveDepthPng(flat, Path("flat.png"), cam.depth_scale);
  const RunResult r = Run(EstimateArgs(Path("flat.png"), Scene("camera.json"),
                                       {"--mesh", Scene("box.ply"), "--prior", "auto", "--out", Path("r.json")}));
  ExpectInputError(r, "estimate", "--prior auto: no candidates");
  EXPECT_FALSE(std::filesystem::exists(Path("r.json")));
}

TEST_F(CliTest, EstimateWithEveryPriorFormWritesResultsAndOverlay) {
  const CameraFile cam = ReadCameraJson(Scene("camera.json"));
  const std::vector<std::vector<std::string>> priors = {
      {"--prior", Scene("detections.json")},
      {"--prior", Scene("prior.pyr"), "--classes", Scene("classes.txt")},
      {"--prior", "none"},
      {"--prior", "auto"}};
  for (std::size_t i = 0; i < priors.size(); ++i) {
    SCOPED_TRACE(priors[i][1]);
    const std::string out = Path("results" + std::to_string(i) + ".json");
    const std::string overlay = Path("overlay" + std::to_string(i) + ".png");
    std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--out", out, "--overlay", overlay};
    extra.insert(extra.end(), priors[i].begin(), priors[i].end());
    for (const auto& s : Small()) extra.push_back(s);
    const RunResult r = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra));
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << "--quiet but stderr: " << r.err;
    EXPECT_NE(r.out.find("box"), std::string::npos) << r.out;  // the summary table
    ExpectOneBoxResult(out, 5);
    const RgbImage img = LoadRgbPng(overlay);
    EXPECT_EQ(img.width, cam.camera.width);
    EXPECT_EQ(img.height, cam.camera.height);
  }
}

TEST_F(CliTest, EstimateIsDeterministicPerSeed) {
  auto run = [&](const std::string& name, const std::string& seed) {
    std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--prior", Scene("detections.json"), "--seed", seed,
                                      "--out", Path(name)};
    for (const auto& s : Small()) extra.push_back(s);
    const RunResult r = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra));
    EXPECT_EQ(r.code, 0) << r.err;
    return ExpectOneBoxResult(Path(name), 5);
  };
  const ObjectResult a = run("a.json", "11"), b = run("b.json", "11"), c = run("c.json", "12");
  EXPECT_EQ(a.T_cam_obj.matrix(), b.T_cam_obj.matrix());
  EXPECT_EQ(a.weight, b.weight);
  EXPECT_EQ(a.iterations, b.iterations);
  // Byte-identical files once the wall time is taken out.
  const std::regex time_ms("\"time_ms\"\\s*:\\s*[-+0-9.eE]+");
  const std::string ta = std::regex_replace(ReadFile(Path("a.json")), time_ms, "");
  const std::string tb = std::regex_replace(ReadFile(Path("b.json")), time_ms, "");
  EXPECT_EQ(ta, tb);
  EXPECT_NE(ta, ReadFile(Path("a.json"))) << "results JSON has no time_ms to ignore";
  // And the seed matters (otherwise the check above proves nothing).
  EXPECT_NE(a.T_cam_obj.matrix(), c.T_cam_obj.matrix());
}

// ---------------------------------------------------------------------------------------------
// estimate: input errors (exit 1, one line naming the file or option).

// estimate --mask: the target's instance mask (the synthetic scene's label 1) with a class
// map is the whole prior; the pose found lies within 1 cm of the ground truth.
TEST_F(CliTest, EstimateWithAMaskPrior) {
  const LabelImage labels = LoadLabelPng(Scene("label.png"));
  LabelImage mask = labels;
  for (auto& id : mask.ids) id = id == 1 ? 4 : 0;  // instance id 4
  SaveLabelPng(mask, Path("mask.png"));
  WriteFile(Path("classes.json"), R"({"4": "box"})");
  std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--mask", Path("mask.png"), "--mask-classes",
                                    Path("classes.json"), "--out", Path("r.json")};
  const RunResult r = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra));
  ASSERT_EQ(r.code, 0) << r.err;
  const ObjectResult o = ExpectOneBoxResult(Path("r.json"), 1000);
  const std::vector<GtObject> gt = ReadGtJson(Scene("gt.json"));
  EXPECT_LT((o.T_cam_obj.translation() - gt[0].T_cam_obj.translation()).norm(), 0.01);
}

// Mask priors with a wrong size, unknown ids or no instance, or given with --prior: one
// line naming the file or option, exit 1.
TEST_F(CliTest, BadMaskPriorsAreErrorsNamingTheFile) {
  const LabelImage labels = LoadLabelPng(Scene("label.png"));
  LabelImage target = labels;
  for (auto& id : target.ids) id = id == 1 ? 1 : 0;
  SaveLabelPng(target, Path("target.png"));
  WriteFile(Path("classes.json"), R"({"1": "box"})");
  auto run = [&](const std::string& mask, std::vector<std::string> more = {}) {
    std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--mask", mask, "--mask-classes", Path("classes.json")};
    extra.insert(extra.end(), more.begin(), more.end());
    return Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra));
  };
  SaveLabelPng(LabelImage{10, 10, std::vector<std::uint16_t>(100, 1)}, Path("small.png"));
  ExpectInputError(run(Path("small.png")), "estimate", Path("small.png"));
  ExpectInputError(run(Path("small.png")), "estimate", "10x10");
  LabelImage two = target;
  two.ids[0] = 9;
  SaveLabelPng(two, Path("two.png"));
  ExpectInputError(run(Path("two.png")), "estimate", Path("two.png"));
  ExpectInputError(run(Path("two.png")), "estimate", "mask id 9");
  LabelImage empty = target;
  std::fill(empty.ids.begin(), empty.ids.end(), 0);
  SaveLabelPng(empty, Path("empty.png"));
  ExpectInputError(run(Path("empty.png")), "estimate", Path("empty.png"));
  ExpectInputError(run(Path("empty.png")), "estimate", "mask is empty");
  WriteFile(Path("other.json"), R"({"1": "mug"})");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                    {"--mesh", Scene("box.ply"), "--mask", Path("target.png"), "--mask-classes",
                                     Path("other.json")})),
                   "estimate", "no instance of 'box'");
  ExpectInputError(run(Path("missing.png")), "estimate", Path("missing.png"));
  ExpectInputError(run(Path("target.png"), {"--prior", Scene("detections.json")}), "estimate", "--prior");
  WriteFile(Path("bad.json"), "[1, 2]");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                    {"--mesh", Scene("box.ply"), "--mask", Path("target.png"), "--mask-classes",
                                     Path("bad.json")})),
                   "estimate", Path("bad.json"));
}

TEST_F(CliTest, MissingDepthPng) {
  const std::string depth = Path("no_such_depth.png");
  ExpectInputError(Run(EstimateArgs(depth, Scene("camera.json"), {"--mesh", Scene("box.ply")})), "estimate", depth);
}

TEST_F(CliTest, CorruptDepthPngRandomBytes) {
  const std::string depth = Path("random.png");
  std::string bytes;
  std::uint32_t x = 12345;
  for (int i = 0; i < 4096; ++i) {  // xorshift32: deterministic garbage
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    bytes += char(x & 0xff);
  }
  WriteFile(depth, bytes);
  ExpectInputError(Run(EstimateArgs(depth, Scene("camera.json"), {"--mesh", Scene("box.ply")})), "estimate", depth);
}

TEST_F(CliTest, CorruptDepthPngTruncated) {
  const std::string depth = Path("truncated.png");
  const std::string full = ReadFile(Scene("depth.png"));
  ASSERT_GT(full.size(), 4000u);
  WriteFile(depth, full.substr(0, full.size() / 3));
  ExpectInputError(Run(EstimateArgs(depth, Scene("camera.json"), {"--mesh", Scene("box.ply")})), "estimate", depth);
}

TEST_F(CliTest, MissingMesh) {
  const std::string mesh = Path("no_such_mesh.ply");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), {"--mesh", mesh})), "estimate", mesh);
}

TEST_F(CliTest, CorruptMesh) {
  const std::string mesh = Path("garbage.ply");
  WriteFile(mesh, "this is not a mesh\n\x01\x02\x03 garbage garbage\n");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), {"--mesh", mesh})), "estimate", mesh);
}

TEST_F(CliTest, DepthSizeDiffersFromCamera) {
  nlohmann::json j = nlohmann::json::parse(ReadFile(Scene("camera.json")));
  ASSERT_EQ(j["width"].get<int>(), 640);
  j["width"] = 320;
  const std::string cam = Path("camera320.json");
  WriteFile(cam, j.dump());
  const RunResult r = Run(EstimateArgs(Scene("depth.png"), cam, {"--mesh", Scene("box.ply")}));
  ExpectInputError(r, "estimate", Scene("depth.png"));
  EXPECT_NE(r.err.find("320"), std::string::npos) << r.err;
}

TEST_F(CliTest, AllZeroDepthPng) {
  const std::string depth = Path("zeros.png");
  SaveDepthPng(DepthImage(640, 480, 0.f), depth, 0.0001);
  ExpectInputError(Run(EstimateArgs(depth, Scene("camera.json"), {"--mesh", Scene("box.ply")})), "estimate", depth);
}

TEST_F(CliTest, NanAndNullInCameraJson) {
  const std::string text = ReadFile(Scene("camera.json"));
  const std::regex fx("\"fx\"\\s*:\\s*[-+0-9.eE]+");
  ASSERT_TRUE(std::regex_search(text, fx)) << text;
  const std::string nan_cam = Path("camera_nan.json"), null_cam = Path("camera_null.json");
  WriteFile(nan_cam, std::regex_replace(text, fx, "\"fx\": NaN"));  // not JSON at all
  WriteFile(null_cam, std::regex_replace(text, fx, "\"fx\": null"));
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), nan_cam, {"--mesh", Scene("box.ply")})), "estimate", nan_cam);
  const RunResult r = Run(EstimateArgs(Scene("depth.png"), null_cam, {"--mesh", Scene("box.ply")}));
  ExpectInputError(r, "estimate", null_cam);
  EXPECT_NE(r.err.find("fx"), std::string::npos) << r.err;
}

TEST_F(CliTest, EmptyDetectionsPrior) {
  const std::string prior = Path("empty.json");
  WriteFile(prior, "[]");
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), {"--mesh", Scene("box.ply"), "--prior", prior})),
                   "estimate", prior);
}

TEST_F(CliTest, RawPyramidOfWrongSize) {
  const std::string prior = Path("short.pyr");
  const std::string full = ReadFile(Scene("prior.pyr"));
  WriteFile(prior, full.substr(0, full.size() - 4));  // one float short
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                    {"--mesh", Scene("box.ply"), "--prior", prior, "--classes", Scene("classes.txt")})),
                   "estimate", prior);
}

TEST_F(CliTest, MeshNameNotAmongThePriorsClasses) {
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"),
                                    {"--mesh", "frobnitz=" + Scene("box.ply"), "--prior", Scene("prior.pyr"),
                                     "--classes", Scene("classes.txt")})),
                   "estimate", "frobnitz");
}

TEST_F(CliTest, OverlayOnRgbOfWrongSize) {
  const std::string rgb = Path("small_rgb.png");
  SaveRgbPng(RgbImage(32, 24), rgb);
  std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--overlay", Path("o.png"), "--rgb", rgb};
  for (const auto& s : Small()) extra.push_back(s);
  ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra)), "estimate", rgb);
  EXPECT_FALSE(fs::exists(Path("o.png")));
}

TEST_F(CliTest, NonsenseOptionValues) {
  struct Case {
    std::vector<std::string> opt;
    std::string needle;
  };
  // Values CLI11 parses but the filter rejects: exit 1, the message names the option as the
  // option table spells it on the command line, its range and the value given.
  for (const Case& c : std::vector<Case>{{{"--particles", "-5"}, "--particles must be in [2, 1000000] (got -5)"},
                                         {{"--alpha", "2"}, "--alpha must be in [0, 1] (got 2)"},
                                         {{"--alpha", "0.5"}, "--alpha + --beta + --gamma must equal 1"},
                                         {{"--confidence", "0"}, "--confidence must"},
                                         {{"--iterations", "0"}, "--iterations must"},
                                         {{"--inlier-thr", "0"}, "--inlier-thr must"},
                                         {{"--elite", "5000"}, "--elite must be < --particles (got 5000 >= 510)"},
                                         {{"--pool", "0"}, "--pool must"},
                                         {{"--window", "4"}, "--window must"},
                                         {{"--sigma-t", "-1"}, "--sigma-t must"},
                                         {{"--sigma-r", "-1"}, "--sigma-r must"},
                                         {{"--threads", "-1"}, "--threads must"},
                                         {{"--stall-iterations", "-1"}, "--stall-iterations must be in [0, 1000]"},
                                         {{"--stall-gain", "2"}, "--stall-gain must be in [0, 1]"},
                                         {{"--anneal-subsample", "0"}, "--anneal-subsample must be in [1, 4]"},
                                         {{"--anneal-fraction", "1.5"}, "--anneal-fraction must be in [0, 1]"},
                                         {{"--fine-fraction", "0"}, "--fine-fraction must be in (0, 1]"},
                                         {{"--contact-span", "0"}, "--contact-span must be > 0 (got 0)"},
                                         {{"--lod", "2"}, "--lod must be 0 (the full mesh) or >= 4 (got 2)"},
                                         {{"--heuristics-percentile-lo", "0.95"},
                                          "--heuristics-percentile-lo must be <= --heuristics-percentile-hi"},
                                         {{"--move-probabilities", "0", "0", "0", "0", "0", "0", "0", "0", "0", "0", "0",
                                           "0", "0", "0", "0", "0", "0"},
                                          "--move-probabilities: at least one must be > 0"},
                                         {{"--depth-scale", "-1"}, "--depth-scale"},
                                         {{"--unit-scale", "0"}, "--unit-scale"}}) {
    SCOPED_TRACE(c.opt[0] + " " + c.opt[1]);
    std::vector<std::string> extra = {"--mesh", Scene("box.ply")};
    extra.insert(extra.end(), c.opt.begin(), c.opt.end());
    ExpectInputError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra)), "estimate", c.needle);
  }
  // Values or options CLI11 rejects: exit 2, first line names the option.
  for (const Case& c : std::vector<Case>{{{"--engine", "vulkan"}, "--engine"},
                                         {{"--cpu-isa", "avx9"}, "--cpu-isa"},
                                         {{"--move-probabilities", "1", "2"}, "--move-probabilities"},
                                         {{"--iterations", "abc"}, "--iterations"},
                                         {{"--frobnicate"}, "--frobnicate"}}) {
    SCOPED_TRACE(c.opt[0]);
    std::vector<std::string> extra = {"--mesh", Scene("box.ply")};
    extra.insert(extra.end(), c.opt.begin(), c.opt.end());
    ExpectUsageError(Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra)), c.needle);
  }
  // A required option missing.
  ExpectUsageError(Run({"estimate", "--camera", Scene("camera.json"), "--mesh", Scene("box.ply")}), "--depth");
}

// ---------------------------------------------------------------------------------------------
// The dispatcher.

// Scene options of the commands that make synthetic scenes: the message names the CLI option.
TEST_F(CliTest, SynthAndSuiteNameTheSceneOption) {
  ExpectInputError(Run({"synth", "--out", Path("bad_synth"), "--max-distance", "9"}), "synth",
                   "--max-distance (max_distance_m): must be in [0.2, 5] (got 9)");
  ExpectInputError(Run({"suite", "--count", "1", "--min-distance", "0.1"}), "suite",
                   "--min-distance (min_distance_m): must be in [0.2, 5] (got 0.1)");
  ExpectInputError(Run({"suite", "--count", "1", "--false-positives", "-1"}), "suite", "--false-positives");
  ExpectInputError(Run({"suite", "--world", "ycbv", "--min-objects", "0"}), "suite", "--min-objects");
  ExpectInputError(Run({"suite", "--world", "ycbv", "--max-distance", "0.4"}), "suite", "--max-distance");
  ExpectInputError(Run({"suite", "--world", "ycbv", "--targets", "giraffe"}), "suite", "'giraffe'");
  ExpectInputError(Run({"suite", "--world", "ycbv", "--models", Path("no_models")}), "suite", Path("no_models"));
  // No product default points beside the checkout: without --models the meshes come from
  // $POSEFILTER_DATA, and without that the error says where to get them.
  if (std::getenv("POSEFILTER_DATA") == nullptr)
    ExpectInputError(Run({"suite", "--world", "ycbv", "--count", "1"}), "suite", "set POSEFILTER_DATA");
  ExpectUsageError(Run({"suite", "--world", "moon"}), "--world");
  ExpectUsageError(Run({"suite", "--world", "ycbv", "--prior", "hints"}), "--prior");
}

// The YCB table-top suite on one scene of the shared meshes (skipped without them): the table
// and the JSON hold every target with its ground-truth weight, and the per-class summary.
TEST_F(CliTest, SuiteOnTheYcbTableTopWorld) {
  const fs::path models = testing_util::YcbvDataDir() / "models";
  if (!fs::exists(models)) GTEST_SKIP() << "no YCB-Video meshes at " << models;
  for (const char* prior : {"boxes", "masks"}) {
    const std::string json = Path(std::string("suite_") + prior + ".json");
    const RunResult r = Run({"suite", "--world", "ycbv", "--models", models.string(), "--count", "1", "--prior", prior,
                             "--particles", "64", "--iterations", "6", "--restarts", "1", "--polish-steps", "2",
                             "--write-scenes", Path("scenes"), "--json", json});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("recall (ADD-S < 10% of diameter)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("AUC of ADD-S"), std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(testing_util::ReadFile(json));
    EXPECT_EQ(j["prior"], prior);
    ASSERT_FALSE(j["objects"].empty());
    for (const auto& o : j["objects"]) {
      EXPECT_GE(o["visible_fraction"].get<double>(), 0.1);
      EXPECT_GE(o["gt_weight"].get<double>(), 0.0);
      EXPECT_EQ(o["status"], "ok");
    }
    EXPECT_FALSE(j["classes"].empty());
    EXPECT_TRUE(fs::exists(Path("scenes") + "/scene_000001/mask.png"));
  }
}

TEST_F(CliTest, UnknownSubcommand) {
  const RunResult r = Run({"frobnicate"});
  EXPECT_EQ(r.code, 2);
  const auto lines = Lines(r.err);
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines[0].find("unknown command 'frobnicate'"), std::string::npos) << lines[0];
}

TEST_F(CliTest, NoArgumentsPrintsUsage) {
  const RunResult r = Run({});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("usage: posefilter", 0), 0u) << r.err;
  for (const char* cmd : {"estimate", "demo", "synth", "eval", "suite", "gt-detections"})
    EXPECT_NE(r.err.find(std::string("\n  ") + cmd + " "), std::string::npos) << cmd << " not listed:\n" << r.err;
  // --help: the same list on stdout, exit 0.
  const RunResult h = Run({"--help"});
  EXPECT_EQ(h.code, 0);
  EXPECT_NE(h.out.find("gt-detections"), std::string::npos) << h.out;
}

// A switch's help says its default in words; CLI11's "{false}" after a negated name is gone.
TEST_F(CliTest, HelpSaysEachSwitchsDefault) {
  const RunResult h = Run({"estimate", "--help"});
  EXPECT_EQ(h.code, 0);
  EXPECT_EQ(h.out.find("{false}"), std::string::npos) << h.out;
  const auto line_after = [&](const std::string& name) {
    const std::size_t at = h.out.find(name);
    if (at == std::string::npos) return std::string();
    const std::size_t end = h.out.find("\n  -", at + name.size());
    return h.out.substr(at, end == std::string::npos ? std::string::npos : end - at);
  };
  EXPECT_NE(line_after("--scene-pass,--no-scene-pass").find("(default: on)"), std::string::npos) << h.out;
  EXPECT_NE(line_after("--hard-inlier,--no-hard-inlier").find("(default: off)"), std::string::npos) << h.out;
}

// ---------------------------------------------------------------------------------------------
// gt-detections.

TEST_F(CliTest, GtDetectionsBoxMatchesTheSynthGtBox) {
  const nlohmann::json synth = nlohmann::json::parse(ReadFile(Scene("synth.json")));
  const auto& g = synth.at("gt_bbox");
  const Box gt_box = DetectionBox({"box", 1, g[0].get<double>(), g[1].get<double>(), g[2].get<double>(), g[3].get<double>()});
  ASSERT_GT(gt_box.w, 10);

  // Jittered (defaults: σ 8 px, score 0.9).
  const std::string out = Path("dets.json");
  const RunResult r = Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                           Scene("box.ply"), "--seed", "5", "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Detection> dets = ReadDetectionsJson(out);
  ASSERT_EQ(dets.size(), 1u);
  EXPECT_EQ(dets[0].cls, "box");
  EXPECT_DOUBLE_EQ(dets[0].score, 0.9);
  const double iou = BoxIoU(DetectionBox(dets[0]), gt_box);
  EXPECT_GT(iou, 0.5);
  EXPECT_LT(iou, 1.0);  // it was jittered

  // No jitter: exactly the full silhouette's box.
  const std::string exact = Path("exact.json");
  ASSERT_EQ(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                 Scene("box.ply"), "--jitter", "0", "--score", "0.7", "--out", exact})
                .code,
            0);
  const std::vector<Detection> e = ReadDetectionsJson(exact);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0].x, g[0].get<double>(), 1e-9);
  EXPECT_NEAR(e[0].y, g[1].get<double>(), 1e-9);
  EXPECT_NEAR(e[0].w, g[2].get<double>(), 1e-9);
  EXPECT_NEAR(e[0].h, g[3].get<double>(), 1e-9);
  EXPECT_DOUBLE_EQ(e[0].score, 0.7);

  // Same seed, same file; --models-dir finds DIR/<obj>.ply.
  const std::string again = Path("again.json");
  ASSERT_EQ(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--models-dir",
                 fs::path(Scene("box.ply")).parent_path().string(), "--seed", "5", "--out", again, "--quiet"})
                .code,
            0);
  EXPECT_EQ(ReadFile(out), ReadFile(again));
  // A mesh that --models-dir finds is an input too: --out over it is refused, the mesh kept.
  const std::string mesh_before = ReadFile(Scene("box.ply"));
  const RunResult over = Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--models-dir",
                              fs::path(Scene("box.ply")).parent_path().string(), "--out", Scene("box.ply")});
  EXPECT_EQ(over.code, 1);
  EXPECT_NE(over.err.find("is a file of the input folder --models-dir"), std::string::npos) << over.err;
  EXPECT_EQ(ReadFile(Scene("box.ply")), mesh_before);

  // And `estimate` takes it as its prior.
  std::vector<std::string> extra = {"--mesh", Scene("box.ply"), "--prior", out, "--out", Path("res.json")};
  for (const auto& s : Small()) extra.push_back(s);
  const RunResult est = Run(EstimateArgs(Scene("depth.png"), Scene("camera.json"), extra));
  ASSERT_EQ(est.code, 0) << est.err;
  ExpectOneBoxResult(Path("res.json"), 5);
}

TEST_F(CliTest, GtDetectionsSkipsObjectsOutOfView) {
  // The synth gt object, plus a second instance behind the camera.
  nlohmann::json gt = nlohmann::json::parse(ReadFile(Scene("gt.json")));
  nlohmann::json behind = gt["objects"][0];
  behind["t"] = {0.0, 0.0, -1.0};
  gt["objects"].push_back(behind);
  const std::string gt2 = Path("gt2.json");
  WriteFile(gt2, gt.dump());
  const std::string out = Path("dets.json");
  const RunResult r = Run({"gt-detections", "--gt", gt2, "--camera", Scene("camera.json"), "--mesh", Scene("box.ply"),
                           "--out", out});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("objects[1]"), std::string::npos) << r.err;
  EXPECT_EQ(ReadDetectionsJson(out).size(), 1u);

  // Nothing in view at all: an error, no file.
  gt["objects"].erase(0);
  const std::string gt3 = Path("gt3.json");
  WriteFile(gt3, gt.dump());
  const std::string none = Path("none.json");
  const RunResult n = Run({"gt-detections", "--gt", gt3, "--camera", Scene("camera.json"), "--mesh", Scene("box.ply"),
                           "--out", none, "--quiet"});
  EXPECT_EQ(n.code, 1);
  EXPECT_NE(n.err.find("error: " + gt3), std::string::npos) << n.err;
  EXPECT_FALSE(fs::exists(none));
}

TEST_F(CliTest, GtDetectionsInputErrors) {
  const std::string out = Path("dets.json");
  const std::string gt = Path("no_such_gt.json");
  ExpectInputError(Run({"gt-detections", "--gt", gt, "--camera", Scene("camera.json"), "--mesh", Scene("box.ply"),
                        "--out", out}),
                   "gt-detections", gt);
  const std::string mesh = Path("no_such_mesh.ply");
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                        "box=" + mesh, "--out", out}),
                   "gt-detections", mesh);
  // No mesh for the gt object at all: names the object.
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--out", out}),
                   "gt-detections", "'box'");
  // --models-dir without the object's file: names DIR/box.ply.
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--models-dir",
                        dir_.string(), "--out", out}),
                   "gt-detections", Path("box.ply"));
  const std::string cam = Path("no_such_camera.json");
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", cam, "--mesh", Scene("box.ply"), "--out",
                        out}),
                   "gt-detections", cam);
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                        Scene("box.ply"), "--score", "1.5", "--out", out}),
                   "gt-detections", "--score");
  ExpectInputError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                        Scene("box.ply"), "--jitter", "-1", "--out", out}),
                   "gt-detections", "--jitter");
  ExpectUsageError(Run({"gt-detections", "--gt", Scene("gt.json"), "--camera", Scene("camera.json"), "--mesh",
                        Scene("box.ply")}),
                   "--out");
  EXPECT_FALSE(fs::exists(out));
}

// ---------------------------------------------------------------------------------------------
// demo.

TEST_F(CliTest, DemoWritesAnOverlay) {
  const std::string out = Path("demo");
  const RunResult r = Run({"demo", "--iterations", "3", "--particles", "32", "--out", out, "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ADD-S"), std::string::npos) << r.out;
  const RgbImage img = LoadRgbPng(out + "/overlay.png");
  EXPECT_EQ(img.width, 640);
  EXPECT_EQ(img.height, 480);
}

}  // namespace
}  // namespace posefilter
