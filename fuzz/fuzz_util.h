// fuzz/fuzz_util.h — shared by the libFuzzer targets: a scratch file per process for readers
// that take a path, and the check that a reader fails only with posefilter::Error.
//
// The contract under test (include/posefilter/error.h): bad input throws posefilter::Error with
// a one-line message naming the file. Any other outcome is a finding: a crash or sanitizer
// report, another exception type escaping (libFuzzer reports it as a deadly signal via
// std::terminate), a hang, a huge allocation, an Error whose message does not name the file or
// spans lines, or a returned value that breaks what the header promises (checked per target
// with Require).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "posefilter/error.h"

namespace posefilter_fuzz {

// Prints `what` and aborts (libFuzzer saves the input as a crash) unless `ok`.
inline void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "posefilter fuzz: contract violated: %s\n", what);
    std::abort();
  }
}

// A file of this process, rewritten with each input: <dir>/posefilter_fuzz_<tag>_<pid><suffix>,
// where <dir> is /dev/shm when writable (no disk traffic), else $TMPDIR, else /tmp. The suffix
// matters to readers that pick a format by extension (.ply, .obj, .json). Removed at exit.
class ScratchFile {
 public:
  ScratchFile(const char* tag, const char* suffix) {
    std::string dir = "/dev/shm";
    if (::access(dir.c_str(), W_OK) != 0) {
      const char* tmp = std::getenv("TMPDIR");
      dir = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
    }
    path_ = dir + "/posefilter_fuzz_" + tag + "_" + std::to_string(::getpid()) + suffix;
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() { std::remove(path_.c_str()); }

  // Replaces the file's contents with the input; returns its path.
  const std::string& Write(const std::uint8_t* data, std::size_t size) {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (f == nullptr || (size != 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
      std::perror(path_.c_str());
      std::abort();  // the harness itself failed: not a finding in the reader
    }
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// PNG chunks carry a CRC-32 that libpng checks first, so almost every mutation of a chunk would
// stop at "CRC error". The PNG targets therefore rewrite the CRC of each complete chunk after
// the 8-byte signature (a length that runs past the end stops the walk) before the reader sees
// the bytes, so the fuzzer reaches the header and pixel handling behind the check.
inline std::uint32_t Crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

inline std::vector<std::uint8_t> WithPngCrcsFixed(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> b(data, data + size);
  std::size_t pos = 8;
  while (pos + 12 <= b.size()) {
    const std::uint64_t len = (std::uint64_t(b[pos]) << 24) | (std::uint64_t(b[pos + 1]) << 16) |
                              (std::uint64_t(b[pos + 2]) << 8) | std::uint64_t(b[pos + 3]);
    if (len > b.size() - pos - 12) break;
    const std::uint32_t crc = Crc32(&b[pos + 4], 4 + len);  // type + data
    const std::size_t at = pos + 8 + len;
    for (int k = 0; k < 4; ++k) b[at + k] = std::uint8_t(crc >> (24 - 8 * k));
    pos = at + 4;
  }
  return b;
}

// Runs `read` (a reader call on `path`); a posefilter::Error is the correct outcome for bad
// input, provided its message is one line that names the file. Anything else propagates.
// Returns true when `read` returned normally.
template <class F>
bool ReadOrError(const std::string& path, F&& read) {
  try {
    read();
    return true;
  } catch (const posefilter::Error& e) {
    const std::string msg = e.what();
    if (msg.find(path) == std::string::npos || msg.find('\n') != std::string::npos) {
      std::fprintf(stderr, "posefilter fuzz: Error message does not name the file in one line:\n%s\n",
                   msg.c_str());
      std::abort();
    }
    return false;
  }
}

}  // namespace posefilter_fuzz
