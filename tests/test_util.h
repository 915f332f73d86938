// tests/test_util.h — helpers shared by the test binaries: scratch directories and whole-file
// reads/writes, the expectation that a call throws posefilter::Error naming given words, small
// mesh/camera builders, and running the built `posefilter` binary (POSEFILTER_CLI_PATH).
// Header-only; every test binary gets tests/ on its include path.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/error.h"
#include "posefilter/mesh.h"

namespace posefilter::testing_util {

namespace fs = std::filesystem;

// ---- Files -----------------------------------------------------------------------------------

// <system temp dir>/posefilter_<tag>_<pid>, removed if it exists (not created): unique per
// process, so parallel ctest runs do not collide.
inline fs::path FreshTempPath(const std::string& tag) {
  const fs::path p = fs::temp_directory_path() / ("posefilter_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

// The whole file, byte for byte ("" when it cannot be opened).
inline std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Writes `bytes` to `path` (replacing it); a failed write fails the test.
inline void WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  EXPECT_TRUE(out.good()) << "cannot write " << path;
}

// A directory of its own for the running test: <temp>/posefilter_<tag>_<suite>_<test>_<pid>
// ('/' of parameterised names → '_'), created empty on construction, removed on destruction.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string leaf = tag + "_" + info->test_suite_name() + "_" + info->name();
    std::replace(leaf.begin(), leaf.end(), '/', '_');
    dir_ = FreshTempPath(leaf);
    fs::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const fs::path& dir() const { return dir_; }
  // The path of `name` in the directory (nothing is created).
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  // Writes `bytes` to `name` in the directory; returns its path.
  std::string Write(const std::string& name, const std::string& bytes) const {
    WriteFile(dir_ / name, bytes);
    return Path(name);
  }

 private:
  fs::path dir_;
};

// A fixture with a ScratchDir per test; `tag` names the test file's area ("json", "mesh", …).
class ScratchDirTest : public ::testing::Test, public ScratchDir {
 protected:
  explicit ScratchDirTest(const std::string& tag) : ScratchDir(tag) {}
};

// The real YCB-Video data (README "Data"): $POSEFILTER_DATA/ycbv when POSEFILTER_DATA is set,
// else the shared folder's data/ycbv. Optional: tests using it skip, naming this folder, when it
// is absent.
inline fs::path YcbvDataDir() {
  const char* data = std::getenv("POSEFILTER_DATA");
  if (data != nullptr && *data != '\0') return fs::path(data) / "ycbv";
  return fs::path(POSEFILTER_SHARED_DIR) / "data" / "ycbv";
}

// ---- Errors ----------------------------------------------------------------------------------

// Expects `fn` to throw posefilter::Error with a one-line message containing every one of
// `parts`.
template <typename Fn>
void ExpectError(Fn fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no posefilter::Error thrown";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const auto& part : parts) {
      EXPECT_NE(msg.find(part), std::string::npos) << "message: " << msg << "\nmissing: " << part;
    }
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
  }
}

// Expects `value.IsValid(&why)` to fail with a reason containing `needle`.
template <typename T>
void ExpectInvalid(const T& value, const std::string& needle) {
  std::string why;
  EXPECT_FALSE(value.IsValid(&why)) << "accepted, expected a reason naming " << needle;
  EXPECT_NE(why.find(needle), std::string::npos) << "why = " << why << "\nmissing: " << needle;
}

// ---- Geometry --------------------------------------------------------------------------------

// A square of side s (metres) in the object's z = 0 plane, two triangles, CCW seen from −z:
// its normal (v1−v0)×(v2−v0) points to −z, towards a camera looking along +z at it.
inline Mesh FrontSquare(float s) {
  Mesh m;
  m.name = "square";
  const float h = s / 2;
  m.vertices = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  m.faces = {{0, 3, 2}, {0, 2, 1}};
  return m;
}

// A 640×480 pinhole camera with the given intrinsics (pixels) and identity base_to_camera.
inline Camera PinholeCamera(double fx, double fy, double cx = 320, double cy = 240) {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  return c;
}

// The pure translation (x, y, z) (metres).
inline Eigen::Isometry3d At(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// ---- The CLI binary --------------------------------------------------------------------------

struct RunResult {
  int code = -1;  // exit status; -1 if the process did not exit normally
  std::string out, err;
};

// `s` as one single-quoted shell word.
inline std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `posefilter <shell_args>` through the shell (`shell_args` already quoted as needed),
// stdout and stderr captured in <capture>.out and <capture>.err.
inline RunResult RunCliShell(const std::string& shell_args, const fs::path& capture) {
  const std::string out = capture.string() + ".out", err = capture.string() + ".err";
  std::string cmd = ShellQuote(POSEFILTER_CLI_PATH);
  if (!shell_args.empty()) cmd += " " + shell_args;
  cmd += " >" + ShellQuote(out) + " 2>" + ShellQuote(err);
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadFile(out);
  r.err = ReadFile(err);
  return r;
}

// Runs `posefilter` with `args`, each passed as one argument; output captured as above.
inline RunResult RunCli(const std::vector<std::string>& args, const fs::path& capture) {
  std::string shell_args;
  for (const auto& a : args) shell_args += (shell_args.empty() ? "" : " ") + ShellQuote(a);
  return RunCliShell(shell_args, capture);
}

// The lines of `s` (no trailing empty line).
inline std::vector<std::string> Lines(const std::string& s) {
  std::vector<std::string> lines;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

}  // namespace posefilter::testing_util
