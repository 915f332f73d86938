// Tests of how files are written (include/posefilter/file_io.h): atomic replacement, durable
// appends, torn-line repair and the output-path checks the CLI makes before it starts work.
#include "posefilter/file_io.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/mask_prior.h"
#include "posefilter/mesh.h"
#include "posefilter/metrics.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectError;
using testing_util::ReadFile;
using testing_util::WriteFile;

class FileIoTest : public testing_util::ScratchDirTest {
 protected:
  FileIoTest() : ScratchDirTest("file_io") {}
  // Number of entries in the scratch directory (temporary files left behind show up here).
  int Entries() const {
    int n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir())) ++n;
    return n;
  }
};

TEST_F(FileIoTest, WriteCreatesAndReplacesWholeFiles) {
  const std::string path = (dir() / "a.json").string();
  WriteFileAtomically(path, [](std::ostream& os) { os << "first\n"; });
  EXPECT_EQ(ReadFile(path), "first\n");
  WriteFileAtomically(path, [](std::ostream& os) { os << "second, longer\n"; });
  EXPECT_EQ(ReadFile(path), "second, longer\n");
  EXPECT_EQ(Entries(), 1) << "a temporary file was left beside the target";
}

TEST_F(FileIoTest, FailedFormatterLeavesTargetUntouched) {
  const std::string path = (dir() / "a.json").string();
  WriteFile(path, "old\n");
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](std::ostream& os) {
                                     os << "half";
                                     throw std::runtime_error("formatter failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadFile(path), "old\n");
  EXPECT_EQ(Entries(), 1);
}

TEST_F(FileIoTest, MissingDirectoryNamesTheTarget) {
  const std::string path = (dir() / "no_such_dir" / "a.json").string();
  ExpectError([&] { WriteFileAtomically(path, [](std::ostream& os) { os << "x"; }); }, {path, "does not exist"});
  ExpectError([&] { WriteFileAtomicallyC(path, [](std::FILE*, std::string*) { return true; }); }, {path});
}

TEST_F(FileIoTest, CWriterFailureRemovesTheTemporaryFile) {
  const std::string path = (dir() / "a.png").string();
  WriteFile(path, "old");
  ExpectError(
      [&] {
        WriteFileAtomicallyC(path, [](std::FILE* fp, std::string* error) {
          std::fputs("partial", fp);
          *error = "encoder gave up";
          return false;
        });
      },
      {path, "encoder gave up"});
  EXPECT_EQ(ReadFile(path), "old");
  EXPECT_EQ(Entries(), 1);
}

// A write that runs out of space (here: the file-size limit, RLIMIT_FSIZE, which makes write(2)
// fail with EFBIG as a full disk fails with ENOSPC) leaves the old file whole and no temporary
// file. Runs in a child process so the limit does not touch the test runner.
TEST_F(FileIoTest, WriteFailureMidwayLeavesTargetUntouched) {
  const std::string path = (dir() / "results.json").string();
  const std::string old(100, 'o');
  WriteFile(path, old);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim {4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    int code = 3;
    try {
      WriteFileAtomically(path, [](std::ostream& os) { os << std::string(100000, 'n'); });
      code = 1;  // the write should have failed
    } catch (const Error& e) {
      code = std::string(e.what()).find(path) != std::string::npos ? 0 : 2;
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: the error did not name the file";
  EXPECT_EQ(ReadFile(path), old);
  EXPECT_EQ(Entries(), 1);
}

// Every reader of a command's inputs refuses a huge file within its stated limits, also when the
// process's address space is limited (ulimit -v): sparse files of 2 GiB (over kMaxMeshBytes
// and kMaxSmallFileBytes, a PNG that is not one, raw pyramid floats) must each give an Error, not
// std::bad_alloc and not a crash. In a child process with RLIMIT_AS 512 MiB above its size;
// skipped under the sanitizers, whose shadow memory needs terabytes of address space.
TEST_F(FileIoTest, EveryReaderStaysWithinItsLimitUnderAnAddressSpaceLimit) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "RLIMIT_AS cannot be set under a sanitizer";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
  GTEST_SKIP() << "RLIMIT_AS cannot be set under a sanitizer";
#endif
#endif
  const std::uintmax_t huge = std::uintmax_t(2) << 30;
  auto sparse = [&](const std::string& name, const std::string& head) {
    const std::string path = (dir() / name).string();
    WriteFile(path, head);
    fs::resize_file(path, huge);
    return path;
  };
  const std::string json = sparse("huge.json", "{\"objects\": [");
  const std::string csv = sparse("huge.csv", "scene_id,im_id,obj_id,score,R,t,time\n");
  const std::string ply = sparse("huge.ply", "ply\nformat ascii 1.0\n");
  const std::string obj = sparse("huge.obj", "v 0 0 0\n");
  const std::string png = sparse("huge.png", "\x89PNG\r\n\x1a\n");
  const std::string raw = sparse("huge.raw", "");
  const std::string xyz = sparse("huge.xyz", "0 0 0\n");
  const std::vector<std::pair<std::string, std::function<void()>>> readers = {
      {"ReadCameraJson", [&] { ReadCameraJson(json); }},
      {"ReadGtJson", [&] { ReadGtJson(json); }},
      {"ReadResultsJson", [&] { ReadResultsJson(json); }},
      {"ReadDetectionsJson", [&] { ReadDetectionsJson(json); }},
      {"ReadMaskClasses", [&] { ReadMaskClasses(json); }},
      {"ReadBopDetections", [&] { ReadBopDetections(json); }},
      {"ReadBopResultsCsv", [&] { ReadBopResultsCsv(csv); }},
      {"ReadXyzPoints", [&] { ReadXyzPoints(xyz); }},
      {"LoadMesh ply", [&] { LoadMesh(ply); }},
      {"LoadMesh obj", [&] { LoadMesh(obj); }},
      {"LoadDepthPng", [&] { LoadDepthPng(png, 0.001); }},
      {"LoadRgbPng", [&] { LoadRgbPng(png); }},
      {"LoadLabelPng", [&] { LoadLabelPng(png); }},
      {"ReadRawPyramid", [&] { ReadRawPyramid(raw, PyramidLayout::Thesis()); }},
  };
  for (std::size_t i = 0; i < readers.size(); ++i) {
    SCOPED_TRACE(readers[i].first);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      long pages = 0;
      if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
        std::fclose(f);
      }
      const rlim_t limit = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + (rlim_t(512) << 20);
      struct rlimit lim {limit, limit};
      if (pages == 0 || ::setrlimit(RLIMIT_AS, &lim) != 0) ::_exit(4);
      int code = 1;  // no error
      try {
        readers[i].second();
      } catch (const Error&) {
        code = 0;
      } catch (const std::bad_alloc&) {
        code = 2;
      } catch (...) {
        code = 3;
      }
      ::_exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status)) << "the reader crashed (signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << ")";
    EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: std::bad_alloc, 3: another exception, 4: no limit set";
  }
}

