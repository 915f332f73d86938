#include "posefilter/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "posefilter/error.h"

namespace posefilter {

namespace fs = std::filesystem;

namespace {

std::string Errno() { return std::strerror(errno); }

// The longest suffix TempPathBeside adds: ".tmp." + a pid (≤ 10 digits) + "." + a counter
// (≤ 20 digits).
constexpr std::size_t kTempSuffixMax = 5 + 10 + 1 + 20;

// A fresh name beside `path` ("<path>.tmp.<pid>.<n>"), unique within this process and among
// processes writing the same target.
std::string TempPathBeside(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
}

// Writes all of `data` to `fd`, retrying short writes and EINTR. False with errno set on failure.
bool WriteAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Renames the finished temporary file `tmp` over `path` (removing `tmp` on failure) and syncs
// the directory so the rename survives a crash (best effort: some file systems refuse). A path
// that is not a regular file (a symlink, FIFO, device, socket) is not replaced.
void Commit(const std::string& tmp, const std::string& path) {
  if (const std::string kind = SpecialFileKind(path); !kind.empty()) {
    std::remove(tmp.c_str());
    throw Error(path + ": is " + kind + ", not a regular file; not replaced");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = Errno();
    std::remove(tmp.c_str());
    throw Error(path + ": cannot replace the file (" + why + ")");
  }
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

// Removes a temporary file when the write is abandoned (an exception or an early return).
struct TempFile {
  std::string path;
  bool committed = false;
  ~TempFile() {
    if (!committed) std::remove(path.c_str());
  }
};

// The longest file name the file system of `dir` (or of its nearest existing parent) takes,
// in bytes (pathconf NAME_MAX; 255 where it cannot say).
std::size_t NameLimitIn(fs::path dir) {
  std::error_code ec;
  if (dir.empty()) dir = ".";
  dir = fs::absolute(dir, ec);
  while (!dir.empty() && !fs::exists(dir, ec) && dir != dir.root_path()) dir = dir.parent_path();
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  return name_max > 0 ? std::size_t(name_max) : 255;
}

}  // namespace

bool InsideFolder(const std::string& path, const std::string& folder) {
  std::error_code ep, ef;
  const fs::path p = fs::weakly_canonical(fs::absolute(path), ep), f = fs::weakly_canonical(fs::absolute(folder), ef);
  if (ep || ef) return false;
  const auto mismatch = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return mismatch.first == f.end() && p != f;
}

std::uintmax_t CheckInputFile(const std::string& path, std::uintmax_t max_bytes, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": cannot open " + what + " (no such file)");
  if (!fs::is_regular_file(path, ec)) {
    // What the path is once its links are followed (an input may be a link to a file).
    const std::string kind = SpecialFileKind(fs::canonical(path, ec).string());
    throw Error(path + ": is " + (kind.empty() ? "not a regular file" : kind) + ", not a regular " + what + " file");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(path + ": cannot read the size of the " + what + " (" + ec.message() + ")");
  if (size > max_bytes)
    throw Error(path + ": " + what + " is " + std::to_string(size) + " bytes, over the limit of " +
                std::to_string(max_bytes) + " bytes");
  return size;
}

std::string ReadSmallFile(const std::string& path, std::size_t max_bytes, const std::string& what) {
  const std::uintmax_t size = CheckInputFile(path, max_bytes, what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open " + what + " (" + Errno() + ")");
  std::string bytes = NameOutOfMemory(path, what, [&] { return std::string(std::size_t(size) + 1, '\0'); });
  in.read(bytes.data(), std::streamsize(bytes.size()));
  if (in.bad()) throw Error(path + ": cannot read " + what);
  bytes.resize(std::size_t(in.gcount()));
  if (bytes.size() > max_bytes)
    throw Error(path + ": " + what + " is over the limit of " + std::to_string(max_bytes) + " bytes");
  if (bytes.size() > size) throw Error(path + ": " + what + " grew while it was read");
  return bytes;
}

Error OutOfMemoryError(const std::string& path, const std::string& what) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  return Error(path + ": out of memory reading the " + what +
               (ec ? std::string() : " (" + std::to_string(size) + " bytes)") +
               "; free memory or raise the process's memory limit");
}

std::string SpecialFileKind(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return "";
  if (S_ISLNK(st.st_mode)) return "a symbolic link";
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "a special file";
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  CheckOutputFile(path, "");
  std::ostringstream buffer(std::ios::binary);
  write(buffer);
  if (!buffer) throw Error(path + ": cannot format the contents");
  const std::string bytes = std::move(buffer).str();
  TempFile tmp{TempPathBeside(path)};
  const int fd = ::open(tmp.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw Error(path + ": cannot open for writing (" + Errno() + ")");
  bool ok = WriteAll(fd, bytes.data(), bytes.size()) && ::fsync(fd) == 0;
  const std::string why = ok ? "" : Errno();
  ok = (::close(fd) == 0) && ok;
  if (!ok) throw Error(path + ": write failed (" + (why.empty() ? Errno() : why) + ")");
  tmp.committed = true;
  Commit(tmp.path, path);
}

void WriteFileAtomicallyC(const std::string& path, const std::function<bool(std::FILE*, std::string*)>& write) {
  CheckOutputFile(path, "");
  TempFile tmp{TempPathBeside(path)};
  std::FILE* fp = std::fopen(tmp.path.c_str(), "wbx");
  if (fp == nullptr) throw Error(path + ": cannot open for writing (" + Errno() + ")");
  std::string error;
  bool ok = write(fp, &error);
  if (ok && (std::fflush(fp) != 0 || ::fsync(::fileno(fp)) != 0)) {
    error = "write failed (" + Errno() + ")";
    ok = false;
  }
  if (std::fclose(fp) != 0 && ok) {
    error = "write failed on close (" + Errno() + ")";
    ok = false;
  }
  if (!ok) throw Error(path + ": " + (error.empty() ? std::string("write failed") : error));
  tmp.committed = true;
  Commit(tmp.path, path);
}

void AppendFileDurably(const std::string& path, const std::string& text) {
  // O_NOFOLLOW: not through a symlink; O_NONBLOCK: a FIFO does not block the open (refused below).
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0666);
  if (fd < 0) {
    const std::string why = Errno();
    if (const std::string kind = SpecialFileKind(path); !kind.empty())
      throw Error(path + ": is " + kind + ", not a regular file; not appended to");
    throw Error(path + ": cannot open for appending (" + why + ")");
  }
  struct stat st {};
  const bool sized = ::fstat(fd, &st) == 0;
  if (sized && !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw Error(path + ": is " + SpecialFileKind(path) + ", not a regular file; not appended to");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  bool ok = WriteAll(fd, text.data(), text.size()) && ::fsync(fd) == 0;
  const std::string why = ok ? "" : Errno();
  // A failed append (a full disk) is undone: the file is cut back to its old size.
  if (!ok && sized) (void)::ftruncate(fd, st.st_size);
  ok = (::close(fd) == 0) && ok;
  if (!ok) throw Error(path + ": append failed (" + (why.empty() ? Errno() : why) + ")");
}

std::string TrimTornLastLine(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return "";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open (" + Errno() + ")");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(path + ": read error");
  if (text.empty() || text.back() == '\n') return "";
  const std::size_t nl = text.rfind('\n');
  const std::size_t keep = nl == std::string::npos ? 0 : nl + 1;
  fs::resize_file(path, keep, ec);
  if (ec) throw Error(path + ": cannot cut its torn last line (" + ec.message() + ")");
  return text.substr(keep);
}

void CheckOutputFolder(const std::string& path, const std::string& option) {
  if (path.empty()) throw Error(option + ": empty value; give a folder");
  const std::string name = option + " " + path;
  std::error_code ec;
  // Follows a final symlink: a link to a folder is that folder.
  const fs::file_status st = fs::status(path, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) {
      const std::string kind = SpecialFileKind(path);
      throw Error(name + ": is " + (kind.empty() ? std::string("a file") : kind) + ", not a folder");
    }
    if (::access(path.c_str(), W_OK | X_OK) != 0) throw Error(name + ": the folder is not writable");
    return;
  }
  const std::size_t limit = NameLimitIn(fs::path(path).parent_path());
  for (const fs::path& part : fs::path(path)) {
    const std::size_t n = part.string().size();
    if (n > limit)
      throw Error(name + ": the name " + part.string().substr(0, 16) + "... is " + std::to_string(n) +
                  " bytes, longer than a file name may be (" + std::to_string(limit) + ")");
  }
  // The folder is made with its parents: the nearest existing one must be a writable folder.
  fs::path up = fs::absolute(fs::path(path), ec).parent_path();
  while (!up.empty() && !fs::exists(fs::symlink_status(up, ec)) && up != up.root_path()) up = up.parent_path();
  if (!up.empty() && fs::exists(up, ec)) {
    if (!fs::is_directory(up, ec)) throw Error(name + ": " + up.string() + " is not a folder");
    if (::access(up.c_str(), W_OK | X_OK) != 0) throw Error(name + ": the folder " + up.string() + " is not writable");
  }
}

void MakeOutputFolder(const std::string& path, const std::string& option) {
  CheckOutputFolder(path, option);
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec || !fs::is_directory(path)) throw Error(option + " " + path + ": cannot make the folder: " + ec.message());
}

bool SamePath(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  if (fs::exists(a, ea) && fs::exists(b, eb)) return fs::equivalent(a, b, ea);  // hard links too
  const fs::path ca = fs::weakly_canonical(fs::absolute(a), ea);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b), eb);
  if (ea || eb) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  return ca == cb;
}

