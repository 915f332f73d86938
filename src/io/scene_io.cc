// io/scene_io.cc — camera / ground-truth / results JSON files (nlohmann-json).
//
// Readers are strict: every value they use must be present and of the right type; numbers must
// be finite (nlohmann writes NaN/inf as null, and strings such as "nan" are not numbers, so both
// are rejected); matrices must have the stated shape. Keys a reader does not use are ignored.
// Every error is one line "<path>: <what>" naming the key, e.g.
//   camera.json: key "fx" must be a finite number
//   gt.json: key "objects[1].R" must be a 3x3 array (3 rows of 3 numbers, or 9 numbers)
#include "posefilter/scene_io.h"

#include <nlohmann/json.hpp>

#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {

namespace {

// ordered_json keeps the keys in the order written (obj first), for human readers.
using json = nlohmann::ordered_json;

// Tolerance for "R is a rotation": max |RᵀR − I| and |det R − 1| (the brief's 1e-3 — loose
// enough for 6–8 decimal files, tight enough to catch scale, shear or a reflection).
constexpr double kRotationTolerance = 1e-3;

json ReadJsonFile(const std::string& path) {
  const std::string text = ReadSmallFile(path, kMaxSmallFileBytes, "JSON");
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw Error(path + ": malformed JSON: " + e.what());
  }
  if (!root.is_object()) throw Error(path + ": top level must be a JSON object");
  return root;
}

void WriteJsonFile(const json& root, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& os) { os << root.dump(1) << "\n"; });
}

// Typed, key-naming access to one JSON file's values. `where` is the key path of the
// enclosing object ("" at the top level, "objects[2]." inside an array entry).
class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw Error(path_ + ": key \"" + key + "\" " + what);
  }

  const json& Get(const json& obj, const std::string& where, const char* key) const {
    auto it = obj.find(key);
    if (it == obj.end()) throw Error(path_ + ": missing key \"" + where + key + "\"");
    return *it;
  }

  double NumberValue(const json& j, const std::string& full_key) const {
    // is_number() excludes null (NaN/inf as written by nlohmann), strings ("nan") and booleans.
    if (!j.is_number()) Fail(full_key, "must be a finite number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) Fail(full_key, "must be a finite number");
    return v;
  }

  double Number(const json& obj, const std::string& where, const char* key) const {
    return NumberValue(Get(obj, where, key), where + key);
  }

  int Int(const json& obj, const std::string& where, const char* key) const {
    const double v = Number(obj, where, key);
    if (v != std::floor(v) || v < std::numeric_limits<int>::min() ||
        v > std::numeric_limits<int>::max()) {
      Fail(where + key, "must be an integer");
    }
    return static_cast<int>(v);
  }

  std::string String(const json& obj, const std::string& where, const char* key) const {
    const json& j = Get(obj, where, key);
    if (!j.is_string()) Fail(where + key, "must be a string");
    std::string s = j.get<std::string>();
    if (s.empty()) Fail(where + key, "must not be empty");
    return s;
  }

  // rows×cols matrix given as `rows` arrays of `cols` numbers (row-major), or, when allow_flat,
  // as rows·cols numbers (row-major).
  Eigen::MatrixXd Matrix(const json& obj, const std::string& where, const char* key, int rows,
                         int cols, bool allow_flat) const {
    const json& j = Get(obj, where, key);
    const std::string full = where + key;
    const std::string shape = std::to_string(rows) + "x" + std::to_string(cols);
    const std::string expected =
        allow_flat ? "must be a " + shape + " array (" + std::to_string(rows) + " rows of " +
                         std::to_string(cols) + " numbers, or " + std::to_string(rows * cols) +
                         " numbers)"
                   : "must be a " + shape + " array (" + std::to_string(rows) + " rows of " +
                         std::to_string(cols) + " numbers)";
    if (!j.is_array()) Fail(full, expected);
    Eigen::MatrixXd m(rows, cols);
    if (j.size() == size_t(rows) && j[0].is_array()) {
      for (int r = 0; r < rows; ++r) {
        const json& row = j[size_t(r)];
        if (!row.is_array() || row.size() != size_t(cols)) Fail(full, expected);
        for (int c = 0; c < cols; ++c) {
          m(r, c) = NumberValue(row[size_t(c)],
                                full + "[" + std::to_string(r) + "][" + std::to_string(c) + "]");
        }
      }
      return m;
    }
    if (allow_flat && j.size() == size_t(rows) * cols) {
      for (int k = 0; k < rows * cols; ++k) {
        m(k / cols, k % cols) = NumberValue(j[size_t(k)], full + "[" + std::to_string(k) + "]");
      }
      return m;
    }
    Fail(full, expected);
  }

  Eigen::Vector3d Vector3(const json& obj, const std::string& where, const char* key) const {
    const json& j = Get(obj, where, key);
    const std::string full = where + key;
    if (!j.is_array() || j.size() != 3) Fail(full, "must be an array of 3 numbers");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      v[k] = NumberValue(j[size_t(k)], full + "[" + std::to_string(k) + "]");
    }
    return v;
  }

  // A rotation matrix: checked within kRotationTolerance, then projected onto SO(3) (nearest
  // rotation in the Frobenius norm, R = U·Vᵀ of the SVD) so downstream inverses are exact.
  Eigen::Matrix3d Rotation(const json& obj, const std::string& where, const char* key) const {
    const Eigen::Matrix3d r = Matrix(obj, where, key, 3, 3, /*allow_flat=*/true);
    const double ortho_err = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    const double det = r.determinant();
    if (ortho_err > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance) {
      std::ostringstream os;
      os << "is not a rotation matrix (max |R^T R - I| = " << ortho_err << ", det = " << det
         << ", tolerance " << kRotationTolerance << ")";
      Fail(where + key, os.str());
    }
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return svd.matrixU() * svd.matrixV().transpose();  // det > 0 here, so this is in SO(3)
  }

  const json& Array(const json& obj, const std::string& where, const char* key) const {
    const json& j = Get(obj, where, key);
    if (!j.is_array()) Fail(where + key, "must be an array");
    return j;
  }

  const json& Object(const json& j, const std::string& full_key) const {
    if (!j.is_object()) Fail(full_key, "must be a JSON object");
    return j;
  }

 private:
  const std::string& path_;
};

json MatrixToJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (int r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

json VectorToJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

// Writers refuse non-finite values: nlohmann would write them as null, which no reader accepts.
void RequireFinite(double v, const std::string& path, const std::string& key) {
  if (!std::isfinite(v)) throw Error(path + ": refusing to write non-finite value for \"" + key + "\"");
}

void RequireFiniteTransform(const Eigen::Isometry3d& T, const std::string& path,
                            const std::string& key) {
  if (!T.matrix().allFinite()) {
    throw Error(path + ": refusing to write non-finite value for \"" + key + "\"");
  }
}

std::string Entry(size_t i) { return "objects[" + std::to_string(i) + "]."; }

}  // namespace

CameraFile ReadCameraJson(const std::string& path) {
  const json root = ReadJsonFile(path);
  const Reader rd(path);
  CameraFile cf;
  Camera& c = cf.camera;
  c.fx = rd.Number(root, "", "fx");
  c.fy = rd.Number(root, "", "fy");
  c.cx = rd.Number(root, "", "cx");
  c.cy = rd.Number(root, "", "cy");
  c.width = rd.Int(root, "", "width");
  c.height = rd.Int(root, "", "height");
  cf.depth_scale = rd.Number(root, "", "depth_scale");
  if (cf.depth_scale <= 0) rd.Fail("depth_scale", "must be > 0 (metres per PNG unit)");
  if (root.contains("base_to_camera")) {
    c.base_to_camera.matrix() = rd.Matrix(root, "", "base_to_camera", 4, 4, /*allow_flat=*/false);
  }
  std::string why;
  if (!c.IsValid(&why)) throw Error(path + ": invalid camera: " + why);
  return cf;
}

void WriteCameraJson(const CameraFile& cam, const std::string& path) {
  std::string why;
  if (!cam.camera.IsValid(&why)) throw Error(path + ": refusing to write an invalid camera: " + why);
  if (!std::isfinite(cam.depth_scale) || cam.depth_scale <= 0) {
    throw Error(path + ": refusing to write a camera with depth_scale not finite and > 0");
  }
  const Camera& c = cam.camera;
  json root;
  root["fx"] = c.fx;
  root["fy"] = c.fy;
  root["cx"] = c.cx;
  root["cy"] = c.cy;
  root["width"] = c.width;
  root["height"] = c.height;
  root["depth_scale"] = cam.depth_scale;
  root["depth_units_note"] = "metres = png_value * depth_scale";
  root["base_to_camera"] = MatrixToJson(c.base_to_camera.matrix());
  WriteJsonFile(root, path);
}

