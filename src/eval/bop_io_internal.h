// eval/bop_io_internal.h — what the BOP readers and writers share (bop_dataset_reader.cc,
// bop_detections.cc, bop_writers.cc, bop_results_csv.cc): the place of a value for error
// messages, strict JSON accessors, 6-digit ids and poses from row-major rotations. Not a public
// header.
#pragma once

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter::bop_io_internal {

using json = nlohmann::json;

// "R is a rotation" tolerance (max |RᵀR − I|), as scene_io.cc uses for gt.json.
inline constexpr double kRotationTolerance = 1e-3;

// Where a value comes from: the file and the entry inside it, for error messages.
struct Where {
  std::string file;
  std::string entry;  // "image 3, entry 1" or ""
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(file + ": " + (entry.empty() ? std::string() : entry + ": ") + what);
  }
  Where Sub(const std::string& more) const { return {file, entry.empty() ? more : entry + ", " + more}; }
};

// A dataset's JSON file: a regular file of at most kMaxSmallFileBytes (ReadSmallFile).
inline json ReadJson(const std::string& path) {
  const std::string text = ReadSmallFile(path, kMaxSmallFileBytes, "JSON");
  try {
    return NameOutOfMemory(path, "JSON", [&] { return json::parse(text); });
  } catch (const json::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw Error(path + ": malformed JSON: " + what);
  }
}

inline const json& Key(const json& obj, const char* key, const Where& w) {
  if (!obj.is_object()) w.Fail("must be a JSON object");
  const auto it = obj.find(key);
  if (it == obj.end()) w.Fail(std::string("missing key \"") + key + "\"");
  return *it;
}

inline double Number(const json& j, const std::string& what, const Where& w) {
  if (!j.is_number()) w.Fail(what + " must be a finite number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) w.Fail(what + " must be a finite number");
  return v;
}

inline int Integer(const json& j, const std::string& what, const Where& w) {
  const double v = Number(j, what, w);
  if (v != std::floor(v) || std::abs(v) > 2e9) w.Fail(what + " must be an integer");
  return static_cast<int>(v);
}

inline std::vector<double> Numbers(const json& j, std::size_t n, const std::string& what, const Where& w) {
  if (!j.is_array() || j.size() != n) w.Fail(what + " must be an array of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(Number(j[i], what + "[" + std::to_string(i) + "]", w));
  return v;
}

// "000012": the BOP file and folder name of an id.
inline std::string Digits6(int id) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06d", id);
  return buf;
}

// Row-major 3×3 (+ t) → isometry; R must be a rotation.
inline Eigen::Isometry3d MakePose(const std::vector<double>& r9, const Eigen::Vector3d& t_m, const std::string& what,
                                  const Where& w) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = r9[i];
  const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho > kRotationTolerance || R.determinant() < 0)
    w.Fail(what + " is not a rotation matrix (|RᵀR − I| = " + std::to_string(ortho) + ")");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t_m;
  return T;
}

}  // namespace posefilter::bop_io_internal
