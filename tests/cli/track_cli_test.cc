// `posefilter track` (apps/track_cmd.cc) end to end, and `posefilter synth --sequence`
// (apps/synth_cmd.cc) that writes its input: a small synthetic sequence tracked from its
// ground truth (the printed table, the CSV, one results JSON per frame), a jump reported lost
// and restarted by a detections stage 1, a folder of depth PNGs (--frames) started by a
// uniform stage 1, the real YCB-Video frames of ../shared/data/ycbv (skipped when absent), and
// the input and usage errors of both commands.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "posefilter/depth_image.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::Lines;
using testing_util::ReadFile;
using testing_util::RunResult;

const char* kCsvHeader = "frame,scene_id,im_id,obj,status,weight,time_ms,frame_ms,R,t,adds_mm,found";

// One CSV row, by column name.
using Row = std::map<std::string, std::string>;

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

// One CSV line's fields, with RFC 4180 quoting undone.
std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      out.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

// The rows of a track CSV; checks the header and that every row has every column.
std::vector<Row> ReadTrackCsv(const std::string& path) {
  const std::vector<std::string> lines = Lines(ReadFile(path));
  EXPECT_FALSE(lines.empty()) << path;
  if (lines.empty()) return {};
  EXPECT_EQ(lines[0], kCsvHeader);
  const std::vector<std::string> names = Split(kCsvHeader, ',');
  std::vector<Row> rows;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> cells = SplitCsvLine(lines[i]);
    EXPECT_EQ(cells.size(), names.size()) << lines[i];
    Row r;
    for (std::size_t c = 0; c < names.size() && c < cells.size(); ++c) r[names[c]] = cells[c];
    rows.push_back(r);
  }
  return rows;
}

// The printed table's rows of one object (lines that start with a frame number).
std::vector<std::vector<std::string>> TableRows(const std::string& out, const std::string& obj) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& l : Lines(out)) {
    std::istringstream in(l);
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    if (words.empty() || words[0].find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::find(words.begin(), words.end(), obj) == words.end()) continue;
    rows.push_back(words);
  }
  return rows;
}

bool Has(const std::vector<std::string>& words, const std::string& w) {
  return std::find(words.begin(), words.end(), w) != words.end();
}

// Two sequences, written once per binary run by the binary itself:
//   seq:  6 frames, lshape, seed 5 (synth's default slide and turn);
//   jump: 4 frames, lshape, seed 22, 5 mm per frame, no turn, a 15 cm jump at frame 2.
class TrackCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(testing_util::FreshTempPath("track_cli"));
    fs::create_directories(*root_);
    RunResult r = Run({"synth", "--sequence", "6", "--out", Seq(), "--target", "lshape", "--seed", "5"});
    ASSERT_EQ(r.code, 0) << r.err;
    synth_out_ = new std::string(r.out);
    r = Run({"synth", "--sequence", "4", "--out", Jump(), "--target", "lshape", "--seed", "22", "--speed", "0.005", "--turn",
             "0", "--jump-frame", "2", "--jump", "0.15"});
    ASSERT_EQ(r.code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
    delete synth_out_;
    root_ = nullptr;
    synth_out_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(fs::exists(fs::path(Seq()) / "scenes")) << "synth --sequence did not write the sequence";
    dir_ = *root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }

  static RunResult Run(const std::vector<std::string>& args) {
    static int n = 0;
    return testing_util::RunCli(args, *root_ / ("run_" + std::to_string(n++)));
  }
  static std::string Seq() { return (*root_ / "seq").string(); }
  static std::string Jump() { return (*root_ / "jump").string(); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // An input error: exit 1 and exactly one stderr line "posefilter <cmd>: error: …<needle>…".
  static void ExpectInputError(const RunResult& r, const std::string& cmd, const std::string& needle) {
    EXPECT_EQ(r.code, 1) << r.err;
    const auto lines = Lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("posefilter " + cmd + ": error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << needle << "' not in: " << lines[0];
  }
  // A usage error (CLI11): exit 2, the first stderr line names the problem.
  static void ExpectUsageError(const RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.code, 2) << r.err;
    const auto lines = Lines(r.err);
    ASSERT_FALSE(lines.empty());
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << needle << "' not in: " << lines[0];
  }

  inline static fs::path* root_ = nullptr;
  inline static std::string* synth_out_ = nullptr;
  fs::path dir_;
};

