// The CLI's checks before work and its plausibility checks: outputs that would overwrite an
// input or each other, missing output folders and RGB images (refused before the estimate, with
// nothing written), thread and iteration caps, seeds out of range, duplicate mesh names,
// options that do not apply, 8-bit depth, implausible intrinsics, degenerate or huge meshes,
// wrong mesh or depth units, and priors whose classes or boxes match nothing.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "filter/engine_registry.h"
#include "posefilter/depth_image.h"
#include "posefilter/version.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ReadFile;
using testing_util::RunResult;
using testing_util::WriteFile;

// estimate on the shared scene with the small budget, the box mesh and `extra`.
std::vector<std::string> SmallBoxEstimate(const std::string& depth, const std::string& camera,
                                          const std::vector<std::string>& extra, bool with_mesh = true) {
  std::vector<std::string> e = {"--particles", "64", "--iterations", "5", "--restarts", "1"};
  if (with_mesh) {
    e.push_back("--mesh");
    e.push_back((fs::path(depth).parent_path() / "box.ply").string());
  }
  e.insert(e.end(), extra.begin(), extra.end());
  std::vector<std::string> a = {"estimate", "--depth", depth, "--camera", camera, "--quiet"};
  a.insert(a.end(), e.begin(), e.end());
  return a;
}

TEST_F(CliTest, VersionIsTheLibrarysAndTakesNoArguments) {
  const RunResult v = Run({"--version"});
  EXPECT_EQ(v.code, 0) << v.err;
  // First line: the version and the commit; then one line per engine.
  const std::string first = std::string("posefilter ") + Version() + " (git " + GitRevision() + ")\n";
  EXPECT_EQ(v.out.substr(0, first.size()), first) << v.out;
  EXPECT_NE(std::string(Version()).find('.'), std::string::npos);
  // A build from this checkout knows its commit: 12 hex digits (and "-dirty" while edited).
  const std::string rev = GitRevision();
  EXPECT_TRUE(rev == "unknown" || (rev.size() >= 12 && rev.find_first_not_of("0123456789abcdef") >= 12)) << rev;
  for (const char* engine : {"\n  reference ", "\n  cpu ", "\n  gpu ", "\n  hw "})
    EXPECT_NE(v.out.find(engine), std::string::npos) << engine << " missing from\n" << v.out;
  EXPECT_NE(v.out.find("instruction sets built: portable"), std::string::npos) << v.out;
  EXPECT_EQ(Run({"version"}).out, v.out);
  const RunResult extra = Run({"--version", "now"});
  EXPECT_EQ(extra.code, 2);
  EXPECT_NE(extra.err.find("--version takes no arguments (got 'now')"), std::string::npos) << extra.err;
  EXPECT_EQ(Run({"version", "now"}).code, 2);
}

TEST_F(CliTest, OutputNamingAnInputIsRefusedAndTheInputKept) {
  for (const std::string input : {"depth.png", "camera.json", "box.ply", "detections.json"}) {
    SCOPED_TRACE(input);
    const std::string before = ReadFile(Scene(input));
    for (const std::string out_opt : {"--out", "--overlay"}) {
      const RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                               {"--prior", Scene("detections.json"), out_opt, Scene(input)}));
      ExpectInputError(r, "estimate", out_opt + " " + Scene(input));
      EXPECT_NE(r.err.find("would be overwritten"), std::string::npos) << r.err;
      EXPECT_EQ(ReadFile(Scene(input)), before) << input << " was changed";
    }
  }
  // The same file under another spelling.
  const std::string dotted = (fs::path(Scene("")) / "." / "camera.json").string();
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--out", dotted})), "estimate",
                   "would be overwritten");
}

TEST_F(CliTest, TwoOutputsOnOneFileAreRefused) {
  const RunResult r =
      Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--out", Path("r.json"), "--overlay", Path("r.json")}));
  ExpectInputError(r, "estimate", "give each output its own file");
  EXPECT_FALSE(fs::exists(Path("r.json")));
}

TEST_F(CliTest, MissingOutputFolderOrRgbFailsBeforeAnythingIsWritten) {
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                        {"--out", Path("r.json"), "--overlay", Path("no_dir/o.png")})),
                   "estimate", "--overlay " + Path("no_dir/o.png") + ": the directory");
  EXPECT_FALSE(fs::exists(Path("r.json"))) << "results written although the overlay cannot be";
  const RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                           {"--out", Path("r.json"), "--overlay", Path("o.png"), "--rgb", Path("no.png")}));
  ExpectInputError(r, "estimate", Path("no.png"));
  EXPECT_FALSE(fs::exists(Path("r.json"))) << "results written although --rgb is missing";
  EXPECT_FALSE(fs::exists(Path("o.png")));
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--out", dir_.string()})), "estimate",
                   "is a directory");
}

