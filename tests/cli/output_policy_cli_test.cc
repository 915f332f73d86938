// The output policy as a matrix: every command that writes a file, each of its output options,
// against every kind of output the policy refuses before any work — an existing symbolic link,
// FIFO or device node, an empty path, a missing folder, a file name too long for the temporary
// name, and a file the command reads (given directly or found through a folder) or writes
// under another option. Each must end with exit 1 and one line "posefilter <cmd>: error: …"
// that names the option, and leave every file as it was: the scratch folder and the inputs are
// listed (kind, and size, inode and modification time of regular files) before and after each run. docs/RELIABILITY.md
// states the policy.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cli/cli_fixture.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ReadFile;
using testing_util::RunResult;

// What a folder holds: for each entry (recursively, links not followed), its kind and, for a
// regular file, its size, inode and modification time in nanoseconds (a write in place moves
// the time, an atomic replacement the inode), without reading the bytes.
std::map<std::string, std::string> Snapshot(const fs::path& root) {
  std::map<std::string, std::string> s;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::none, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    struct stat st {};
    if (::lstat(it->path().c_str(), &st) != 0) {
      s[it->path().string()] = "gone";
      continue;
    }
    std::string v;
    switch (st.st_mode & S_IFMT) {
      case S_IFREG: v = "file"; break;
      case S_IFDIR: v = "dir"; break;
      case S_IFLNK: v = "link:" + fs::read_symlink(it->path()).string(); break;
      case S_IFIFO: v = "fifo"; break;
      case S_IFCHR: v = "char"; break;
      default: v = "other"; break;
    }
    if (S_ISREG(st.st_mode))
      v += ":" + std::to_string(st.st_size) + ":" + std::to_string(st.st_ino) + ":" +
           std::to_string(std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec);
    s[it->path().string()] = v;
  }
  return s;
}

// One output option of one command: the argv without the option, and files the option must
// never be given (inputs of the command, found directly or through a folder, and the paths of
// its other outputs), each with a phrase of the expected message.
struct OutputCase {
  std::string command;
  std::vector<std::string> args;
  std::string option;
  std::vector<std::pair<std::string, std::string>> victims;  // (path, message phrase)
};

class OutputPolicyTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    // A two-frame sequence in the YCB-Video layout for track and run-dataset (models/ and scenes/).
    seq_ = Path("seq");
    const RunResult r = Run({"synth", "--out", seq_, "--target", "box", "--sequence", "2", "--seed", "5"});
    ASSERT_EQ(r.code, 0) << r.err;
    frame_ = (fs::path(seq_) / "scenes" / "synth_0000_000001").string();
    ASSERT_TRUE(fs::exists(fs::path(frame_) / "gt.json")) << "synth --sequence wrote no frame " << frame_;
    results_ = Path("results.json");
    ObjectResult res;
    res.obj = "box";
    res.T_cam_obj = ReadGtJson(Scene("gt.json")).at(0).T_cam_obj;
    res.weight = 0.5;
    res.iterations = 2;
    WriteResultsJson({res}, results_);
    results_csv_ = Path("results.csv");
    testing_util::WriteFile(results_csv_, "scene_id,im_id,obj_id,score,R,t,time\n");
    demo_ = Path("demo");
    fs::create_directories(demo_);
    testing_util::WriteFile((fs::path(demo_) / "depth.png").string(), "an earlier demo's image");
  }

  std::vector<OutputCase> Cases() const {
    const std::string depth = Scene("depth.png"), camera = Scene("camera.json"), mesh = Scene("box.ply"),
                      dets = Scene("detections.json"), gt = Scene("gt.json");
    const std::string seq_mesh = (fs::path(seq_) / "models" / "box.ply").string();
    const std::string frame_gt = (fs::path(frame_) / "gt.json").string();
    const std::string frame_depth = (fs::path(frame_) / "depth.png").string();
    const std::vector<std::string> small = {"--particles", "32", "--iterations", "2", "--restarts", "1"};
    auto with = [](std::vector<std::string> a, const std::vector<std::string>& b) {
      a.insert(a.end(), b.begin(), b.end());
      return a;
    };
    const char* kInput = "would be overwritten";
    const char* kOther = "give each output its own file";
    // run-dataset appends to a results CSV, which may live in the dataset's folder: an existing
    // file there is refused because it is not a results CSV, before any byte of it changes.
    const char* kNotResults = "is not a results CSV";
    const std::vector<std::string> estimate = with(
        {"estimate", "--depth", depth, "--camera", camera, "--mesh", mesh, "--prior", dets, "--quiet"}, small);
    const std::vector<std::string> track = with({"track", "--dataset", seq_, "--init-gt", "--quiet"}, small);
    return {
        {"estimate", with(estimate, {"--overlay", Path("o.png")}), "--out",
         {{depth, kInput}, {dets, kInput}, {mesh, kInput}, {Path("o.png"), kOther}}},
        {"estimate", with(estimate, {"--out", Path("r.json")}), "--overlay", {{camera, kInput}, {Path("r.json"), kOther}}},
        {"estimate", with(estimate, {"--out", Path("r.json")}), "--view", {{mesh, kInput}, {Path("r.json"), kOther}}},
        {"eval", {"eval", "--results", results_, "--gt", gt, "--mesh", "box=" + mesh}, "--json",
         {{results_, kInput}, {gt, kInput}, {mesh, kInput}}},
        // Inputs found through --dataset: a frame's files and the dataset's meshes.
        {"eval", {"eval", "--dataset", seq_, "--results", results_csv_, "--no-vsd", "--quiet"}, "--json",
         {{frame_gt, kInput}, {frame_depth, kInput}, {seq_mesh, kInput}, {results_csv_, kInput}}},
        {"track", track, "--csv", {{frame_gt, kInput}, {frame_depth, kInput}, {seq_mesh, kInput}}},
        {"gt-detections", {"gt-detections", "--gt", gt, "--camera", camera, "--models-dir", Scene(""), "--quiet"},
         "--out", {{gt, kInput}, {camera, kInput}, {mesh, kInput}}},
        {"run-dataset", with({"run-dataset", "--dataset", seq_, "--gt-boxes", "0.1", "--quiet"}, small), "--out",
         {{frame_gt, kNotResults}, {frame_depth, kNotResults}, {seq_mesh, kNotResults}}},
        {"suite", with({"suite", "--count", "1"}, small), "--json", {}},
        {"bench", {"bench"}, "--json", {}},
        {"hw-report", {"hw-report", "--cores", "1"}, "--json", {}},
        // demo writes its scene, results and overlay into --out: --view must not be one of them.
        {"demo", {"demo", "--out", demo_}, "--view",
         {{(fs::path(demo_) / "depth.png").string(), kOther}, {(fs::path(demo_) / "overlay.png").string(), kOther}}},
    };
  }

  std::string seq_, frame_, results_, results_csv_, demo_;
};