TEST_F(TrackCliTest, SynthSequenceWritesADatasetFolderOfItsFrames) {
  EXPECT_NE(synth_out_->find("target lshape  6 frames"), std::string::npos) << *synth_out_;
  EXPECT_TRUE(fs::exists(fs::path(Seq()) / "models" / "lshape.ply"));
  for (int t = 1; t <= 6; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "synth_0000_%06d", t);
    for (const char* f : {"depth.png", "camera.json", "gt.json", "detections.json"})
      EXPECT_TRUE(fs::exists(fs::path(Seq()) / "scenes" / name / f)) << name << "/" << f;
  }
  EXPECT_FALSE(fs::exists(fs::path(Seq()) / "scenes" / "synth_0000_000007"));
  // The ground truth moves from frame to frame.
  const auto gt1 = ReadGtJson((fs::path(Seq()) / "scenes" / "synth_0000_000001" / "gt.json").string());
  const auto gt6 = ReadGtJson((fs::path(Seq()) / "scenes" / "synth_0000_000006" / "gt.json").string());
  ASSERT_EQ(gt1.size(), 1u);
  ASSERT_EQ(gt6.size(), 1u);
  EXPECT_GT((gt1[0].T_cam_obj.translation() - gt6[0].T_cam_obj.translation()).norm(), 0.02);
}

TEST_F(TrackCliTest, TracksTheSequenceFromItsGroundTruthWithCsvAndPerFrameJson) {
  const std::string csv = Path("track.csv"), out_dir = Path("json");
  const RunResult r = Run({"track", "--dataset", Seq(), "--init-gt", "--csv", csv, "--out-dir", out_dir});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  // Every frame printed, tracked and found.
  const auto table = TableRows(r.out, "lshape");
  ASSERT_EQ(table.size(), 6u) << r.out;
  for (std::size_t t = 0; t < table.size(); ++t) {
    EXPECT_EQ(table[t][0], std::to_string(t)) << r.out;
    EXPECT_TRUE(Has(table[t], "tracked")) << r.out;
    EXPECT_TRUE(Has(table[t], "yes")) << r.out;
  }
  EXPECT_NE(r.out.find("6/6"), std::string::npos) << r.out;  // the summary's found column
  EXPECT_NE(r.out.find("per frame"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("stage 1 (--prior"), std::string::npos) << "no stage 1 was given:\n" << r.out;

  // One CSV row per frame and object.
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 6u) << ReadFile(csv);
  const double diameter_mm = MakeShape("lshape").Diameter() * 1e3;
  for (std::size_t t = 0; t < rows.size(); ++t) {
    const Row& row = rows[t];
    EXPECT_EQ(row.at("frame"), std::to_string(t));
    EXPECT_EQ(row.at("scene_id"), "0");
    EXPECT_EQ(row.at("im_id"), std::to_string(t + 1));
    EXPECT_EQ(row.at("obj"), "lshape");
    EXPECT_EQ(row.at("status"), "tracked");
    const double w = std::stod(row.at("weight"));
    EXPECT_GE(w, 0.45);  // --lost-weight's default
    EXPECT_LE(w, 1.0);
    EXPECT_GE(std::stod(row.at("time_ms")), 0.0);
    EXPECT_GE(std::stod(row.at("frame_ms")), std::stod(row.at("time_ms")) - 1e-3);
    EXPECT_EQ(Split(row.at("R"), ' ').size(), 9u);
    EXPECT_EQ(Split(row.at("t"), ' ').size(), 3u);
    ASSERT_FALSE(row.at("adds_mm").empty());
    EXPECT_LT(std::stod(row.at("adds_mm")), 0.1 * diameter_mm);
    EXPECT_EQ(row.at("found"), "yes");

    // The frame's results JSON holds the same pose.
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.json", t);
    const std::vector<ObjectResult> res = ReadResultsJson((fs::path(out_dir) / name).string());
    ASSERT_EQ(res.size(), 1u) << name;
    EXPECT_EQ(res[0].obj, "lshape");
    EXPECT_NEAR(res[0].weight, w, 1e-6);
    EXPECT_GE(res[0].iterations, 1);
    const std::vector<std::string> tr = Split(row.at("t"), ' ');
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(res[0].T_cam_obj.translation()[k], std::stod(tr[std::size_t(k)]), 2e-6) << name;
    EXPECT_NEAR(res[0].T_cam_obj.linear().determinant(), 1.0, 1e-6);
  }
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(out_dir)) files += e.path().extension() == ".json";
  EXPECT_EQ(files, 6u);
}