TEST_F(CliTest, ThreadsAndIterationsAreCapped) {
  const RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--threads", "100000"}));
  ExpectInputError(r, "estimate", "--threads must be in [0, ");
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--threads", "30000"})), "estimate",
                   "--threads must be in [0, ");
  std::vector<std::string> args = {"estimate", "--depth", Scene("depth.png"), "--camera", Scene("camera.json"),
                                   "--quiet", "--mesh", Scene("box.ply"), "--iterations", "1000000000"};
  ExpectInputError(Run(args), "estimate", "--iterations must be in [1, 100000]");
}

TEST_F(CliTest, SeedsOutOfRangeAreUsageErrors) {
  for (const std::string seed : {"-1", "1e23", "18446744073709551616", "3.5", "abc"}) {
    SCOPED_TRACE(seed);
    ExpectUsageError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--seed", seed})), "--seed");
    ExpectUsageError(Run({"synth", "--out", Path("s"), "--seed", seed}), "--seed");
  }
  ExpectUsageError(Run({"suite", "--first-seed", "-1", "--scenes", "1"}), "--first-seed");
  ExpectUsageError(Run({"demo", "--scene-seed", "-1"}), "--scene-seed");
  // Seeds are decimal: "010" is 10 (CLI11 alone reads a leading 0 as octal, 8).
  ASSERT_EQ(Run({"synth", "--out", Path("s010"), "--seed", "010", "--target", "box"}).code, 0);
  ASSERT_EQ(Run({"synth", "--out", Path("s10"), "--seed", "10", "--target", "box"}).code, 0);
  ASSERT_EQ(Run({"synth", "--out", Path("s8"), "--seed", "8", "--target", "box"}).code, 0);
  const auto depth_of = [&](const std::string& d) { return ReadFile(fs::path(Path(d)) / "scene_000" / "depth.png"); };
  EXPECT_EQ(depth_of("s010"), depth_of("s10"));
  EXPECT_NE(depth_of("s010"), depth_of("s8"));
  // A seed range that would wrap past 2^64 - 1 is refused.
  ExpectInputError(Run({"synth", "--out", Path("wrap"), "--seed", "18446744073709551615", "--count", "2"}), "synth",
                   "would wrap");
  ExpectInputError(Run({"suite", "--first-seed", "18446744073709551615", "--count", "2"}), "suite", "would wrap");
  // The largest seed is accepted.
  const RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--seed", "18446744073709551615"}));
  EXPECT_EQ(r.code, 0) << r.err;
}

// A device or a FIFO as a small input is refused by name, never read forever or waited on.
TEST_F(CliTest, DevicesAndFifosAreNotReadAsInputs) {
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), "/dev/zero", {})), "estimate", "/dev/zero: is a character device");
  const std::string fifo = Path("cam.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), fifo, {})), "estimate", "is a FIFO");
}

// A value CLI11 cannot convert is one line with the command's prefix, exit 2.
TEST_F(CliTest, ParserErrorsAreOneLineWithTheCommandsPrefix) {
  const RunResult r = Run({"estimate", "--particles", "abc"});
  EXPECT_EQ(r.code, 2);
  const auto lines = testing_util::Lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("posefilter estimate: error: ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("--particles"), std::string::npos) << lines[0];
  const RunResult unknown = Run({"track", "--frobnicate"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_EQ(testing_util::Lines(unknown.err).size(), 1u) << unknown.err;
  EXPECT_EQ(unknown.err.rfind("posefilter track: error: ", 0), 0u) << unknown.err;
}

// --depth-scale 0 given on the command line is an error, not "the camera's scale".
TEST_F(CliTest, AGivenDepthScaleMustBePositive) {
  for (const char* v : {"0", "-0.001"}) {
    SCOPED_TRACE(v);
    ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--depth-scale", v})), "estimate",
                     "--depth-scale must be finite and > 0");
  }
}

// An empty value is an error naming the option, not "no output" or the current folder.
TEST_F(CliTest, EmptyValuesAreErrorsNamingTheOption) {
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--out", ""})), "estimate",
                   "--out: empty value");
  ExpectInputError(Run({"synth", "--out", "", "--target", "box", "--count", "1"}), "synth", "--out: empty value");
  ExpectInputError(Run({"hw-report", "--json", "", "--iterations", "1"}), "hw-report", "--json: empty value");
}

TEST_F(CliTest, DuplicateMeshNamesAndInapplicableOptions) {
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--mesh", "box=" + Scene("box.ply")})),
                   "estimate", "--mesh: NAME 'box' given twice");
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                        {"--prior", Scene("detections.json"), "--classes", Scene("classes.txt")})),
                   "estimate", "--classes");
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--rgb", Scene("rgb.png")})),
                   "estimate", "--rgb");
}