std::vector<GtObject> ReadGtJson(const std::string& path) {
  const json root = ReadJsonFile(path);
  const Reader rd(path);
  const json& objects = rd.Array(root, "", "objects");
  std::vector<GtObject> out;
  out.reserve(objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const std::string where = Entry(i);
    const json& o = rd.Object(objects[i], "objects[" + std::to_string(i) + "]");
    GtObject g;
    g.obj = rd.String(o, where, "obj");
    g.T_cam_obj.linear() = rd.Rotation(o, where, "R");
    g.T_cam_obj.translation() = rd.Vector3(o, where, "t");
    out.push_back(std::move(g));
  }
  return out;
}

void WriteGtJson(const std::vector<GtObject>& objects, const std::string& path) {
  json root;
  root["R_convention"] = "x_cam = R @ x_model + t (R row-major 3x3, t metres)";
  json arr = json::array();
  for (size_t i = 0; i < objects.size(); ++i) {
    const GtObject& g = objects[i];
    if (g.obj.empty()) throw Error(path + ": refusing to write an empty \"" + Entry(i) + "obj\"");
    RequireFiniteTransform(g.T_cam_obj, path, Entry(i) + "R/t");
    json o;
    o["obj"] = g.obj;
    o["R"] = MatrixToJson(g.T_cam_obj.linear());
    o["t"] = VectorToJson(g.T_cam_obj.translation());
    arr.push_back(o);
  }
  root["objects"] = arr;
  WriteJsonFile(root, path);
}

std::vector<ObjectResult> ReadResultsJson(const std::string& path) {
  const json root = ReadJsonFile(path);
  const Reader rd(path);
  const json& objects = rd.Array(root, "", "objects");
  std::vector<ObjectResult> out;
  out.reserve(objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    const std::string where = Entry(i);
    const json& o = rd.Object(objects[i], "objects[" + std::to_string(i) + "]");
    ObjectResult r;
    r.obj = rd.String(o, where, "obj");
    r.pose_base.x = rd.Number(o, where, "x");
    r.pose_base.y = rd.Number(o, where, "y");
    r.pose_base.z = rd.Number(o, where, "z");
    r.pose_base.roll = rd.Number(o, where, "roll");
    r.pose_base.pitch = rd.Number(o, where, "pitch");
    r.pose_base.yaw = rd.Number(o, where, "yaw");
    r.T_cam_obj.linear() = rd.Rotation(o, where, "R");
    r.T_cam_obj.translation() = rd.Vector3(o, where, "t");
    r.weight = rd.Number(o, where, "weight");
    r.iterations = rd.Int(o, where, "iterations");
    if (r.iterations < 0) rd.Fail(where + "iterations", "must be >= 0");
    r.time_ms = rd.Number(o, where, "time_ms");
    out.push_back(std::move(r));
  }
  return out;
}

void WriteResultsJson(const std::vector<ObjectResult>& results, const std::string& path) {
  json arr = json::array();
  for (size_t i = 0; i < results.size(); ++i) {
    const ObjectResult& r = results[i];
    const std::string where = Entry(i);
    if (r.obj.empty()) throw Error(path + ": refusing to write an empty \"" + where + "obj\"");
    const Pose6& p = r.pose_base;
    const std::pair<const char*, double> scalars[] = {
        {"x", p.x},   {"y", p.y},         {"z", p.z},          {"roll", p.roll},
        {"pitch", p.pitch}, {"yaw", p.yaw}, {"weight", r.weight}, {"time_ms", r.time_ms}};
    json o;
    o["obj"] = r.obj;
    for (const auto& [key, value] : scalars) {
      RequireFinite(value, path, where + key);
      o[key] = value;
    }
    RequireFiniteTransform(r.T_cam_obj, path, where + "R/t");
    o["R"] = MatrixToJson(r.T_cam_obj.linear());
    o["t"] = VectorToJson(r.T_cam_obj.translation());
    o["iterations"] = r.iterations;
    arr.push_back(o);
  }
  json root;
  root["objects"] = arr;
  WriteJsonFile(root, path);
}

}  // namespace posefilter