TEST_F(TrackCliTest, QuietPrintsOnlyTheSummaryAndObjectsAndSceneSelect) {
  const RunResult r = Run({"track", "--dataset", Seq(), "--init-gt", "--quiet", "--scene", "0", "--objects", "lshape"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(TableRows(r.out, "tracked").empty()) << r.out;
  EXPECT_NE(r.out.find("6/6"), std::string::npos) << r.out;
}

TEST_F(TrackCliTest, AJumpIsReportedLostWithoutAStage1) {
  const std::string csv = Path("jump.csv");
  const RunResult r = Run({"track", "--dataset", Jump(), "--init-gt", "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto table = TableRows(r.out, "lshape");
  ASSERT_EQ(table.size(), 4u) << r.out;
  EXPECT_TRUE(Has(table[1], "tracked")) << r.out;
  EXPECT_TRUE(Has(table[2], "lost")) << r.out;
  EXPECT_TRUE(Has(table[3], "lost")) << r.out;
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 4u);
  const std::vector<std::string> status = {rows[0].at("status"), rows[1].at("status"), rows[2].at("status"), rows[3].at("status")};
  EXPECT_EQ(status, (std::vector<std::string>{"tracked", "tracked", "lost", "lost"}));
  const std::vector<std::string> found = {rows[0].at("found"), rows[1].at("found"), rows[2].at("found"), rows[3].at("found")};
  EXPECT_EQ(found, (std::vector<std::string>{"yes", "yes", "no", "no"}));
  EXPECT_NE(r.out.find("2/4"), std::string::npos) << r.out;
}

TEST_F(TrackCliTest, ALostObjectIsNeverFoundEvenWhenItsSearchPoseIsClose) {
  // --lost-weight 0.99: every step is judged lost, though the searched pose is near the truth.
  const std::string csv = Path("strict.csv");
  const RunResult r = Run({"track", "--dataset", Seq(), "--init-gt", "--lost-weight", "0.99", "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 6u);
  const double diameter_mm = MakeShape("lshape").Diameter() * 1e3;
  for (const Row& row : rows) {
    EXPECT_EQ(row.at("status"), "lost");
    EXPECT_EQ(row.at("found"), "no");
    ASSERT_FALSE(row.at("adds_mm").empty());  // a lost object still has its search's pose
  }
  EXPECT_LT(std::stod(rows[0].at("adds_mm")), 0.1 * diameter_mm) << "frame 0 searched about the true pose";
  EXPECT_NE(r.out.find("0/6"), std::string::npos) << r.out;
}

TEST_F(TrackCliTest, ADetectionsPriorRestartsTheObjectAfterTheJump) {
  // The BOP detections of the jump sequence: each frame's synthetic detection of the target (the
  // first of the frame's list; the false positives are left out). lshape is the folder's only
  // model, obj_id 22: the first id after the 21 YCB-Video ones.
  nlohmann::json dets = nlohmann::json::array();
  for (int t = 1; t <= 4; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "synth_0000_%06d", t);
    const std::vector<Detection> list = ReadDetectionsJson((fs::path(Jump()) / "scenes" / name / "detections.json").string());
    ASSERT_FALSE(list.empty());
    const Detection& d = list[0];
    ASSERT_EQ(d.cls, "lshape") << name;
    dets.push_back({{"scene_id", 0}, {"image_id", t}, {"category_id", 22}, {"score", d.score}, {"bbox", {d.x, d.y, d.w, d.h}}});
  }
  ASSERT_EQ(dets.size(), 4u);
  const std::string json = Path("dets.json");
  testing_util::WriteFile(json, dets.dump());
  const std::string csv = Path("restart.csv");
  const RunResult r = Run({"track", "--dataset", Jump(), "--init-gt", "--prior", json, "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 4u);
  std::vector<std::string> status, found;
  for (const Row& row : rows) status.push_back(row.at("status")), found.push_back(row.at("found"));
  EXPECT_EQ(status, (std::vector<std::string>{"tracked", "tracked", "initialised", "tracked"})) << r.out;
  EXPECT_EQ(found, (std::vector<std::string>{"yes", "yes", "yes", "yes"})) << r.out;
  // The stage 1 ran once: for the jump frame only.
  EXPECT_NE(r.out.find("stage 1 (--prior detections): 1 frame(s)"), std::string::npos) << r.out;
}

TEST_F(TrackCliTest, TheAutoPriorStartsTheSequenceWithoutGroundTruthAndRunsOnce) {
  const std::string csv = Path("auto.csv");
  const RunResult r = Run({"track", "--dataset", Seq(), "--prior", "auto", "--quiet", "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t t = 0; t < rows.size(); ++t) {
    EXPECT_EQ(rows[t].at("status"), t == 0 ? "initialised" : "tracked") << t;
    EXPECT_EQ(rows[t].at("found"), "yes") << t << ": ADD-S " << rows[t].at("adds_mm");
  }
  EXPECT_NE(r.out.find("stage 1 (--prior auto): 1 frame(s)"), std::string::npos) << r.out;
}

TEST_F(TrackCliTest, AFolderOfDepthPngsStartsFromAUniformStage1) {
  const fs::path frames = dir_ / "frames";
  fs::create_directories(frames);
  for (int t = 1; t <= 3; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "synth_0000_%06d", t);
    fs::copy_file(fs::path(Seq()) / "scenes" / name / "depth.png", frames / ("f" + std::to_string(t) + ".png"));
  }
  testing_util::WriteFile(frames / "notes.txt", "not a frame\n");
  const std::string camera = (fs::path(Seq()) / "scenes" / "synth_0000_000001" / "camera.json").string();
  // A name with a comma and a quote: the CSV quotes it.
  const std::string mesh = "l,\"shape\"=" + (fs::path(Seq()) / "models" / "lshape.ply").string();
  const std::string csv = Path("frames.csv");
  const RunResult r = Run({"track", "--frames", frames.string(), "--camera", camera, "--mesh", mesh, "--prior", "none",
                           "--refresh-weight", "0", "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto table = TableRows(r.out, "l,\"shape\"");
  ASSERT_EQ(table.size(), 3u) << r.out;
  EXPECT_TRUE(Has(table[0], "f1")) << r.out;  // rows named by the PNG's stem, in name order
  EXPECT_TRUE(Has(table[2], "f3")) << r.out;
  EXPECT_NE(ReadFile(csv).find(",\"l,\"\"shape\"\"\","), std::string::npos) << ReadFile(csv);
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("obj"), "l,\"shape\"");
  EXPECT_EQ(rows[0].at("status"), "initialised") << r.out;
  EXPECT_EQ(rows[1].at("status"), "tracked") << r.out;
  EXPECT_EQ(rows[2].at("status"), "tracked") << r.out;
  for (const Row& row : rows) {
    EXPECT_EQ(row.at("adds_mm"), "");  // no ground truth
    EXPECT_EQ(row.at("found"), "");
  }
  EXPECT_NE(r.out.find("stage 1 (--prior none): 1 frame(s)"), std::string::npos) << r.out;
  // The initialised pose is the frame's ground truth (the scene is easy).
  const auto gt = ReadGtJson((fs::path(Seq()) / "scenes" / "synth_0000_000003" / "gt.json").string());
  const std::vector<std::string> tr = Split(rows[2].at("t"), ' ');
  ASSERT_EQ(tr.size(), 3u);
  const Eigen::Vector3d t3(std::stod(tr[0]), std::stod(tr[1]), std::stod(tr[2]));
  EXPECT_LT((t3 - gt[0].T_cam_obj.translation()).norm(), 0.02);
}

TEST_F(TrackCliTest, EveryYcbVideoFrameIsFoundFromTheFirstGroundTruth) {
  const fs::path data = testing_util::YcbvDataDir();
  if (!fs::exists(data / "scenes")) GTEST_SKIP() << "no " << data;
  const std::string csv = Path("ycbv.csv");
  const RunResult r = Run({"track", "--dataset", data.string(), "--init-gt", "--quiet", "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Row> rows = ReadTrackCsv(csv);
  ASSERT_EQ(rows.size(), 30u) << ReadFile(csv);  // 10 frames × 3 objects
  std::map<std::string, int> found;
  for (const Row& row : rows) {
    EXPECT_EQ(row.at("found"), "yes") << row.at("frame") << " " << row.at("obj") << " " << row.at("status") << " ADD-S "
                                      << row.at("adds_mm");
    EXPECT_EQ(row.at("status"), "tracked") << row.at("frame") << " " << row.at("obj");
    ++found[row.at("obj")];
  }
  EXPECT_EQ(found, (std::map<std::string, int>{{"009_gelatin_box", 10}, {"025_mug", 10}, {"061_foam_brick", 10}}));
  for (const char* obj : {"009_gelatin_box", "025_mug", "061_foam_brick"}) EXPECT_NE(r.out.find(obj), std::string::npos);
  EXPECT_NE(r.out.find("10/10"), std::string::npos) << r.out;
}

// ---- Errors ---------------------------------------------------------------------------------

TEST_F(TrackCliTest, SequenceChoiceErrors) {
  ExpectUsageError(Run({"track", "--init-gt"}), "--dataset DIR or --frames DIR");
  ExpectUsageError(Run({"track", "--dataset", Seq(), "--frames", Seq(), "--init-gt"}), "excludes");
  const std::string camera = (fs::path(Seq()) / "scenes" / "synth_0000_000001" / "camera.json").string();
  const std::string mesh = "lshape=" + (fs::path(Seq()) / "models" / "lshape.ply").string();
  const std::string depths = (fs::path(Seq()) / "scenes" / "synth_0000_000001").string();
  ExpectInputError(Run({"track", "--frames", depths, "--prior", "none"}), "track", "--frames needs --camera and --mesh");
  ExpectInputError(Run({"track", "--frames", depths, "--camera", camera, "--prior", "none"}), "track",
                   "--frames needs --camera and --mesh");
  ExpectInputError(Run({"track", "--frames", depths, "--mesh", mesh, "--prior", "none"}), "track",
                   "--frames needs --camera and --mesh");
  ExpectInputError(Run({"track", "--frames", depths, "--camera", camera, "--mesh", mesh, "--init-gt"}), "track",
                   "--init-gt needs a --dataset");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--camera", camera}), "track", "belong to --frames");
}

TEST_F(TrackCliTest, StartAndPriorErrors) {
  ExpectInputError(Run({"track", "--dataset", Seq()}), "track", "give --prior");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--prior", "detections.txt"}), "track",
                   "--prior must be auto, none or a BOP detections JSON");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--prior", "automatic"}), "track", "'automatic'");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--prior", Path("missing.json")}), "track", "missing.json");
  const std::string camera = (fs::path(Seq()) / "scenes" / "synth_0000_000001" / "camera.json").string();
  const std::string mesh = "lshape=" + (fs::path(Seq()) / "models" / "lshape.ply").string();
  ExpectInputError(Run({"track", "--frames", Seq(), "--camera", camera, "--mesh", mesh, "--prior", Path("d.json")}), "track",
                   "a detections file needs --dataset");
}

TEST_F(TrackCliTest, DatasetErrors) {
  ExpectInputError(Run({"track", "--dataset", Path("no_such_dataset"), "--init-gt"}), "track", "no_such_dataset");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--scene", "7"}), "track", "no images of scene 7");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--objects", "lshape,teapot"}), "track",
                   "'teapot' is not a model");
}

TEST_F(TrackCliTest, OptionRangeErrors) {
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--lost-weight", "3"}), "track", "lost_weight");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--refresh-weight", "-1"}), "track", "refresh_weight");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--window-margin", "0"}), "track", "window_margin");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--search-r", "4"}), "track", "search_r_rad");
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--particles", "0"}), "track", "--particles");
}