TEST_F(CliTest, EightBitDepthIsRefused) {
  const std::string depth = Path("depth8.png");
  SaveGray8Png(std::vector<std::uint8_t>(640 * 480, 100), 640, 480, depth);
  const RunResult r = Run(SmallBoxEstimate(depth, Scene("camera.json"), {"--mesh", Scene("box.ply")}, false));
  ExpectInputError(r, "estimate", depth);
  EXPECT_NE(r.err.find("16-bit"), std::string::npos) << r.err;
}

TEST_F(CliTest, ImplausibleIntrinsicsAreRefused) {
  const nlohmann::json good = nlohmann::json::parse(ReadFile(Scene("camera.json")));
  struct Case {
    std::string key;
    double value;
  };
  for (const Case& c : std::vector<Case>{{"fx", 1e300}, {"fy", 0.5}, {"cx", 1e6}, {"cy", -1e4}}) {
    SCOPED_TRACE(c.key);
    nlohmann::json j = good;
    j[c.key] = c.value;
    const std::string cam = Path("camera_" + c.key + ".json");
    WriteFile(cam, j.dump());
    const RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), cam, {"--mesh", Scene("box.ply")}, false));
    ExpectInputError(r, "estimate", cam);
    EXPECT_NE(r.err.find(c.key + " = "), std::string::npos) << r.err;
  }
}

TEST_F(CliTest, DegenerateAndHugeMeshesAreRefused) {
  // Every face has zero area (collinear or repeated vertices).
  WriteFile(Path("flat.ply"),
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n0.1 0 0\n0.2 0 0\n0 0.1 0\n3 0 1 2\n3 0 0 3\n");
  RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--mesh", Path("flat.ply")}, false));
  ExpectInputError(r, "estimate", Path("flat.ply"));
  EXPECT_NE(r.err.find("area"), std::string::npos) << r.err;

  WriteFile(Path("huge.ply"),
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1e30 0 0\n0 1e30 0\n3 0 1 2\n");
  r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--mesh", Path("huge.ply")}, false));
  ExpectInputError(r, "estimate", Path("huge.ply"));
}

// estimate with `engine` on a wall filling the view at 1.5 m (written to `wall`), no prior.
std::vector<std::string> WallEstimate(const std::string& wall, const std::string& camera, const std::string& mesh,
                                      const std::string& engine) {
  SaveDepthPng(DepthImage(640, 480, 1.5f), wall, 0.001);
  return {"estimate", "--depth", wall, "--camera", camera, "--depth-scale", "0.001", "--mesh", mesh, "--prior",
          "none", "--particles", "40", "--iterations", "2", "--restarts", "1", "--engine", engine, "--quiet"};
}

// The wall's depth scale is right, but the support plane took every reading, and the message
// says so.
void ExpectAPlaneFillingTheView(const RunResult& r) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("100 % of the depth readings lie on one plane"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-support-plane"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("depth scale"), std::string::npos) << r.err;
}

// Every engine checks the units; the hw engine's checks are TheHwEngineNamesWrongUnits.
TEST_F(CliTest, WrongUnitsAreNamed) {
  // A metre mesh read as millimetres: 0.2 mm across in a scene 0.4 m away.
  RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--unit-scale", "0.001"}));
  ExpectInputError(r, "estimate", "--unit-scale");
  EXPECT_EQ(r.out, "") << "a results table was printed before the error";
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                        {"--unit-scale", "0.001", "--engine", "reference"})),
                   "estimate", "--unit-scale");
  // Depth 100x too deep: beyond the heuristic range, no cell of the prior can host a particle.
  r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--depth-scale", "0.01"}));
  ExpectInputError(r, "estimate", "--depth-scale");
  // 1000x: no depth camera sees that far.
  r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--depth-scale", "0.1"}));
  ExpectInputError(r, "estimate", Scene("depth.png"));
  EXPECT_NE(r.err.find("wrong depth scale"), std::string::npos) << r.err;
  ExpectAPlaneFillingTheView(Run(WallEstimate(Path("wall.png"), Scene("camera.json"), Scene("box.ply"), "cpu")));
}

// The same checks in the hw engine. Skipped in a build without it (CMake option
// POSEFILTER_HW=OFF, as in the asan preset), with its registry row's reason.
TEST_F(CliTest, TheHwEngineNamesWrongUnits) {
  if (std::string why; !filter::FindEngine("hw")->available(&why)) GTEST_SKIP() << why;
  ExpectInputError(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"),
                                        {"--unit-scale", "0.001", "--engine", "hw"})),
                   "estimate", "--unit-scale");
  ExpectAPlaneFillingTheView(Run(WallEstimate(Path("wall.png"), Scene("camera.json"), Scene("box.ply"), "hw")));
}