void CheckOutputFile(const std::string& path, const std::string& option) {
  const std::string label = option.empty() ? std::string("the output path") : option;
  if (path.empty()) throw Error(label + ": empty value; give a file name");
  const std::string name = option.empty() ? path : option + " " + path;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(name + ": is a directory, not a file");
  // An output is written as a new file that replaces the old one: that would destroy a
  // symlink, FIFO or device node (and write nothing through it), so such a path is refused.
  if (const std::string kind = SpecialFileKind(path); !kind.empty())
    throw Error(name + ": is " + kind + ", not a regular file; outputs replace a file whole, so give a regular file's path");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec)) throw Error(name + ": the directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK | X_OK) != 0) throw Error(name + ": the directory " + dir.string() + " is not writable");
  // The temporary file beside it (TempPathBeside: "<name>.tmp.<pid>.<n>") must fit the file
  // system's name limit too, or the write would fail after the work.
  const std::size_t limit = NameLimitIn(dir);
  const std::size_t file_name = fs::path(path).filename().string().size();
  if (file_name + kTempSuffixMax > limit)
    throw Error(name + ": the file name is " + std::to_string(file_name) + " bytes; at most " +
                std::to_string(limit > kTempSuffixMax ? limit - kTempSuffixMax : 0) +
                " fit, with the temporary name <name>.tmp.<pid>.<n> written first");
  if (fs::exists(path, ec) && ::access(path.c_str(), W_OK) != 0) throw Error(name + ": the file exists and is read-only");
}

void CheckOutputPaths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    if (out.path.empty()) continue;
    CheckOutputFile(out.path, out.option);
    const std::string name = out.option + " " + out.path;
    std::error_code ec;
    for (const NamedPath& in : inputs) {
      if (in.path.empty()) continue;
      if (SamePath(out.path, in.path))
        throw Error(name + ": is the input " + in.option + " " + in.path + "; it would be overwritten");
      // An input folder (a dataset, a models folder): none of the files in it is an output.
      if (fs::is_directory(in.path, ec) && fs::exists(out.path, ec) && InsideFolder(out.path, in.path))
        throw Error(name + ": is a file of the input folder " + in.option + " " + in.path + "; it would be overwritten");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && SamePath(out.path, outputs[j].path))
        throw Error(name + ": is also " + outputs[j].option + " " + outputs[j].path + "; give each output its own file");
    }
  }
}

}  // namespace posefilter