TEST_F(OutputPolicyTest, EveryOutputOptionRefusesWhatItMustNotWriteAndChangesNothing) {
  // The special files the atomic replacement would destroy.
  const std::string target = Path("target.txt");
  testing_util::WriteFile(target, "keep me\n");
  const std::string link = Path("link.json");
  fs::create_symlink(target, link);
  const std::string fifo = Path("fifo.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const std::string device = Path("null.json");  // a node like /dev/null (needs CAP_MKNOD)
  const bool have_device = ::mknod(device.c_str(), S_IFCHR | 0600, ::makedev(1, 3)) == 0;
  if (!have_device) std::printf("no device node case: mknod: %s\n", std::strerror(errno));
  const std::string long_name = Path(std::string(250, 'n') + ".json");  // fits, its temporary name does not

  struct Bad {
    std::string path, phrase;
  };
  std::vector<Bad> common = {{link, "symbolic link"},
                             {fifo, "FIFO"},
                             {"", "empty value"},
                             {Path("no_such_folder/out.json"), "does not exist"},
                             {long_name, "temporary name"}};
  if (have_device) common.push_back({device, "character device"});

  const fs::path inputs = fs::path(Scene("")).parent_path();
  int runs = 0;
  for (const OutputCase& c : Cases()) {
    std::vector<Bad> bad = common;
    for (const auto& [path, phrase] : c.victims) bad.push_back({path, phrase});
    for (const Bad& b : bad) {
      SCOPED_TRACE(c.command + " " + c.option + " '" + b.path + "'");
      const auto before = Snapshot(dir_), inputs_before = Snapshot(inputs);
      std::vector<std::string> argv = c.args;
      argv.push_back(c.option);
      argv.push_back(b.path);
      const RunResult r = Run(argv);
      ++runs;
      ExpectInputError(r, c.command, c.option);
      EXPECT_NE(r.err.find(b.phrase), std::string::npos) << "'" << b.phrase << "' not in: " << r.err;
      EXPECT_TRUE(Snapshot(dir_) == before) << "a file in the scratch folder changed";
      EXPECT_TRUE(Snapshot(inputs) == inputs_before) << "an input changed";
    }
  }
  EXPECT_EQ(fs::symlink_status(link).type(), fs::file_type::symlink);
  EXPECT_EQ(fs::symlink_status(fifo).type(), fs::file_type::fifo);
  EXPECT_EQ(ReadFile(target), "keep me\n");
  EXPECT_GE(runs, 70);
}

// The folders a command fills (synth --out, track --out-dir) are created with their parents;
// a path that exists and is not a folder, or an empty one, is refused naming the option, and
// nothing is written.
TEST_F(OutputPolicyTest, OutputFoldersAreFoldersOrNew) {
  const std::string file = Path("file.txt");
  testing_util::WriteFile(file, "x\n");
  const std::string fifo = Path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  for (const std::string& bad : {file, fifo, std::string()}) {
    SCOPED_TRACE("'" + bad + "'");
    const auto before = Snapshot(dir_);
    ExpectInputError(Run({"synth", "--target", "box", "--out", bad}), "synth", "--out");
    ExpectInputError(Run({"track", "--dataset", seq_, "--init-gt", "--quiet", "--particles", "32", "--iterations", "2",
                          "--out-dir", bad}),
                     "track", "--out-dir");
    EXPECT_TRUE(Snapshot(dir_) == before);
  }
  // A new nested folder is made.
  ASSERT_EQ(Run({"synth", "--target", "box", "--out", Path("a/b")}).code, 0);
  EXPECT_TRUE(fs::exists(Path("a/b/scene_000/depth.png")));
}

}  // namespace
}  // namespace posefilter
