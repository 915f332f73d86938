// eval/bop_results_csv.cc — the BOP 2019 results CSV (bop.h): one row's text, the strict
// reader (every error is one line "<file>: line N: <what>"), the atomic writer and the durable
// append of run-dataset.
#include "posefilter/bop.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include "eval/bop_io_internal.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {

namespace {

namespace fs = std::filesystem;
using bop_io_internal::MakePose;
using bop_io_internal::Where;

// Two rows of one image may differ in time by at most this (seconds), as the BOP toolkit allows.
constexpr double kTimeTolerance = 1e-3;

std::vector<std::string> SplitOn(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (true) {
    const auto e = s.find(sep, b);
    out.push_back(s.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return out;
}

std::vector<std::string> SplitSpaces(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string tok; in >> tok;) out.push_back(tok);
  return out;
}

double ParseDouble(const std::string& tok, const std::string& what, const Where& w) {
  double v = 0;
  const char* first = tok.data();
  const char* last = first + tok.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (tok.empty() || ec != std::errc() || ptr != last) w.Fail(what + ": not a number: '" + tok + "'");
  if (!std::isfinite(v)) w.Fail(what + ": non-finite value '" + tok + "'");
  return v;
}

int ParseInt(const std::string& tok, const std::string& what, const Where& w) {
  int v = 0;
  const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (tok.empty() || ec != std::errc() || ptr != tok.data() + tok.size() || v < 0)
    w.Fail(what + ": not a non-negative integer: '" + tok + "'");
  return v;
}

}  // namespace

std::string FormatBopCsvRow(const BopResult& r) {
  std::string s = std::to_string(r.scene_id) + "," + std::to_string(r.im_id) + "," + std::to_string(r.obj_id) + ",";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f,", r.score);
  s += buf;
  const Eigen::Matrix3d R = r.T_cam_obj.linear();
  for (int i = 0; i < 9; ++i) {
    std::snprintf(buf, sizeof buf, i < 8 ? "%.9g " : "%.9g,", R(i / 3, i % 3));
    s += buf;
  }
  const Eigen::Vector3d t = r.T_cam_obj.translation() * 1e3;
  std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f,", t.x(), t.y(), t.z());
  s += buf;
  std::snprintf(buf, sizeof buf, "%.6f", r.time_s);
  return s + buf;
}

std::vector<BopResult> ReadBopResultsCsv(const std::string& path) {
  CheckInputFile(path, kMaxResultsCsvBytes, "results CSV");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open results CSV");
  std::vector<BopResult> out;
  std::map<std::pair<int, int>, std::pair<double, int>> times;  // image → (time, first line)
  std::string line;
  int line_no = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const Where w{path, "line " + std::to_string(line_no)};
    if (!header) {
      if (line != kBopCsvHeader) w.Fail(std::string("header must be exactly \"") + kBopCsvHeader + "\"");
      header = true;
      continue;
    }
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::vector<std::string> f = SplitOn(line, ',');
    if (f.size() != 7)
      w.Fail("expected 7 fields scene_id,im_id,obj_id,score,R,t,time, got " + std::to_string(f.size()) +
             " (truncated row?)");
    BopResult r;
    r.scene_id = ParseInt(f[0], "scene_id", w);
    r.im_id = ParseInt(f[1], "im_id", w);
    r.obj_id = ParseInt(f[2], "obj_id", w);
    r.score = ParseDouble(f[3], "score", w);
    const std::vector<std::string> rt = SplitSpaces(f[4]), tt = SplitSpaces(f[5]);
    if (rt.size() != 9) w.Fail("R must hold 9 space-separated numbers, got " + std::to_string(rt.size()));
    if (tt.size() != 3) w.Fail("t must hold 3 space-separated numbers (mm), got " + std::to_string(tt.size()));
    std::vector<double> R9;
    for (const auto& tok : rt) R9.push_back(ParseDouble(tok, "R", w));
    Eigen::Vector3d t;
    for (int k = 0; k < 3; ++k) t[k] = ParseDouble(tt[k], "t", w) * 1e-3;
    r.T_cam_obj = MakePose(R9, t, "R", w);
    r.time_s = ParseDouble(f[6], "time", w);
    const auto key = std::make_pair(r.scene_id, r.im_id);
    if (const auto it = times.find(key); it != times.end()) {
      if (std::abs(it->second.first - r.time_s) > kTimeTolerance)
        w.Fail("time " + f[6] + " differs from line " + std::to_string(it->second.second) + " of the same image (" +
               std::to_string(it->second.first) + "); BOP needs one time per image");
    } else {
      times.emplace(key, std::make_pair(r.time_s, line_no));
    }
    out.push_back(r);
  }
  if (in.bad()) throw Error(path + ": read error");
  if (!header) throw Error(path + ": empty file (no header \"" + std::string(kBopCsvHeader) + "\")");
  return out;
}

void WriteBopResultsCsv(const std::vector<BopResult>& results, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << kBopCsvHeader << "\n";
    for (const auto& r : results) out << FormatBopCsvRow(r) << "\n";
  });
}

void AppendBopResultsCsv(const std::vector<BopResult>& results, const std::string& path) {
  std::error_code ec;
  const bool fresh = !fs::exists(path, ec) || fs::file_size(path, ec) == 0;
  if (!fresh) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(-1, std::ios::end);
    char last = 0;
    if (!in.get(last) || last != '\n')
      throw Error(path + ": does not end with a newline (a partly written row?); remove the last line and rerun");
  }
  std::string text;
  if (fresh) text += std::string(kBopCsvHeader) + "\n";
  for (const auto& r : results) text += FormatBopCsvRow(r) + "\n";
  AppendFileDurably(path, text);
}

}  // namespace posefilter