TEST_F(TrackCliTest, FramesFolderErrors) {
  const std::string camera = (fs::path(Seq()) / "scenes" / "synth_0000_000001" / "camera.json").string();
  const std::string mesh = "lshape=" + (fs::path(Seq()) / "models" / "lshape.ply").string();
  // A folder without PNGs.
  const fs::path empty = dir_ / "empty";
  fs::create_directories(empty);
  testing_util::WriteFile(empty / "depth.txt", "1\n");
  ExpectInputError(Run({"track", "--frames", empty.string(), "--camera", camera, "--mesh", mesh, "--prior", "none"}), "track",
                   "holds no .png");
  ExpectInputError(Run({"track", "--frames", Path("missing"), "--camera", camera, "--mesh", mesh, "--prior", "none"}), "track",
                   "not a folder");
  // A PNG of another size than the camera's among the frames: an error once it is reached.
  const fs::path mixed = dir_ / "mixed";
  fs::create_directories(mixed);
  fs::copy_file(fs::path(Seq()) / "scenes" / "synth_0000_000001" / "depth.png", mixed / "a.png");
  SaveDepthPng(DepthImage(320, 240, 0.8f), (mixed / "b.png").string(), 0.0001);
  // An existing --csv is replaced only by a finished run: the failed one leaves it as it was.
  const std::string csv = Path("kept.csv");
  testing_util::WriteFile(csv, "an earlier run\n");
  const RunResult r = Run({"track", "--frames", mixed.string(), "--camera", camera, "--mesh", mesh, "--prior", "none",
                           "--refresh-weight", "0", "--csv", csv});
  ExpectInputError(r, "track", "320x240");
  EXPECT_EQ(testing_util::ReadFile(csv), "an earlier run\n");
}