// The same for an append: a row that does not fit is cut back, the file keeps its whole rows.
TEST_F(FileIoTest, FailedAppendIsUndone) {
  const std::string path = (dir() / "results.csv").string();
  AppendFileDurably(path, "h\n");
  AppendFileDurably(path, "row 1\n");
  EXPECT_EQ(ReadFile(path), "h\nrow 1\n");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim {64, 64};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    int code = 1;
    try {
      AppendFileDurably(path, std::string(200, 'r') + "\n");
    } catch (const Error&) {
      code = 0;
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the append did not fail";
  EXPECT_EQ(ReadFile(path), "h\nrow 1\n");
}

TEST_F(FileIoTest, TrimTornLastLine) {
  const std::string path = (dir() / "r.csv").string();
  EXPECT_EQ(TrimTornLastLine(path), "");  // no file: nothing to do
  WriteFile(path, "h\nrow 1\n");
  EXPECT_EQ(TrimTornLastLine(path), "");
  EXPECT_EQ(ReadFile(path), "h\nrow 1\n");
  WriteFile(path, "h\nrow 1\nrow 2,cut");
  EXPECT_EQ(TrimTornLastLine(path), "row 2,cut");
  EXPECT_EQ(ReadFile(path), "h\nrow 1\n");
  WriteFile(path, "no newline at all");
  EXPECT_EQ(TrimTornLastLine(path), "no newline at all");
  EXPECT_EQ(ReadFile(path), "");
}

TEST_F(FileIoTest, SamePathResolvesRelativeAndLinkedNames) {
  const fs::path a = dir() / "a.json";
  WriteFile(a, "x");
  EXPECT_TRUE(SamePath(a.string(), (dir() / "sub" / ".." / "a.json").string()));
  fs::create_hard_link(a, dir() / "hard.json");
  EXPECT_TRUE(SamePath(a.string(), (dir() / "hard.json").string()));
  fs::create_symlink(a, dir() / "soft.json");
  EXPECT_TRUE(SamePath(a.string(), (dir() / "soft.json").string()));
  EXPECT_FALSE(SamePath(a.string(), (dir() / "b.json").string()));
  EXPECT_TRUE(SamePath((dir() / "new.json").string(), (dir() / "." / "new.json").string()));
}

TEST_F(FileIoTest, CheckOutputPathsRefusesInputsAndClashes) {
  const std::string depth = (dir() / "depth.png").string(), out = (dir() / "out.json").string();
  WriteFile(depth, "png");
  CheckOutputPaths({{out, "--out"}}, {{depth, "--depth"}, {"", "--rgb"}});  // fine
  ExpectError([&] { CheckOutputPaths({{depth, "--out"}}, {{depth, "--depth"}}); },
              {"--out", depth, "--depth", "overwritten"});
  ExpectError([&] { CheckOutputPaths({{out, "--out"}, {(dir() / "." / "out.json").string(), "--overlay"}}, {}); },
              {"--overlay", "--out", "its own file"});
  ExpectError([&] { CheckOutputPaths({{dir().string(), "--json"}}, {}); }, {"--json", "is a directory"});
  ExpectError([&] { CheckOutputPaths({{(dir() / "missing" / "o.json").string(), "--out"}}, {}); },
              {"--out", "does not exist"});
}

// A symlink, a FIFO or a device node given as an output would be replaced by a regular file
// (the atomic rename): the check refuses them, and the writers do too, leaving them in place.
TEST_F(FileIoTest, SpecialFilesAreRefusedAsOutputsAndLeftInPlace) {
  const fs::path target = dir() / "target.json", link = dir() / "link.json", fifo = dir() / "fifo";
  WriteFile(target, "old");
  fs::create_symlink(target, link);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(SpecialFileKind(target.string()), "");
  EXPECT_EQ(SpecialFileKind((dir() / "none.json").string()), "");
  EXPECT_EQ(SpecialFileKind(link.string()), "a symbolic link");
  EXPECT_EQ(SpecialFileKind(fifo.string()), "a FIFO");
  EXPECT_EQ(SpecialFileKind("/dev/null"), "a character device");
  ExpectError([&] { CheckOutputPaths({{link.string(), "--out"}}, {}); }, {"--out", "a symbolic link", "regular file"});
  ExpectError([&] { CheckOutputPaths({{fifo.string(), "--json"}}, {}); }, {"--json", "a FIFO"});
  ExpectError([&] { CheckOutputPaths({{"/dev/null", "--csv"}}, {}); }, {"--csv", "/dev/null", "a character device"});
  const int before = Entries();
  ExpectError([&] { WriteFileAtomically(link.string(), [](std::ostream& o) { o << "new"; }); },
              {link.string(), "a symbolic link", "regular file"});
  ExpectError([&] { WriteFileAtomically(fifo.string(), [](std::ostream& o) { o << "new"; }); }, {"a FIFO"});
  ExpectError([&] { AppendFileDurably(link.string(), "row\n"); }, {"a symbolic link", "not appended"});
  ExpectError([&] { AppendFileDurably(fifo.string(), "row\n"); }, {"a FIFO", "not appended"});  // does not block
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(ReadFile(target), "old");
  EXPECT_EQ(Entries(), before);  // no temporary file left behind
}

// A name that fits the file system but not with the temporary suffix is refused before work.
TEST_F(FileIoTest, CheckOutputPathsRefusesANameTooLongForItsTemporaryFile) {
  const std::string fits = (dir() / (std::string(200, 'a') + ".json")).string();
  CheckOutputPaths({{fits, "--out"}}, {});
  WriteFileAtomically(fits, [](std::ostream& o) { o << "x"; });
  const std::string too_long = (dir() / (std::string(240, 'b') + ".json")).string();  // 245 of 255 bytes
  ExpectError([&] { CheckOutputPaths({{too_long, "--out"}}, {}); }, {"--out", "the file name is 245 bytes", "at most"});
  // Every writer makes the same check first (Python's writers included): nothing is written.
  const int before = Entries();
  ExpectError([&] { WriteFileAtomically(too_long, [](std::ostream& o) { o << "x"; }); },
              {too_long, "the file name is 245 bytes", "at most"});
  ExpectError([&] { WriteFileAtomicallyC(too_long, [](std::FILE*, std::string*) { return true; }); },
              {"the file name is 245 bytes"});
  EXPECT_EQ(Entries(), before);
}

// An empty path is refused by name, by the pre-work check and by every writer, and nothing is
// written into the current folder.
TEST_F(FileIoTest, AnEmptyOutputPathIsRefusedByEveryWriter) {
  ExpectError([] { CheckOutputFile("", "--json"); }, {"--json: empty value"});
  ExpectError([] { WriteFileAtomically("", [](std::ostream& o) { o << "x"; }); }, {"the output path: empty value"});
  ExpectError([] { WriteFileAtomicallyC("", [](std::FILE*, std::string*) { return true; }); },
              {"the output path: empty value"});
  CheckOutputPaths({{"", "--optional"}}, {});  // an output not asked for is not checked
}

// Small inputs are read only from regular files and up to a limit: a FIFO does not block, a
// device such as /dev/zero is not read forever, an oversized file is refused before it is read.
TEST_F(FileIoTest, ReadSmallFileTakesRegularFilesUpToItsLimit) {
  const fs::path f = dir() / "cam.json", fifo = dir() / "fifo.json";
  WriteFile(f, "{\"fx\": 1}");
  EXPECT_EQ(ReadSmallFile(f.string(), 100, "camera JSON"), "{\"fx\": 1}");
  ExpectError([&] { ReadSmallFile(f.string(), 5, "camera JSON"); },
              {f.string(), "camera JSON is 9 bytes, over the limit of 5 bytes"});
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ExpectError([&] { ReadSmallFile(fifo.string(), 100, "camera JSON"); }, {fifo.string(), "a FIFO", "camera JSON"});
  ExpectError([&] { ReadSmallFile("/dev/zero", 100, "class list"); }, {"/dev/zero", "a character device"});
  ExpectError([&] { ReadSmallFile(dir().string(), 100, "JSON"); }, {"is a directory"});
  ExpectError([&] { ReadSmallFile((dir() / "none.json").string(), 100, "JSON"); }, {"none.json", "cannot open"});
}

TEST_F(FileIoTest, OutOfMemoryInAReaderNamesTheFile) {
  const fs::path f = dir() / "big.ply";
  WriteFile(f, "0123456789");
  EXPECT_EQ(NameOutOfMemory(f.string(), "mesh", [] { return 7; }), 7);
  ExpectError([&] { NameOutOfMemory(f.string(), "mesh", []() -> int { throw std::bad_alloc(); }); },
              {f.string(), "out of memory reading the mesh (10 bytes)"});
  // Other exceptions pass through unchanged.
  ExpectError([&] { NameOutOfMemory(f.string(), "mesh", []() -> int { throw Error("parse error"); }); }, {"parse error"});
}

TEST_F(FileIoTest, CheckOutputPathsRefusesReadOnlyPlaces) {
  if (::geteuid() == 0) GTEST_SKIP() << "root may write anywhere: permissions cannot be tested";
  const fs::path ro = dir() / "ro";
  fs::create_directory(ro);
  WriteFile(dir() / "locked.json", "x");
  fs::permissions(dir() / "locked.json", fs::perms::owner_read);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  ExpectError([&] { CheckOutputPaths({{(ro / "o.json").string(), "--out"}}, {}); }, {"--out", "not writable"});
  ExpectError([&] { CheckOutputPaths({{(dir() / "locked.json").string(), "--out"}}, {}); }, {"--out", "read-only"});
  fs::permissions(ro, fs::perms::owner_all);
}

}  // namespace
}  // namespace posefilter
