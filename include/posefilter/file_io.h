// posefilter/file_io.h — how posefilter writes files: atomically, never over an input.
//
// Every file the library and the CLI write (JSON, CSV, PNG, PLY, pyramid files) goes through
// WriteFileAtomically: the bytes go to a temporary file beside the target, which is flushed to
// disk and then renamed over the target. A reader sees the old file or the whole new one,
// never a half-written one; on any failure (a full disk, a missing directory) the temporary
// file is removed, the target is untouched, and Error names the target.
//
// Each write starts with CheckOutputFile (the path can be written and replaced); the CLI checks
// every output path before it starts work (CheckOutputPaths): CheckOutputFile, and the path is
// no input of the command nor another output (compared by resolved path, so "./a.json" and
// "dir/../a.json" are the same).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <new>
#include <ostream>
#include <string>
#include <vector>

#include "posefilter/error.h"

namespace posefilter {

// Writes `path` atomically: `write` fills the stream of a temporary file in the same
// directory. Throws Error naming `path` if the file cannot be created, written, flushed or
// renamed; an exception thrown by `write` removes the temporary file and propagates.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// The same for writers that need a C FILE* (libpng): `write` gets the open temporary file and
// returns false on failure, with `*error` saying why; Error("<path>: <error>") is thrown then.
void WriteFileAtomicallyC(const std::string& path, const std::function<bool(std::FILE*, std::string* error)>& write);

// `text` (whole lines) appended to `path` with one write(2) and flushed to disk (fsync), so a
// crash leaves either all of `text` or a prefix of it that TrimTornLastLine removes.
void AppendFileDurably(const std::string& path, const std::string& text);

// If `path` exists and does not end with '\n' (its last line was cut short by a crash),
// truncates the torn last line and returns it ("" when nothing was cut).
std::string TrimTornLastLine(const std::string& path);

// The bytes of a small input file (a JSON file, a class list): `path` must be a regular file
// (or a link to one: a FIFO or a device such as /dev/zero is refused without being opened) of at
// most `max_bytes`; the error names the file and `what` ("camera JSON"). The read itself stops
// at the limit too, so a file that grows while it is read cannot exceed it.
std::string ReadSmallFile(const std::string& path, std::size_t max_bytes, const std::string& what);
// The checks of ReadSmallFile, for readers that stream: `path` is a regular file (or a link to
// one) of at most `max_bytes`. Returns its size; throws Error naming the file and `what`.
std::uintmax_t CheckInputFile(const std::string& path, std::uintmax_t max_bytes, const std::string& what);
// The byte limit of the JSON and text inputs read with ReadSmallFile (64 MiB: a dataset's
// detections or results are a few MB).
inline constexpr std::size_t kMaxSmallFileBytes = std::size_t(64) << 20;

// The error NameOutOfMemory throws.
Error OutOfMemoryError(const std::string& path, const std::string& what);
// Runs `read` (a reader of `path`) and returns what it returns; a std::bad_alloc thrown inside
// becomes Error("<path>: out of memory reading the <what> ..."), so that running out of memory
// on a large input names the file instead of ending the process with "std::bad_alloc".
template <typename Read>
auto NameOutOfMemory(const std::string& path, const std::string& what, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw OutOfMemoryError(path, what);
  }
}

// An input or output of a command: the path and the option that names it ("--out").
struct NamedPath {
  std::string path;
  std::string option;
};

// Throws Error naming the option ("--out"; "" names the output by its path alone) and the path
// unless one output file can be written: the path is not empty, not a directory, nor a symlink,
// FIFO, device or socket (which the atomic replacement would destroy); its folder exists and is
// writable; its name and the temporary name beside it ("<name>.tmp.<pid>.<n>") fit the file
// system's name limit; an existing file is not read-only. WriteFileAtomically and
// WriteFileAtomicallyC start with it, so every writer (the CLI's and Python's) refuses the same
// paths with the same message.
void CheckOutputFile(const std::string& path, const std::string& option);

// Throws Error naming the option and path unless every non-empty output can be written
// (CheckOutputFile), no output is one of the inputs or an existing file inside an input that is
// a folder (a dataset), and no two outputs are the same file. Inputs with an empty path are
// ignored. AppendFileDurably refuses special files too.
void CheckOutputPaths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

// Checks, before any work, that the output folder `path` given by `option` ("--out") can be
// written or made with its parents. Throws Error naming the option and path if the path is
// empty, exists and is not a folder (a file, a FIFO, a device; a symbolic link to a folder is a
// folder) or is not writable, one of its names is longer than a file name may be, or its nearest
// existing parent is not a writable folder. Makes nothing.
void CheckOutputFolder(const std::string& path, const std::string& option);
// CheckOutputFolder, then makes the folder with its parents (Error naming the option on failure).
void MakeOutputFolder(const std::string& path, const std::string& option);

// What `path` is when it exists and is not a regular file, not following a final symlink ("a
// symbolic link", "a FIFO", "a character device", "a directory", …); "" for a regular file or
// a path that does not exist.
std::string SpecialFileKind(const std::string& path);

// True if `path` lies inside `folder`, at any depth (resolved paths; `folder` itself is not
// inside).
bool InsideFolder(const std::string& path, const std::string& folder);

// True if `a` and `b` name the same file (resolved path; the files need not exist).
bool SamePath(const std::string& a, const std::string& b);

}  // namespace posefilter