// No output lands on an input: a file of the dataset, a mesh, or a per-frame JSON's name.
TEST_F(TrackCliTest, OutputsNeverOverwriteInputs) {
  const fs::path gt = fs::path(Seq()) / "scenes" / "synth_0000_000001" / "gt.json";
  const std::string gt_before = testing_util::ReadFile(gt);
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--csv", gt.string()}), "track",
                   "is a file of the input folder --dataset");
  EXPECT_EQ(testing_util::ReadFile(gt), gt_before);
  ExpectInputError(Run({"track", "--dataset", Seq(), "--init-gt", "--out-dir", (fs::path(Seq()) / "scenes").string()}),
                   "track", "inside the input folder --dataset");
  const std::string camera = (fs::path(Seq()) / "scenes" / "synth_0000_000001" / "camera.json").string();
  const std::string mesh_path = Path("lshape.ply");  // outside the frames' folder
  fs::copy_file(fs::path(Seq()) / "models" / "lshape.ply", mesh_path);
  ExpectInputError(Run({"track", "--frames", Seq(), "--camera", camera, "--mesh", "lshape=" + mesh_path, "--prior", "none",
                        "--csv", mesh_path}),
                   "track", "is the input --mesh");
  // A camera file named like a per-frame result, in the --out-dir.
  const fs::path odir = dir_ / "odir";
  fs::create_directories(odir);
  fs::copy_file(camera, odir / "000000.json");
  ExpectInputError(Run({"track", "--frames", Seq(), "--camera", (odir / "000000.json").string(), "--mesh",
                        "lshape=" + mesh_path, "--prior", "none", "--out-dir", odir.string()}),
                   "track", "holds the input --camera");
  EXPECT_EQ(testing_util::ReadFile(odir / "000000.json"), testing_util::ReadFile(camera));
}

TEST_F(TrackCliTest, SynthSequenceErrors) {
  const std::string out = Path("synth_out");
  ExpectInputError(Run({"synth", "--sequence", "0", "--out", out}), "synth", "frames must be in [1, 1000]");
  ExpectInputError(Run({"synth", "--sequence", "5", "--occlusion", "0.5", "--out", out}), "synth", "occlusion must be 0");
  ExpectInputError(Run({"synth", "--speed", "0.1", "--out", out}), "synth", "give --sequence N");
  ExpectInputError(Run({"synth", "--jump", "0.1", "--out", out}), "synth", "give --sequence N");
  ExpectInputError(Run({"synth", "--sequence", "5", "--count", "3", "--out", out}), "synth", "--count does not apply");
  ExpectInputError(Run({"synth", "--sequence", "5", "--jump-frame", "5", "--jump", "0.1", "--out", out}), "synth",
                   "jump_frame");
  ExpectInputError(Run({"synth", "--sequence", "5", "--speed", "0.6", "--out", out}), "synth", "speed_m");
  EXPECT_FALSE(fs::exists(out)) << "a refused synth wrote " << out;
}

}  // namespace
}  // namespace posefilter