TEST_F(CliTest, PriorsMatchingNoMeshAreRefusedAndOffImageBoxesWarned) {
  // No detection's class is a mesh name.
  const std::string others = Path("others.json");
  WriteFile(others, R"({"detections": [{"bbox": [100, 100, 80, 80], "class": "giraffe", "score": 0.9}]})");
  RunResult r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--prior", others}));
  ExpectInputError(r, "estimate", others);
  EXPECT_NE(r.err.find("giraffe"), std::string::npos) << r.err;

  // The only box of the class lies wholly off the image.
  const std::string off = Path("off.json");
  WriteFile(off, R"({"detections": [{"bbox": [2000, 2000, 80, 80], "class": "box", "score": 0.9}]})");
  r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--prior", off}));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(off), std::string::npos) << r.err;
  // The message names that cause, not a class mismatch.
  EXPECT_NE(r.err.find("every detection of the objects' classes (1) lies wholly outside the 640x480 image"),
            std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("detector class"), std::string::npos) << r.err;

  // One good box and one off the image: a warning, and the estimate runs.
  nlohmann::json dets = nlohmann::json::parse(ReadFile(Scene("detections.json")));
  dets["detections"].push_back({{"bbox", {-500, -500, 40, 40}}, {"class", "box"}, {"score", 0.5}});
  const std::string mixed = Path("mixed.json");
  WriteFile(mixed, dets.dump());
  r = Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--prior", mixed, "--out", Path("r.json")}));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("wholly outside the 640x480 image"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(Path("r.json")));
}

// synth --mesh in a folder the run writes (a scene folder, or anywhere under a --sequence's
// --out) is refused before anything is written, and the mesh keeps its bytes; beside the scene
// folders it is fine.
TEST_F(CliTest, SynthNeverOverwritesItsMesh) {
  const std::string scene_dir = Path("synth_mesh/scene_001");
  fs::create_directories(scene_dir);
  const std::string mesh = scene_dir + "/mine.ply";
  fs::copy_file(Scene("box.ply"), mesh);
  const std::string before = ReadFile(mesh);
  ExpectInputError(Run({"synth", "--out", Path("synth_mesh"), "--count", "2", "--mesh", mesh}), "synth", "--mesh " + mesh);
  ExpectInputError(Run({"synth", "--out", Path("synth_mesh"), "--sequence", "2", "--mesh", mesh}), "synth", "--mesh");
  EXPECT_EQ(ReadFile(mesh), before);
  EXPECT_FALSE(fs::exists(Path("synth_mesh/scene_000")));
  // --count 1 writes scene_000 only: a mesh in scene_001 is safe.
  EXPECT_EQ(Run({"synth", "--out", Path("synth_mesh"), "--count", "1", "--mesh", mesh}).code, 0);
  EXPECT_EQ(ReadFile(mesh), before);
}

TEST_F(CliTest, GtDetectionsAndEvalNeverOverwriteTheirInputs) {
  const std::string gt = Path("gt.json");
  fs::copy_file(Scene("gt.json"), gt);
  const std::string before = ReadFile(gt);
  ExpectInputError(Run({"gt-detections", "--gt", gt, "--camera", Scene("camera.json"), "--mesh", Scene("box.ply"),
                        "--out", gt}),
                   "gt-detections", "would be overwritten");
  EXPECT_EQ(ReadFile(gt), before);

  const std::string results = Path("r.json");
  ASSERT_EQ(Run(SmallBoxEstimate(Scene("depth.png"), Scene("camera.json"), {"--out", results})).code, 0);
  const std::string results_before = ReadFile(results);
  for (const std::string& victim : {results, gt}) {
    SCOPED_TRACE(victim);
    ExpectInputError(Run({"eval", "--results", results, "--gt", gt, "--mesh", "box=" + Scene("box.ply"), "--json", victim}),
                     "eval", "would be overwritten");
  }
  EXPECT_EQ(ReadFile(results), results_before);
  EXPECT_EQ(ReadFile(gt), before);
  // A fine --json is written whole.
  const RunResult ok = Run({"eval", "--results", results, "--gt", gt, "--mesh", "box=" + Scene("box.ply"), "--json", Path("e.json")});
  ASSERT_EQ(ok.code, 0) << ok.err;
  const nlohmann::json ev = nlohmann::json::parse(ReadFile(Path("e.json")), nullptr, false);
  EXPECT_FALSE(ev.is_discarded()) << "e.json is not whole JSON";
}

}  // namespace
}  // namespace posefilter
